"""Every web session is recorded, can be downloaded and replayed, and is graded in the Report panel.

``WebSessionRecording`` listens to the drilling session (``DrillSession.
stroke_listener``: strokes, poses, undo and redo, where the session drives
the logic) and to the 3D view's rendered frames, and keeps a version 2
recording (``cutting.recording.SessionRecorder``): each stroke's poses with
their times, the tool of each stroke (a key per tool setting, with the
parameters that rebuild it), undo/redo, the camera of every frame the 3D
view draws (its full view and its fast preview), the nerve monitor's readings
at each pose (those that changed, ``cutting.recording.MonitorCompactor``),
the contacts with structures the tool may not cut and the removed volume per
segment after each stroke and edit. New data starts a new recording.

``replay_in`` drills a downloaded recording into a session on the same data
through the logic (``cutting.recording.replay``), the tools rebuilt from the
recording: the cut is the one the page made, voxel for voxel.

``ReportPanel`` grades the session so far with ``VolumeCuttingLib.
assessment`` (against the shipped careful mastoidectomy on the phantom and
the example head CT; on the user's own CT with their segmentation without a
reference, the regions and structures at risk theirs), shows the score, the key metrics and the report's
plots, offers the recording (JSON with its sha256) and the self-contained
HTML report as downloads, and stores the assessment in the trainee records
(``records.pending.store_or_keep``: an unreachable database keeps it pending,
nothing is lost).
"""

from __future__ import annotations

import asyncio
import json
from dataclasses import asdict

import vtk
from trame.widgets import html
from trame.widgets import vuetify3 as v3

from ..assessment import metrics as metriclib
from ..assessment import report as reportlib
from ..assessment import scans, sessions
from ..config import toolconfig
from ..cutting import recording as recordings
from ..data import owndata
from ..records import pending
from ..records.assessment import AssessmentError as RecordsAssessmentError
from . import session as sessionlib

#: What the panel lists beside the score (those the assessment computed).
KEY_METRICS = (
    ("safety.contacts", "contacts with structures at risk", ""),
    ("safety.min_distance_mm", "closest approach to a structure at risk", "mm"),
    ("safety.large_burr_within_2mm_s", "large cutting burr within 2 mm", "s"),
    ("final.dice", "overlap with the reference (Dice)", ""),
    ("final.removed_mm3", "removed at the end (voxels of the scan)", "mm³"),
    ("efficiency.strokes", "strokes", ""),
    ("efficiency.undo", "undo", ""),
    ("efficiency.duration_s", "time", "s"),
    ("efficiency.path_length_mm", "path length", "mm"),
    ("visibility.hidden_removed_fraction", "removed while the burr was hidden", ""),
)
PARTS = ("safety", "final_product", "visibility", "efficiency")


def tool_entry(params: toolconfig.ToolParameters) -> dict:
    """What a recording keeps of a tool: the burr type and radius the assessment reads, and every parameter to rebuild it."""
    parameters = asdict(params)
    parameters["cuttable_segment_ids"] = list(parameters["cuttable_segment_ids"])
    return {"name": f"{params.shape} {params.burr_type} {params.diameter:g} mm", "burr_type": params.burr_type,
            "radius_mm": params.diameter / 2.0, "parameters": parameters}


def scan_descriptor(session) -> dict | None:
    """The assessment's descriptor of the session's scan, when the assessment rebuilds it on the same voxel grid.

    The user's own scan with their segmentation is named by its files and
    the roles given on the page when the recording is taken (by name).
    """
    cut_node = session.cut_node
    if session.source == "own" and session.inputs.get("segmentation") is not None:
        if not cut_node.GetCuttableSegmentIDs():
            return None
        return scans.own_descriptor(session.volume, session.segmentation, list(cut_node.GetCuttableSegmentIDs()),
                                    list(cut_node.GetProtectedSegmentIDs()), session.inputs["ct"],
                                    session.inputs["segmentation"], session.inputs.get("color_table"))
    if session.source == "phantom":
        scan = scans.phantom_scan(dimensions=list(sessionlib.PHANTOM_DIMENSIONS), spacing=list(sessionlib.PHANTOM_SPACING), seed=0)
    elif session.source == "headct":
        scan = scans.head_ct_scan()
    else:
        return None
    matrix = vtk.vtkMatrix4x4()
    session.volume.GetIJKToRASMatrix(matrix)
    grid = {"dimensions": list(session.volume.GetImageData().GetDimensions()),
            "ijk_to_ras": [matrix.GetElement(r, c) for r in range(4) for c in range(4)]}
    return scan.descriptor() if scans.same_grid(grid, scan.grid()) else None


