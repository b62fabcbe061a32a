"""The assessment as files: a JSON of every metric and a self-contained HTML report with inline plots.

The plots are drawn with matplotlib's Agg backend (no display, no Qt) and
embedded as PNG data URIs, so the report is one file a trainee can mail.
"""

from __future__ import annotations

import base64
import html
import io
import json
from pathlib import Path

import numpy as np

from . import metrics as metriclib

NEAR_PLOT_MM = 15.0  # structures the burr came this close to get a curve
COLORS = {"bone": (0.82, 0.80, 0.74), "removed": (0.85, 0.15, 0.12), "reference": (0.15, 0.45, 0.85), "protected": (0.98, 0.80, 0.10)}


def _figure_png(figure) -> str:
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=110, bbox_inches="tight")
    import matplotlib.pyplot as plt

    plt.close(figure)
    return base64.b64encode(buffer.getvalue()).decode()


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def distance_plot(assessment) -> str:
    plt = _pyplot()
    replayed = assessment.trainee
    figure, axes = plt.subplots(figsize=(8, 3.6))
    time = replayed.times - replayed.times[0]
    shown = 0
    for structure, distance in sorted(replayed.distances.items(), key=lambda item: item[1].min()):
        if distance.min() > NEAR_PLOT_MM:
            continue
        axes.plot(time, distance, lw=1.2, label=structure)
        shown += 1
    for near, style in zip(metriclib.NEAR_MM, (":", "--")):
        axes.axhline(near, color="0.3", ls=style, lw=0.8)
    axes.axhline(0.0, color="red", lw=0.8)
    axes.set_xlabel("time (s)")
    axes.set_ylabel("burr to structure (mm)")
    axes.set_title("Distance from the burr to each structure at risk (lines at 1 and 2 mm; below 0: contact)")
    axes.set_ylim(min(-1.0, min((d.min() for d in replayed.distances.values()), default=0.0) - 0.5), NEAR_PLOT_MM)
    if shown:
        axes.legend(fontsize=8, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    return _figure_png(figure)


def removal_plot(assessment) -> str:
    """Removed volume per segment over time, and on their own scale the bands near each structure at risk."""
    plt = _pyplot()
    replayed = assessment.trainee
    figure, (segments, bands) = plt.subplots(1, 2, figsize=(11, 3.8))
    time = replayed.times - replayed.times[0]
    for index, region in enumerate(assessment.regions):
        curve = replayed.region_series[:, index]
        if curve.max() > 0.0:
            (bands if "_band_" in region else segments).plot(time, curve, lw=1.2, label=region.replace("_band_", " "))
    for axes, title in ((segments, "Segments"), (bands, "Bands around the structures at risk")):
        axes.set_xlabel("time (s)")
        axes.set_ylabel("removed (mm³)")
        axes.set_title(title, fontsize=10)
        if axes.lines:
            axes.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
        else:
            axes.text(0.5, 0.5, "nothing removed here", ha="center", va="center", transform=axes.transAxes)
    figure.suptitle("Removed volume per region over time")
    figure.tight_layout()
    return _figure_png(figure)


def region_bars(assessment) -> str | None:
    """Removed volume per region, this session against the reference: segments, and on their own scale the bands near structures at risk."""
    if assessment.reference_replay is None:
        return None
    plt = _pyplot()
    metrics = assessment.metrics
    regions = [r for r in assessment.regions
               if metrics.get(f"final.removed_mm3.{r}", 0) or metrics.get(f"final.reference_removed_mm3.{r}", 0)]
    groups = [[r for r in regions if "_band_" not in r], [r for r in regions if "_band_" in r]]
    groups = [group for group in groups if group]
    if not groups:
        return None
    figure, panels = plt.subplots(1, len(groups), figsize=(10, max(2.8, 1.2 + 0.32 * max(len(g) for g in groups))), squeeze=False)
    for panel, group, title in zip(panels[0], groups, ("Segments", "Bands around the structures at risk")):
        rows = np.arange(len(group))
        panel.barh(rows - 0.2, [metrics[f"final.removed_mm3.{r}"] for r in group], height=0.4, color=COLORS["removed"], label="this session")
        panel.barh(rows + 0.2, [metrics[f"final.reference_removed_mm3.{r}"] for r in group], height=0.4, color=COLORS["reference"], label="reference")
        panel.set_yticks(rows, [r.replace("_band_", " ") for r in group], fontsize=8)
        panel.invert_yaxis()
        panel.set_xlabel("removed (mm³)")
        panel.set_title(title, fontsize=10)
    panels[0][0].legend(fontsize=8)
    figure.suptitle(f"Removed volume per region against the reference (Dice {metrics['final.dice']:.2f})")
    figure.tight_layout()
    return _figure_png(figure)


def _view_axis(assessment) -> int:
    """The crop axis (0 = k, 1 = j, 2 = i of the [k, j, i] arrays) closest to the recorded camera's view direction."""
    crop = assessment.crop
    # The reference's view when there is one, so that both sessions' pictures look the same way.
    direction = assessment.reference_camera_direction if assessment.reference_camera_direction is not None else assessment.camera_direction
    camera = np.asarray(direction, dtype=float) if direction is not None else np.array([1.0, 0.0, 0.0])
    ijk_direction = np.linalg.inv(crop.scan.ijk_to_ras[:3, :3]) @ camera
    return 2 - int(np.argmax(np.abs(ijk_direction * crop.scan.spacing)))


def cavity_pictures(assessment) -> str:
    """The cavity (and the reference's) as the camera sees it (depth of the removed bone) and in a slice through it."""
    plt = _pyplot()
    crop = assessment.crop
    cavities = [("This session", assessment.trainee.final_removed, COLORS["removed"])]
    if assessment.reference_replay is not None:
        cavities.append(("Reference", assessment.reference_replay.final_removed, COLORS["reference"]))
    axis = _view_axis(assessment)
    protected = crop.scan.lookup(crop.scan.protected)[crop.labels]
    bone = crop.cuttable & ~protected
    figure, grid = plt.subplots(len(cavities), 2, figsize=(9, 4.2 * len(cavities)), squeeze=False)
    for row, (title, removed, color) in enumerate(cavities):
        depth = removed.sum(axis=axis).astype(float) * crop.scan.spacing[2 - axis]
        picture = np.ones(depth.shape + (3,)) * np.array(COLORS["bone"]) * np.where(bone.any(axis=axis), 1.0, 0.35)[..., None]
        shade = np.clip(depth / max(depth.max(), 1e-6), 0.0, 1.0)[..., None]
        picture = np.where(depth[..., None] > 0, (0.35 + 0.65 * shade) * np.array(color), picture)
        picture = np.where(protected.any(axis=axis)[..., None] & (depth[..., None] == 0), np.array(COLORS["protected"]), picture)
        grid[row, 0].imshow(picture, origin="lower", interpolation="nearest")
        grid[row, 0].set_title(f"{title}: removed bone seen from the camera's side\n(darker: deeper; yellow: structures at risk behind)", fontsize=9)
        # The slice across the view through the middle of the cavity.
        along = [a for a in range(3) if a != axis][0]
        counts = removed.sum(axis=tuple(a for a in range(3) if a != along))
        middle = int(np.argmax(counts)) if counts.max() else removed.shape[along] // 2
        section = np.take(np.stack([bone, removed, protected], axis=-1), middle, axis=along)
        image = np.zeros(section.shape[:2] + (3,)) + 0.1
        image[section[..., 0]] = COLORS["bone"]
        image[section[..., 1]] = color
        image[section[..., 2]] = COLORS["protected"]
        grid[row, 1].imshow(image, origin="lower", interpolation="nearest")
        grid[row, 1].set_title(f"{title}: slice through the cavity (bone, removed, structures at risk)", fontsize=9)
        for axes in grid[row]:
            axes.set_xticks([])
            axes.set_yticks([])
    return _figure_png(figure)


def _table(metrics: dict, prefix: str) -> str:
    rows = "".join(f"<tr><td>{html.escape(key)}</td><td>{'—' if value is None else f'{value:.4g}' if isinstance(value, float) else value}</td></tr>"
                   for key, value in metrics.items() if key.startswith(prefix))
    return f"<table>{rows}</table>"


def html_report(assessment) -> str:
    session = assessment.session
    weights = ", ".join(f"{part.replace('_', ' ')} {100 * weight:.0f} %" for part, weight in metriclib.SCORE_WEIGHTS.items())
    parts = "".join(f"<li>{part.replace('_', ' ')}: {'not computed' if value is None else f'{100 * value:.1f}'}</li>"
                    for part, value in assessment.parts.items())
    images = [("Distance to the structures at risk", distance_plot(assessment)),
              ("Removal per region", removal_plot(assessment)),
              ("Against the reference", region_bars(assessment)),
              ("The cavities", cavity_pictures(assessment))]
    figures = "".join(f"<h2>{html.escape(title)}</h2><img alt='{html.escape(title)}' src='data:image/png;base64,{png}'>"
                      for title, png in images if png)
    sections = "".join(f"<h2>{title}</h2>{_table(assessment.metrics, prefix)}" for title, prefix in
                       (("Safety", "safety."), ("Final product", "final."), ("Efficiency", "efficiency."), ("Visibility", "visibility.")))
    reference = assessment.reference
    return f"""<!DOCTYPE html>
<html lang="en"><head><meta charset="utf-8"><title>Drilling assessment: {html.escape(session['recording'] or 'session')}</title>
<style>body{{font-family:sans-serif;max-width:980px;margin:2em auto;color:#222}} table{{border-collapse:collapse}}
td{{border-bottom:1px solid #ddd;padding:2px 10px;font-size:13px}} td:last-child{{text-align:right}} img{{max-width:100%}}
.score{{font-size:40px;font-weight:bold}}</style></head><body>
<h1>Drilling assessment</h1>
<p>Recording <code>{html.escape(session['recording'])}</code> on scan <b>{html.escape(session['scan'])}</b>,
started {html.escape(str(session['started']))}, {session['duration_s']:.1f} s, trainee {html.escape(str(session['trainee']))};
sha256 <code>{session['sha256'][:16]}…</code>.
{f"Reference <code>{html.escape(reference['recording'])}</code>." if reference else "No reference session: no final-product comparison."}</p>
<p class="score">Score {assessment.score:.1f} / 100</p>
<p>Weights: {weights} (a part not computed drops out and the others are rescaled).</p><ul>{parts}</ul>
{figures}{sections}
</body></html>
"""


def write(assessment, out_dir) -> dict:
    """Write ``assessment.json`` and ``report.html`` into ``out_dir``; return their paths."""
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    json_path = out_dir / "assessment.json"
    json_path.write_text(json.dumps(assessment.to_dict(), indent=1) + "\n")
    html_path = out_dir / "report.html"
    html_path.write_text(html_report(assessment))
    return {"json": json_path, "html": html_path}
