"""The nerve monitor in the web application: the Drill panel's meter and the 3D tint by level.

The meter is one trame state variable (``vc_monitor``), a short list of
small rows (``nervemonitor.meter_rows``: name, distance in mm, bar fraction
over 0-8 mm, level, level colour; the desktop widget shows the same rows).
It is published only when a distance moves by more than
``nervemonitor.DISTANCE_STEP_MM`` or a level changes (``rows_differ``), so
that a stroke costs the page a few small updates, not one per pose.

The tint: the volume-cut displayable manager draws each segment in its
segment colour (``vtkSegment::GetColor``), so a monitored segment whose level
is above silent takes the level's colour there, and its own colour comes
back when it is silent again (or before an export, which must not save the
tint). The segment colour changes no labelmap: the cut field, the monitor's
distance fields and the label volume of the 3D view stay as they are.
"""

from __future__ import annotations

import vtk

from ..feedback import nervemonitor


def hex_to_rgb(colour: str) -> tuple[float, float, float]:
    """``"#rrggbb"`` as RGB in 0-1."""
    value = colour.lstrip("#")
    if len(value) != 6:
        raise ValueError(f"not a #rrggbb colour: {colour!r}")
    return tuple(int(value[i:i + 2], 16) / 255.0 for i in (0, 2, 4))


def rgb_to_hex(rgb) -> str:
    """RGB in 0-1 as ``"#rrggbb"``."""
    return "#" + "".join(f"{max(0, min(255, round(255 * c))):02x}" for c in rgb[:3])


class SegmentTint:
    """Tints monitored segments by level (above silent) and gives their own colour back when silent."""

    def __init__(self):
        self._own: dict[str, tuple] = {}  # segment ID -> its own colour, while tinted
        self._segmentation_node = None

    @property
    def tinted(self) -> dict[str, tuple]:
        """The tinted segments and their own colours."""
        return dict(self._own)

    def own_colour(self, segment_id: str, colour):
        """The segment's own colour (``colour`` unless it is tinted now)."""
        return self._own.get(segment_id, colour)

    def apply(self, segmentation_node, levels: dict) -> bool:
        """Tint per ``{structure name: level}``; True if a colour changed (the 3D view must be told)."""
        if segmentation_node is not self._segmentation_node:
            self._own.clear()  # another scan: its colours are its own
            self._segmentation_node = segmentation_node
        if segmentation_node is None:
            return False
        segmentation = segmentation_node.GetSegmentation()
        changed = False
        for name, level in levels.items():
            segment_id = segmentation.GetSegmentIdBySegmentName(name)
            segment = segmentation.GetSegment(segment_id) if segment_id else None
            if segment is None:
                continue
            alarm = level in nervemonitor.LEVEL_NAMES and nervemonitor.LEVEL_NAMES.index(level) > 0
            if alarm:
                if segment_id not in self._own:
                    self._own[segment_id] = tuple(segment.GetColor())
                changed |= self._set(segment, hex_to_rgb(nervemonitor.LEVEL_COLOURS[level]))
            elif segment_id in self._own:
                changed |= self._set(segment, self._own.pop(segment_id))
        return changed

    def restore(self) -> bool:
        """Every tinted segment in its own colour again; True if a colour changed."""
        return self.restore_except({})

    def restore_except(self, levels: dict) -> bool:
        """Tinted segments not named in ``levels`` in their own colour again; True if a colour changed."""
        changed = False
        segmentation_node = self._segmentation_node
        if segmentation_node is None:
            self._own.clear()
            return False
        segmentation = segmentation_node.GetSegmentation()
        for segment_id in list(self._own):
            segment = segmentation.GetSegment(segment_id)
            if segment is not None and segment.GetName() in levels:
                continue
            colour = self._own.pop(segment_id)
            if segment is not None:
                changed |= self._set(segment, colour)
        return changed

    @staticmethod
    def _set(segment, colour) -> bool:
        if all(abs(a - b) < 1e-6 for a, b in zip(segment.GetColor(), colour)):
            return False
        segment.SetColor(*colour)
        return True


class MonitorMeter:
    """Keeps ``vc_monitor`` and the tint up to date from the cut node's nerve monitor."""

    def __init__(self, session, state, tool_shown=lambda: True):
        self.session = session
        self.state = state
        self.tool_shown = tool_shown
        self.tint = SegmentTint()
        self.shown: list[dict] = []
        self.published = 0

    def _tool_pose(self):
        pose = vtk.vtkMatrix4x4()
        transform = self.session.tool_node.GetParentTransformNode()
        if transform is not None:
            transform.GetMatrixTransformToWorld(pose)
        return pose

    def current_readings(self) -> dict:
        if not self.session.has_data:
            return {}
        monitor = self.session.logic.GetNerveMonitor(self.session.cut_node)
        if monitor is None:
            return {}
        current = nervemonitor.readings(monitor)
        if (any(r["level"] == nervemonitor.NOT_READY for r in current.values()) and monitor.IsBuilt()
                and not self.session.in_stroke):
            # The logic measures at each pose: fields finished since the last one are read at the tool, where it is.
            self.session.move_tool(self._tool_pose())
            current = nervemonitor.readings(monitor)
        return current

    def refresh(self, force: bool = False) -> bool:
        """Read the monitor; publish the rows if they changed enough, tint by level. True if published."""
        current = self.current_readings()
        if self.session.has_data:
            levels = {name: r["level"] for name, r in current.items()} if self.tool_shown() else {}
            # Segments no longer read (a hidden tool, another scan) take their own colour back.
            changed = self.tint.restore_except(levels) | self.tint.apply(self.session.segmentation, levels)
            if changed:
                # The displayable manager reads segment colours when the cut node changes: no labelmap is rebuilt.
                self.session.cut_node.Modified()
        rows = nervemonitor.meter_rows(current)
        if not force and not nervemonitor.rows_differ(self.shown, rows):
            return False
        self.shown = rows
        self.state.vc_monitor = rows
        self.published += 1
        return True

    def restore_colours(self) -> None:
        """The segments' own colours (before an export or a new scan); the next refresh tints again."""
        if self.tint.restore() and self.session.has_data:
            self.session.cut_node.Modified()

    def diagnostics(self) -> dict:
        """For tests: the rows shown, the segments tinted now, their colours in the scene, the burr's centre (RAS)."""
        colours, centre = {}, None
        if self.session.has_data:
            pose = self._tool_pose()
            centre = [round(pose.GetElement(row, 3), 3) for row in range(3)]
            segmentation = self.session.segmentation.GetSegmentation()
            for row in self.shown:
                segment_id = segmentation.GetSegmentIdBySegmentName(row["name"])
                if segment_id:
                    colours[row["name"]] = [round(c, 4) for c in segmentation.GetSegment(segment_id).GetColor()]
        return {"rows": self.shown, "colours": colours, "tinted": sorted(self.tint.tinted), "published": self.published,
                "tool_centre": centre}