class WebSessionRecording:
    """The recording of a drilling session, kept as it happens (see the module docstring)."""

    def __init__(self, session, clock=None):
        self.session = session
        self._clock = clock
        self.recorder = None
        self._cut_node = None
        self._tools = {}  # tool key -> recorded entry
        self._stroke_action = None
        self._stroke_open = False
        self._contacts_seen = 0
        session.stroke_listener = self

    # -- the recorder of the current data

    def _current(self):
        """The recorder of the data now loaded (new data: a new recording); None without data."""
        if not self.session.has_data:
            return None
        if self.session.cut_node is not self._cut_node:
            self._cut_node = self.session.cut_node
            options = {"clock": self._clock} if self._clock is not None else {}
            self._tools = {}
            self.recorder = recordings.SessionRecorder(self._tools, description=f"Web session on {self.session.description}",
                                                       **options)
            self._stroke_open = False
            table = self.session.logic.GetContactTableNode(self._cut_node)
            self._contacts_seen = table.GetNumberOfRows() if table is not None else 0
        return self.recorder

    def _tool_key(self) -> str:
        entry = tool_entry(toolconfig.from_tool_node(self.session.tool_node))
        for key, known in self._tools.items():
            if known == entry:
                return key
        key = f"tool{len(self._tools) + 1}"
        self._tools[key] = entry
        return key

    # -- DrillSession.stroke_listener

    def stroke_began(self, restore: bool) -> None:
        if self._current() is not None:
            self._stroke_action = "restore" if restore else "cut"
            self._stroke_open = False  # the recorder's stroke opens with its first pose, which gives the rotation

    def tool_moved(self, pose) -> None:
        recorder = self._current()
        if recorder is None or self._stroke_action is None:
            return
        if not self._stroke_open:
            rotation = [[pose.GetElement(r, c) for c in range(3)] for r in range(3)]
            recorder.begin_stroke(self._tool_key(), self._stroke_action, rotation)
            self._stroke_open = True
        # The session tells after the logic moved the tool: the monitor reads at this pose.
        monitor = self.session.logic.GetNerveMonitor(self.session.cut_node)
        if monitor is not None and "monitor" not in recorder.recording:
            recorder.monitor(monitor)
        recorder.pose([pose.GetElement(r, 3) for r in range(3)], readings=recordings.monitor_readings(monitor))

    def stroke_ended(self) -> None:
        recorder = self._current()
        self._stroke_action = None
        if recorder is None or not self._stroke_open:
            return
        self._stroke_open = False
        recorder.end_stroke()
        self._after_change()

    def edited(self, kind: str) -> None:
        if self._current() is not None:
            self.recorder.event(kind)
            self._after_change()

    def _after_change(self) -> None:
        """The contacts since the last change, and the removed volume per segment now."""
        logic, cut_node = self.session.logic, self.session.cut_node
        table = logic.GetContactTableNode(cut_node)
        for row in range(self._contacts_seen, table.GetNumberOfRows() if table is not None else 0):
            self.recorder.event("contact", segment=table.GetCellText(row, 0), depth_mm=float(table.GetCellText(row, 3)))
        self._contacts_seen = table.GetNumberOfRows() if table is not None else 0
        segmentation = self.session.segmentation.GetSegmentation()
        self.recorder.removed({segment_id: logic.GetRemovedVolumeInSegment(cut_node, segment_id)
                               for segment_id in segmentation.GetSegmentIDs()})

    # -- rendered frames

    def watch(self, area) -> None:
        """Record the camera of the frames the 3D view's area draws (its full view and its fast preview)."""
        for view in (area.main_view, area.preview_view):
            renderer = view.renderer()
            view.render_window().AddObserver(vtk.vtkCommand.EndEvent,
                                             lambda *_, renderer=renderer: self.frame_rendered(renderer.GetActiveCamera()))

    def frame_rendered(self, camera) -> None:
        """A frame of the 3D view was drawn with ``camera``: its camera is recorded (every frame, as the trainee saw it)."""
        recorder = self._current()
        if recorder is not None:
            recorder.camera(camera.GetPosition(), camera.GetFocalPoint(), camera.GetViewUp(), camera.GetViewAngle())

    @property
    def camera_frame_count(self) -> int:
        """The cameras recorded for the data now loaded (one per frame drawn since it was loaded)."""
        return len(self.recorder.recording["camera"]["frames"]) if self.recorder is not None and self._cut_node is self.session.cut_node else 0

    # -- what leaves the session

    @property
    def stroke_count(self) -> int:
        return len(self.recorder.recording["strokes"]) if self.recorder is not None and self._cut_node is self.session.cut_node else 0

    def snapshot(self, trainee: str | None = None) -> dict:
        """The session so far as a version 2 recording (no sha256: ``recording.save`` and ``to_json`` add it)."""
        recorder = self._current()
        if recorder is None:
            raise sessionlib.SessionError("Load a scan and drill first: there is no session to record yet")
        recording = json.loads(json.dumps(recorder.recording))  # a copy the session no longer changes
        recording["tools"] = {key: dict(entry) for key, entry in self._tools.items()}
        recording["trainee"] = trainee or None
        descriptor = scan_descriptor(self.session)
        if descriptor is not None:
            recording["scan"] = descriptor
        return recording


def to_json(recording: dict) -> bytes:
    """The file of a recording, as ``recording.save`` writes it: its sha256 inside."""
    return (json.dumps(dict(recording, sha256=recordings.content_sha256(recording)), separators=(",", ":")) + "\n").encode()


def replay_in(session, recording: dict) -> dict:
    """Drill ``recording`` into ``session`` (loaded with the same data) through the logic; ``recording.replay``'s counts.

    The tools are rebuilt from the parameters the recording keeps and
    removed again afterwards; the session's own tool stays active.
    """
    recordings.check(recording, "the recording", require_checksum=False)
    session._require_data()
    created, tool_nodes = [], {}
    try:
        for key, entry in recording.get("tools", {}).items():
            if "parameters" not in entry:
                raise recordings.RecordingError(f"the recording's tool '{key}' lacks the parameters that rebuild it")
            parameters = dict(entry["parameters"], cuttable_segment_ids=tuple(entry["parameters"]["cuttable_segment_ids"]))
            node = toolconfig.create_tool_node(session.scene, toolconfig.ToolParameters(**parameters), f"Replay {key}")
            created += [node, session.scene.GetNodeByID(node.GetTransformNodeID())]
            tool_nodes[key] = node
        return recordings.replay(session.logic, session.cut_node, recording, tool_nodes)
    finally:
        session.cut_node.SetAndObserveActiveToolNodeID(session.tool_node.GetID())
        owndata.remove_nodes(session.scene, *reversed([n for n in created if n is not None]))


def reference_for(scan: scans.Scan) -> dict | None:
    """The shipped careful mastoidectomy on the scan, when the assessment has one for it."""
    if scan.name not in ("phantom", "headct") or scan.entry is None:
        return None
    return sessions.careful(scan)


def grade(recording: dict, path=None) -> metriclib.Assessment:
    """The assessment of a web recording (``path``: where its file is), against the careful session where there is one."""
    scan = scans.from_descriptor(recording.get("scan"))
    reference = reference_for(scan)
    return metriclib.assess(recording, scan, reference, recording_path=path,
                            reference_path=f"the careful mastoidectomy on the {scan.name} (assessment.sessions)" if reference else None)


def _shown(value) -> str:
    if value is None:
        return "—"
    if isinstance(value, float):
        return f"{value:.3g}" if abs(value) < 1000 else f"{value:.0f}"
    return str(value)


class ReportPanel:
    """The Report panel: grade the session so far, download its recording and report, save it to the records."""

    def __init__(self, server, recording: WebSessionRecording, records_url: str | None = None, progress=None):
        self.server = server
        self.work_directory = recording.session.work_directory
        self.recording = recording
        self.records_url = records_url
        self.progress = progress
        self.assessment = None
        self.graded = None  # the recording the report is of
        server.state.update({"vc_rp_busy": False, "vc_rp_error": "", "vc_rp_score": None, "vc_rp_parts": [],
                             "vc_rp_metrics": [], "vc_rp_plots": [], "vc_rp_about": "", "vc_rp_trainee": "",
                             "vc_rp_saved": "", "vc_rp_strokes": 0, "vc_rp_names": {"recording": "session.json",
                                                                                     "report": "report.html"}})
        server.trigger("vc_rp_grade")(self.grade)
        server.trigger("vc_rp_recording")(self.download_recording)
        server.trigger("vc_rp_html")(self.download_html)
        server.trigger("vc_rp_save")(self.save)

    def refresh_counts(self) -> None:
        self.server.state.vc_rp_strokes = self.recording.stroke_count

    async def grade(self) -> None:
        state = self.server.state
        if state.vc_rp_busy:
            return
        with state:
            state.vc_rp_busy, state.vc_rp_error, state.vc_rp_saved = True, "", ""
        await asyncio.sleep(0.05)  # the page shows that the grading runs
        try:
            snapshot = self.recording.snapshot((state.vc_rp_trainee or '').strip() or None)
            if not snapshot["strokes"]:
                raise sessionlib.SessionError("Nothing to grade yet: drill first (Drill mode, press and drag on the bone)")
            if "scan" not in snapshot:
                raise sessionlib.SessionError("This scan is not one the assessment can rebuild (the phantom, the example "
                                              "head CT, or your CT with your segmentation and its cuttable segments): "
                                              "the recording can be downloaded, not graded here")
            # The server keeps what it graded: the records name the file, and it outlives the page.
            stamp = snapshot["started"].replace(":", "").replace("+0000", "Z")
            path = recordings.save(snapshot, self.work_directory / "recordings" / f"session-{stamp}-{len(snapshot['strokes'])}.json")
            assessment = grade(snapshot, path)
            self._show(assessment)
            self.assessment, self.graded = assessment, snapshot
        except (sessionlib.SessionError, recordings.RecordingError, scans.ScanError, metriclib.AssessmentError) as error:
            state.vc_rp_error = str(error)
        finally:
            with state:
                state.vc_rp_busy = False

    def _show(self, assessment) -> None:
        state = self.server.state
        found = assessment.metrics
        state.vc_rp_score = assessment.score
        state.vc_rp_parts = [{"name": part.replace("_", " "), "key": part,
                              "value": None if assessment.parts[part] is None else round(100.0 * assessment.parts[part], 1)}
                             for part in PARTS]
        state.vc_rp_metrics = [{"key": key, "name": name, "value": found[key], "shown": _shown(found[key]), "unit": unit}
                               for key, name, unit in KEY_METRICS if key in found]
        plots = [("Distance to the structures at risk", reportlib.distance_plot(assessment)),
                 ("Removal per region", reportlib.removal_plot(assessment)),
                 ("Against the reference", reportlib.region_bars(assessment))]
        state.vc_rp_plots = [{"title": title, "src": f"data:image/png;base64,{png}"} for title, png in plots if png]
        reference = "against the shipped careful mastoidectomy" if assessment.reference else "without a reference"
        state.vc_rp_about = (f"{found.get('efficiency.strokes', 0)} strokes on the {assessment.session['scan']}, {reference}; recording sha256 {assessment.session['sha256'][:12]}…")
        stamp = assessment.session["started"].replace(":", "").replace("+0000", "Z")
        state.vc_rp_names = {"recording": f"session-{stamp}.json", "report": f"report-{stamp}.html"}

    def download_recording(self):
        try:
            content = to_json(self.recording.snapshot((self.server.state.vc_rp_trainee or '').strip() or None))
        except sessionlib.SessionError as error:
            self.server.state.vc_rp_error = str(error)
            return None
        return self.server.protocol.addAttachment(content)

    def download_html(self):
        if self.assessment is None:
            self.server.state.vc_rp_error = "Grade the session first (Report)"
            return None
        return self.server.protocol.addAttachment(reportlib.html_report(self.assessment).encode())

    def save(self) -> None:
        state = self.server.state
        trainee = (state.vc_rp_trainee or "").strip()
        if self.assessment is None:
            state.vc_rp_saved = "Grade the session first (Report)"
            return
        if not trainee:
            state.vc_rp_saved = "Give the trainee's name first"
            return
        document = self.assessment.to_dict()
        document["session"] = dict(document["session"], trainee=trainee)
        try:
            stored, message = pending.store_or_keep(self.records_url, trainee, document)
        except RecordsAssessmentError as error:
            state.vc_rp_saved = f"The records refused the assessment: {error}"
            return
        state.vc_rp_saved = ("Saved: " if stored is not None else "Not saved yet: ") + message
        if stored is not None and self.progress is not None and self.progress._records is not None:
            self.progress.refresh()

    def build(self) -> None:
        with v3.VExpansionPanel(value="report"):
            v3.VExpansionPanelTitle("Report", raw_attrs=['data-testid="report-panel"'])
            with v3.VExpansionPanelText():
                html.Div("The session is recorded: {{ vc_rp_strokes }} strokes so far.", classes="text-caption",
                         raw_attrs=['data-testid="report-strokes"'])
                with html.Div(classes="d-flex flex-wrap ga-1 mt-1"):
                    v3.VBtn("Grade the session", size="small", color="primary", prepend_icon="mdi-clipboard-check-outline",
                            loading=("vc_rp_busy",), click="trigger('vc_rp_grade')", raw_attrs=['data-testid="report-grade"'])
                    v3.VBtn("Recording", size="small", variant="tonal", prepend_icon="mdi-download",
                            click="trigger('vc_rp_recording').then((content) => content && "
                                  "utils.download(vc_rp_names.recording, content, 'application/json'))",
                            raw_attrs=['data-testid="report-download-recording"'])
                    v3.VBtn("Report (HTML)", size="small", variant="tonal", prepend_icon="mdi-file-chart-outline",
                            v_if="vc_rp_score !== null",
                            click="trigger('vc_rp_html').then((content) => content && "
                                  "utils.download(vc_rp_names.report, content, 'text/html'))",
                            raw_attrs=['data-testid="report-download-html"'])
                with html.Div(v_if="vc_rp_score !== null", classes="mt-2", raw_attrs=['data-testid="report-result"']):
                    html.Div("Score {{ vc_rp_score.toFixed(1) }} / 100", classes="text-h5",
                             raw_attrs=['data-testid="report-score"', ':data-score="vc_rp_score"'])
                    html.Div("{{ vc_rp_about }}", classes="text-caption")
                    with html.Div(classes="d-flex flex-wrap ga-2 text-body-2"):
                        html.Span("{{ p.name }} {{ p.value === null ? 'n/a' : p.value.toFixed(1) }}",
                                  v_for="p in vc_rp_parts", key="p.key", raw_attrs=[':data-part="p.key"'])
                    with v3.VTable(density="compact", style="font-size: 13px", raw_attrs=['data-testid="report-metrics"']):
                        with html.Tbody():
                            with html.Tr(v_for="m in vc_rp_metrics", key="m.key",
                                         raw_attrs=[':data-metric="m.key"', ':data-value="m.value"']):
                                html.Td("{{ m.name }}", style="padding: 0 4px")
                                html.Td("{{ m.shown }} {{ m.unit }}", classes="text-right", style="padding: 0 4px")
                    with html.Div(v_for="p in vc_rp_plots", key="p.title", classes="mt-1"):
                        html.Img(src=("p.src",), alt=("p.title",), style="width: 100%", raw_attrs=[':data-plot="p.title"'])
                v3.VAlert(v_if="vc_rp_error", text=("vc_rp_error",), type="warning", density="compact", classes="mt-2",
                          raw_attrs=['data-testid="report-error"'])
                with html.Div(classes="d-flex align-center ga-1 mt-2"):
                    v3.VTextField(v_model=("vc_rp_trainee",), label="Trainee", density="compact", hide_details=True,
                                  raw_attrs=['data-testid="report-trainee"'])
                    v3.VBtn("Save to my records", size="small", variant="tonal", disabled=("vc_rp_score === null",),
                            click="trigger('vc_rp_save')", raw_attrs=['data-testid="report-save"'])
                html.Div("{{ vc_rp_saved }}", v_if="vc_rp_saved", classes="text-caption mt-1",
                         raw_attrs=['data-testid="report-saved"'])
