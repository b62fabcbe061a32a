"""The VolumeCutting web application: segmentation, then drill, in the browser (trame-slicer).

    python -m VolumeCuttingLib.webapp [--port N] [--host H] [--phantom | --ct PATH [--segmentation PATH]]
                                      [--data-dir DIR ...] [--max-upload-mb N] [--server]
                                      [--openigtlink PORT [--openigtlink-host HOST]]

One page: a 3D view drawn by ``vtkMRMLVolumeCutDisplayableManager`` (the cut
anatomy through the product's ray caster) and three slice views with the cut
region's outline (``vtkMRMLVolumeCutSliceDisplayableManager``); panels for
the data, the segments and their roles, the tool, the drill, SoftCut
(soft-tissue resection: outline on the skin, depth preview, carve,
measurements, STL) and the exports.
Rendering happens here (offscreen; Mesa llvmpipe without a GPU) and trame-rca
streams the images.

With ``--openigtlink PORT`` desktop Slicer (SlicerOpenIGTLink) mirrors the
session and may drive the tool (``collaboration.igtlbridge``).

One process serves one session (one scene). More users get a process each
through trame's launcher (see the README); a second tab on the same process
is told so and may take over, nothing is lost. An instructor joins a
session with its own link (``instructorlink``): they watch, point, draw a
guide axis, freeze the drill, undo, and drill when the trainee accepts.
"""

from __future__ import annotations

import asyncio
import os
import time
import zipfile
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path

import slicer
import vtk
from trame.app import TrameApp
from trame.ui.vuetify3 import SinglePageWithDrawerLayout
from trame.widgets import client, html
from trame.widgets import vuetify3 as v3
from trame_slicer import module as trame_slicer_module
from trame_slicer.app.logic import get_view_trame_id
from trame_slicer.app.ui import create_vertical_slice_view_gutter_ui
from trame_slicer.core import LayoutManager, SlicerApp
from trame_slicer.rca_view.rca_view_factory import RemoteViewFactory
from trame_slicer.views import Layout, LayoutDirection, ViewLayoutDefinition, ViewType
from trame_client.widgets.core import HtmlElement
from trame_client.widgets.vue import Template
from trame_server.utils.asynchronous import create_task
from wslink.websocket import LinkProtocol

from ..collaboration import igtloptions
from ..config import toolconfig
from ..data import headct, owndata
from ..jobs import softcutjob
from . import instructorlink, monitormeter, progress, rendering, sessionrecording, soundfeed, views
from .session import (NORMAL_MODES, SOFTCUT_DEPTH_RANGE_MM, SOFTCUT_DEPTH_STEP_MM, SOFTCUT_MEASUREMENTS, DrillSession,
                      SessionError, SoftCutSession)

WWW = Path(__file__).with_name("www")
CLIENT_MODULE = {"serve": {"__volumecutting": str(WWW)},
                 "scripts": ["__volumecutting/volumecutting.js", "__volumecutting/drillsound.js",
                             "__volumecutting/monitormeter.js"]}

LAYOUT_ID = "volumecutting"
# VOLUMECUTTING_WEBAPP_TRACE=1 prints each frame of the 3D view (window, size, time).
TRACE = os.environ.get("VOLUMECUTTING_WEBAPP_TRACE") == "1"
THREE_D_TAG = "ThreeD"
MONITOR_REFRESH_S = 0.1  # the nerve monitor's meter and tint follow the tool at up to 10 Hz

ROLE_ITEMS = [
    {"title": "cuttable", "value": toolconfig.ROLE_CUTTABLE},
    {"title": "protected", "value": toolconfig.ROLE_PROTECTED},
    {"title": "none", "value": toolconfig.ROLE_NONE},
]
SOURCE_ITEMS = [
    {"title": "Example head CT", "value": "headct"},
    {"title": "Temporal-bone phantom", "value": "phantom"},
    {"title": "My own scan", "value": "own"},
]
EXPORT_FILES = {
    "stl": ("removed.stl", "model/stl"),
    "segmentation": ("removed.seg.nrrd", "application/octet-stream"),
    "drilled_ct": ("drilled.nrrd", "application/octet-stream"),
    "scene": ("drilled.mrb", "application/zip"),
}


@dataclass
class Options:
    """What the command line sets (see ``add_arguments``)."""

    source: str = "headct"
    ct: Path | None = None
    segmentation: Path | None = None
    cuttable: str = ""  # segment names, comma-separated, with --segmentation
    protected: str = ""
    data_dirs: list[Path] = field(default_factory=list)
    max_upload_mb: float = 512.0
    navigate_scale: float = 0.5
    navigate_fps: float = 20.0
    drill_scale: float = 0.5
    refine_delay_s: float = 0.5
    work_dir: Path | None = None
    records: str | None = None
    openigtlink: igtloptions.BridgeOptions | None = None  # off unless --openigtlink PORT
    test_hooks: bool = False  # triggers only automated tests may call (--test-hooks)

    @property
    def max_upload_bytes(self) -> int:
        return int(self.max_upload_mb * 1024 * 1024)


def add_arguments(parser) -> None:
    group = parser.add_argument_group("VolumeCutting")
    data = group.add_mutually_exclusive_group()
    data.add_argument("--phantom", action="store_true", help="start with the temporal-bone phantom")
    data.add_argument("--ct", type=Path, default=None,
                      help="start with this CT: a DICOM series folder, .nrrd, .nii, .nii.gz, .mha (default: the example head CT)")
    group.add_argument("--segmentation", type=Path, default=None, help="its segmentation (.seg.nrrd or labelmap), with --ct")
    group.add_argument("--cuttable", default="", metavar="NAMES",
                       help="with --segmentation: comma-separated names of the segments the drill may cut "
                            "(default: none; the Segments panel sets roles too)")
    group.add_argument("--protected", default="", metavar="NAMES",
                       help="with --segmentation: comma-separated names of the segments the drill must not cut")
    group.add_argument("--data-dir", type=Path, action="append", default=[],
                       help="a folder whose files users may load by path (repeatable; default: the download cache)")
    group.add_argument("--max-upload-mb", type=float, default=Options.max_upload_mb, help="largest upload accepted (MB)")
    group.add_argument("--navigate-scale", type=float, default=Options.navigate_scale,
                       help="render scale of the 3D view while the camera moves (refined when the mouse stops)")
    group.add_argument("--navigate-fps", type=float, default=Options.navigate_fps,
                       help="frames per second the 3D view keeps while the camera moves: the ray caster casts as many "
                            "rays as fit (full quality when the mouse stops)")
    group.add_argument("--drill-scale", type=float, default=Options.drill_scale, help="render scale of the 3D view while drilling")
    group.add_argument("--work-dir", type=Path, default=None, help="folder for uploads and exports (default: a temporary one)")
    group.add_argument("--records", default=None, metavar="URL",
                       help="trainee records for the Progress panel: SQLAlchemy URL or SQLite file "
                            "(default: $VOLUMECUTTING_RECORDS or ~/.local/share/volumecutting/records.sqlite)")
    group.add_argument("--test-hooks", action="store_true",
                       help="for automated tests only: let a page ask for the checksum of the whole cut field "
                            "(trigger vc_co_checksum); leave off when serving users")
    igtloptions.add_arguments(parser)


def options_from_arguments(args) -> Options:
    if args.segmentation is not None and args.ct is None:
        raise SystemExit("--segmentation goes with --ct")
    if (args.cuttable or args.protected) and args.segmentation is None:
        raise SystemExit("--cuttable and --protected name segments of --segmentation: give it (with --ct)")
    for name in ("navigate_scale", "drill_scale"):
        value = getattr(args, name)
        if not 0.05 <= value <= 1.0:
            raise SystemExit(f"--{name.replace('_', '-')} {value}: give a fraction between 0.05 and 1")
    if not 1.0 <= args.navigate_fps <= 120.0:
        raise SystemExit(f"--navigate-fps {args.navigate_fps}: give a rate between 1 and 120 frames per second")
    if args.max_upload_mb <= 0:
        raise SystemExit(f"--max-upload-mb {args.max_upload_mb}: give a positive size")
    data_dirs = [Path(d).expanduser().resolve() for d in args.data_dir] or [headct.default_cache_dir().resolve()]
    source = "phantom" if args.phantom else "own" if args.ct is not None else "headct"
    try:
        openigtlink = igtloptions.options_from_arguments(args)
    except ValueError as error:
        raise SystemExit(str(error)) from None
    return Options(source=source, ct=args.ct, segmentation=args.segmentation, cuttable=args.cuttable,
                   protected=args.protected, data_dirs=data_dirs,
                   max_upload_mb=args.max_upload_mb, navigate_scale=args.navigate_scale, drill_scale=args.drill_scale,
                   navigate_fps=args.navigate_fps, work_dir=args.work_dir, records=args.records, openigtlink=openigtlink,
                   test_hooks=args.test_hooks)


def path_allowed(path: Path, folders) -> bool:
    """Whether ``path`` (symbolic links resolved) lies inside one of ``folders``."""
    resolved = Path(path).expanduser().resolve()
    return any(resolved == folder or folder in resolved.parents for folder in folders)


def unpack_upload(written: list[Path], folder: Path, max_bytes: int) -> Path:
    """The path to load from uploaded files: the file, the folder of a series, or what a .zip holds.

    A .zip is unpacked into ``folder``/unpacked, refusing members that would
    land outside it and contents larger than ``max_bytes``.
    """
    if len(written) == 1 and written[0].suffix.lower() == ".zip":
        archive = written[0]
        with zipfile.ZipFile(archive) as bundle:
            members = [member for member in bundle.infolist() if not member.is_dir()]
            size = sum(member.file_size for member in members)
            if size > max_bytes:
                raise SessionError(f"{archive.name}: unpacked it holds {size / 2**20:.1f} MB, more than this server "
                                   f"accepts ({max_bytes / 2**20:.1f} MB)")
            target = (folder / "unpacked").resolve()
            for member in members:
                destination = (target / member.filename).resolve()
                if target not in destination.parents:
                    raise SessionError(f"{archive.name}: holds a path outside its folder ({member.filename}); not unpacked")
            for member in members:
                destination = target / member.filename
                destination.parent.mkdir(parents=True, exist_ok=True)
                destination.write_bytes(bundle.read(member))
        archive.unlink()
        unpacked = [path for path in target.rglob("*") if path.is_file()]
        return unpacked[0] if len(unpacked) == 1 else target
    return written[0] if len(written) == 1 else folder


class ConnectionWatch(LinkProtocol):
    """Tells the application when a browser tab joins with a secret (the trainee's or the instructor's)
    or goes away (closed, reloaded, network lost)."""

    def __init__(self, application):
        super().__init__()
        self._application = application

    async def validateToken(self, token, client_id):
        # wslink asks the link protocols instead of comparing with its own key: a page without either secret
        # is refused here and sent nothing.
        return self._application.instructor.validate(token, str(client_id))

    def onClose(self, client_id):
        self._application.client_closed(str(client_id))


class VolumeCuttingApp(TrameApp):
    """The application of one session (see the module's docstring)."""

    def __init__(self, server=None, options: Options | None = None):
        super().__init__(server)
        self.options = options or Options()
        self.server.enable_module(trame_slicer_module)
        self.server.enable_module(CLIENT_MODULE)
        self.slicer_app = SlicerApp()
        logic = self.slicer_app.register_module_logic(slicer.vtkSlicerVolumeCuttingLogic(), logic_name="VolumeCutting")
        self.session = DrillSession(self.slicer_app.scene, logic, self.options.work_dir)
        self.drill = views.DrillController(self.session)
        self.drill.on_stroke_begin = self._on_stroke_begin
        self.drill.on_stroke_moved = self._on_stroke_moved
        self.drill.on_stroke_end = self._on_stroke_end
        self.drill.on_hover = self._on_hover
        self.drill.on_depth_changed = self._on_depth_changed
        self.softcut = SoftCutSession(self.session)
        self.sound = soundfeed.SoundFeed(self.session, self.state)
        # The tint shows where the burr is seen: not while its glyph is hidden (off the bone, or before any pose).
        self.monitor_meter = monitormeter.MonitorMeter(self.session, self.state, tool_shown=lambda: self.drill.placed)
        self.drill.on_placed_changed = self._request_monitor_refresh
        self._monitor_task = None
        self.drill.on_outline_pick = self._on_outline_pick
        self._outline_model = None
        self._pipeline_creator = slicer.vtkMRMLLayerDMPipelineScriptedCreator()
        self._pipeline_creator.SetPythonCallback(self._create_pipeline)
        slicer.vtkMRMLLayerDMPipelineFactory.GetInstance().AddPipelineCreator(self._pipeline_creator)
        self._contact_observer = None
        self._observed_cut_node = None
        self.drill.stroke_refusal = lambda: self.instructor.stroke_refusal()
        self.instructor = instructorlink.InstructorLink(self)
        self._upload_names: dict[str, str] = {}
        self._last_table_refresh = 0.0
        self._table_refresh_task = None
        self.progressive = None
        # For tests and benchmarks (vc_diagnostics): events as applied, when each 3D frame began, each 3D frame
        # (window, start ms, duration ms, width, height, pixels per ray each way) and when the data was ready.
        # The Ready message of data whose first picture has not reached the page yet (its 3D view had no size).
        self._ready_when_shown = None
        self.timing = {"events": deque(maxlen=20000), "renders": deque(maxlen=20000), "frames": deque(maxlen=20000),
                       "ready_at": None}
        self.server.add_protocol_to_configure(lambda protocol: protocol.registerLinkProtocol(ConnectionWatch(self)))
        self._register_views()
        self._initialize_state()
        self.progress = progress.ProgressPanel(self.server, self.options.records)
        self.recording = sessionrecording.WebSessionRecording(self.session)
        self.report = sessionrecording.ReportPanel(self.server, self.recording, self.options.records, self.progress)
        self._build_ui()
        self._connect_three_d_view()
        self.recording.watch(self._three_d_factory.areas[THREE_D_TAG])
        self.igtl = None
        self._igtl_task = None
        if self.options.openigtlink is not None:
            from ..collaboration import igtlbridge  # pyigtl only when asked for

            self.igtl = igtlbridge.IgtlBridge(self.options.openigtlink).start()
            self.igtl.on_tool_driven = self._on_remote_tool
            print(f"OpenIGTLink bridge on {self.igtl.address}", flush=True)

    def _request_monitor_refresh(self, delay_s: float = MONITOR_REFRESH_S) -> None:
        """The meter and the tint follow the tool at most every ``delay_s``, after the pose that asked."""
        if self._monitor_task is None or self._monitor_task.done():
            self._monitor_task = create_task(self._refresh_monitor_later(delay_s))

    async def _refresh_monitor_later(self, delay_s: float) -> None:
        await asyncio.sleep(delay_s)
        try:
            if self.monitor_meter.refresh():
                self.state.flush()
        except Exception as error:  # a reading gone bad must not stop the drilling
            print(f"[monitor] {error}", flush=True)
            return
        # The distance fields are built on a worker after a load: look again until every structure is ready.
        if any(row["mm"] is None for row in self.monitor_meter.shown):
            self._monitor_task = None
            self._request_monitor_refresh(0.5)

    # ------------------------------------------------------------------ views

    def _register_views(self) -> None:
        manager = self.slicer_app.view_manager
        common = dict(target_fps=60.0, blur_fps=5.0, interactive_quality=60, rca_event_throttle_s=0.01)
        self._three_d_factory = rendering.ProgressiveThreeDViewFactory(self.server, populate_view_ui_f=self._three_d_view_ui,
                                                                       **common)
        manager.register_factory(self._three_d_factory)
        manager.register_factory(RemoteViewFactory(self.server, views.VolumeCutSliceView, ViewType.SLICE_VIEW,
                                                   populate_view_ui_f=create_vertical_slice_view_gutter_ui, **common))
        self.layout_manager = LayoutManager(self.slicer_app.scene, manager, self.server)
        three_d = ViewLayoutDefinition.threed_view(name=THREE_D_TAG)
        slices = Layout(LayoutDirection.Vertical, [ViewLayoutDefinition.axial_view(), ViewLayoutDefinition.coronal_view(),
                                                   ViewLayoutDefinition.sagittal_view()], flex_sizes=["1", "1", "1"])
        self.layout_manager.register_layout(LAYOUT_ID, Layout(LayoutDirection.Horizontal, [three_d, slices],
                                                              flex_sizes=["3", "1"]))
        self.layout_manager.set_layout(LAYOUT_ID)

    def _three_d_view_ui(self, server, view_id, view) -> None:
        """Over the 3D view: camera buttons, and the contact warning with the view's red frame."""
        with html.Div(classes="view-gutter", style="position: absolute; top: 0; left: 0; z-index: 2;"), \
                html.Div(classes="d-flex flex-column pa-2"):
            with v3.VBtn(size="small", variant="text", icon=True, click=self.reset_camera, raw_attrs=['data-testid="reset-camera"']):
                v3.VIcon("mdi-camera-flip-outline", color="white")
                v3.VTooltip("Look at the patient's right side", activator="parent", location="right")
        # The view's area, for tests and benchmarks (it lets the mouse through).
        html.Div(style="position: absolute; inset: 0; pointer-events: none;", raw_attrs=['data-testid="three-d-view"'])
        html.Div(v_show="vc_contact", style="position: absolute; inset: 0; border: 4px solid #ff1a1a; pointer-events: none; z-index: 2;")
        with html.Div(v_show="vc_contact", raw_attrs=['data-testid="contact-warning"'],
                      style="position: absolute; top: 8px; left: 50%; transform: translateX(-50%); z-index: 3; "
                            "background: #d50000; color: white; padding: 6px 14px; border-radius: 4px; "
                            "font-weight: 600; pointer-events: none;"):
            html.Span("{{ vc_contact }}")
            v3.VBtn("Make {{ vc_contact_fix && vc_contact_fix.name }} cuttable", v_if="vc_contact_fix", size="small",
                    variant="outlined", color="white", classes="ml-3", style="pointer-events: auto;",
                    click="trigger('vc_set_role', [vc_contact_fix.id, 'cuttable']); vc_contact = ''; vc_contact_fix = null",
                    raw_attrs=['data-testid="make-cuttable"'])
        html.Div("{{ vc_mode_hint }}", style="position: absolute; bottom: 8px; left: 12px; z-index: 2; color: white; "
                 "text-shadow: 0 0 3px black; pointer-events: none; font-size: 13px;")
        self.instructor.three_d_overlay()

    def _create_pipeline(self, view_node, display_node):
        pipeline = self.drill.create_pipeline(view_node, display_node)
        if pipeline is not None:
            tag = view_node.GetSingletonTag()
            previews = self._three_d_factory.previews
            preview_of = tag[: -len(rendering.PREVIEW_SUFFIX)] if tag.endswith(rendering.PREVIEW_SUFFIX) else None
            pipeline.view = previews.get(preview_of) if preview_of else self.slicer_app.view_manager.get_view(tag)
        return pipeline

    @property
    def three_d_view(self) -> views.VolumeCutThreeDView:
        return self.slicer_app.view_manager.get_view(THREE_D_TAG)

    def _connect_three_d_view(self) -> None:
        rca_view = self._three_d_factory.get_factory_view(THREE_D_TAG)
        area = self._three_d_factory.areas[THREE_D_TAG]
        self.progressive = rendering.ProgressiveRendering(area, self._three_d_factory.schedulers[THREE_D_TAG],
                                                          self.options.navigate_scale, self.options.drill_scale,
                                                          self.options.refine_delay_s, navigate_fps=self.options.navigate_fps)
        self.drill.depth_sources = lambda: [area.main_view.surface_depth, area.preview_view.surface_depth]
        adapter = rca_view.view_adapter
        handle = adapter.on_interaction

        def on_interaction(origin, event):
            # Only the page in control steers the session (the instructor link's gate drops the others' events).
            sender = self._sender()
            if sender and not self.instructor.cosession.may(sender, "drive"):
                return
            received = time.time() * 1000.0
            handle(origin, event)
            if TRACE:
                print(f"[event] {event.get('type')} {time.time() * 1000.0 - received:.1f} ms", flush=True)
            self.timing["events"].append((event.get("type", ""), received, time.time() * 1000.0,
                                          event.get("x"), event.get("y")))

        adapter.on_interaction = on_interaction
        self._three_d_factory.schedulers[THREE_D_TAG].on_frame_sent = self._three_d_frame_sent
        interactor = area.main_view.interactor()
        for event in ("LeftButtonPressEvent", "MiddleButtonPressEvent", "RightButtonPressEvent"):
            interactor.AddObserver(event, lambda *_: self.progressive.button_pressed(), 10.0)
        for event in ("LeftButtonReleaseEvent", "MiddleButtonReleaseEvent", "RightButtonReleaseEvent"):
            # Before the interactor style, which may take the event for itself.
            interactor.AddObserver(event, lambda *_: self.progressive.button_released(), 10.0)
        for name, view in (("main", area.main_view), ("preview", area.preview_view)):
            window = view.render_window()
            window.AddObserver(vtk.vtkCommand.StartEvent, lambda *_: self._render_started())
            window.AddObserver(vtk.vtkCommand.EndEvent, lambda w, _e, name=name, view=view: self._render_ended(name, view))
        self.state.vc_three_d_area = get_view_trame_id(self.server, area.main_view)

    def _three_d_frame_sent(self) -> None:
        """The page says Ready only once the data's first picture is on its way: never over a black view."""
        if self._ready_when_shown is None or not self.session.has_data or not self._three_d_factory.areas[THREE_D_TAG].sized:
            return
        text, self._ready_when_shown = self._ready_when_shown, None
        self.timing["ready_at"] = time.time() * 1000.0
        with self.state:
            self.state.vc_status = text

    def _render_started(self) -> None:
        self._render_start = time.time() * 1000.0
        self.timing["renders"].append(self._render_start)

    def _render_ended(self, name, view) -> None:
        width, height = view.render_window().GetSize()
        duration = time.time() * 1000.0 - self._render_start
        actor = view.volume_cut_displayable_manager.GetVolumeActor(self.session.cut_node) if self.session.has_data else None
        sample_distance = actor.GetMapper().GetLastImageSampleDistance() if actor is not None else 1
        self.timing["frames"].append((name, self._render_start, duration, width, height, sample_distance))
        if TRACE:
            print(f"[render] {name} {width}x{height} {duration:.0f} ms, a ray per {sample_distance}x{sample_distance} "
                  "pixels", flush=True)


    def _tool_centre(self):
        transform = self.session.tool_node.GetParentTransformNode() if self.session.has_data else None
        if transform is None:
            return None
        pose = vtk.vtkMatrix4x4()
        transform.GetMatrixTransformToWorld(pose)
        return [pose.GetElement(row, 3) for row in range(3)]

    def reset_camera(self) -> None:
        if self.session.has_data:
            self.three_d_view.look_from(self.session.volume_bounds(), (1.0, 0.0, 0.0))
        for view in self.slicer_app.view_manager.get_slice_views():
            view.fit_view_to_content()
            view.schedule_render()

    # ------------------------------------------------------------------ state

    def _initialize_state(self) -> None:
        state = self.state
        state.trame__title = "VolumeCutting"
        state.update({
            "vc_source": self.options.source if self.options.source != "own" else "own",
            "vc_source_items": SOURCE_ITEMS,
            "vc_busy": False, "vc_progress": 0, "vc_status": "", "vc_error": "", "vc_warnings": [],
            "vc_description": "",
            "vc_ct_path": str(self.options.ct or ""), "vc_segmentation_path": str(self.options.segmentation or ""),
            "vc_uploaded": {"ct": "", "segmentation": ""}, "vc_upload_message": "",
            "vc_max_upload_bytes": self.options.max_upload_bytes,
            "vc_data_dirs": [str(d) for d in self.options.data_dirs],
            "vc_segments": [], "vc_role_items": ROLE_ITEMS, "vc_total_removed": 0.0,
            "vc_presets": self.session.preset_names(), "vc_preset": None,
            "vc_shapes": [s for s in toolconfig.SHAPES if s != "Mesh"], "vc_burr_types": list(toolconfig.BURR_TYPES),
            "vc_tool": {}, "vc_tool_error": "", "vc_tool_ranges": self._tool_ranges("Sphere"),
            "vc_mode": self.drill.mode, "vc_mode_hint": "", "vc_depth": self.drill.depth_mm,
            "vc_undo_count": 0, "vc_redo_count": 0,
            "vc_contact": "", "vc_contact_fix": None, "vc_contacts": [],
            "vc_export_error": "", "vc_export_names": {},
            "vc_owner": "", "vc_client_id": "", **self.instructor.initial_state(),
            "vc_sc_points": 0, "vc_sc_example": False, "vc_sc_normal": self.softcut.normal_mode,
            "vc_sc_depth": self.softcut.depth_mm, "vc_sc_previewing": False, "vc_sc_skin": False,
            "vc_sc_error": "", "vc_sc_status": "", "vc_sc_measurements": [],
            "vc_sc_export_name": "resection.stl",
            # The drill sound: parameters from the server (www/drillsound.js watches them outside the template,
            # which would otherwise render again at every update); the switch and volume are each page's own.
            "vc_sound": self.sound.initial_state(), "vc_sound_config": self.sound.config_state(),
            "vc_sound_on": False, "vc_sound_volume": 0.5, "vc_sound_message": "",
            # The nerve monitor's meter: small rows, sent when a distance moves > 0.05 mm or a level changes
            # (www/monitormeter.js draws them, outside the template).
            "vc_monitor": [],
        })
        state.client_only("vc_client_id", "vc_sound_on", "vc_sound_volume", "vc_sound_message",
                          *instructorlink.InstructorLink.CLIENT_ONLY)
        self._update_mode_hint()

    @staticmethod
    def _tool_ranges(shape: str) -> dict:
        ranges = dict(toolconfig.RANGES, diameter=toolconfig.diameter_range(shape))
        return {name: [low, high] for name, (low, high) in ranges.items()}

    # ------------------------------------------------------------------ OpenIGTLink

    def _follow_with_openigtlink(self) -> None:
        """The bridge streams this data's session and applies what clients send, every 10 ms on the server's loop."""
        if self.igtl is None:
            return
        self.igtl.attach(self.session.logic, self.session.cut_node)
        if self._igtl_task is None or self._igtl_task.done():
            self._igtl_task = create_task(self._apply_openigtlink())

    async def _apply_openigtlink(self) -> None:
        while self.igtl is not None:
            try:
                if self.session.has_data and not self.state.vc_busy:
                    self.igtl.process_incoming(self.session)
            except Exception as error:  # a bad command must not stop the session
                print(f"[openigtlink] {error}", flush=True)
            await asyncio.sleep(0.01)

    def _on_remote_tool(self, action: str) -> None:
        """A pose from OpenIGTLink moved the tool: the views and panels follow as they do for the mouse."""
        if action == "stroke_began":
            self._on_stroke_begin()
        elif action == "drilled":
            self._on_stroke_moved()
        elif action == "stroke_ended":
            self._on_stroke_end()
        else:
            self.drill.set_glyph(placed=True)
            self._on_hover()

    def _refresh_after_data(self) -> None:
        self._observe_cut_node()
        self._follow_with_openigtlink()
        self.slicer_app.display_manager.show_volume_in_slice_background(self.session.volume)
        self.state.vc_description = self.session.description
        self.state.vc_warnings = list(self.session.warnings)
        base = "".join(c if c.isalnum() or c in "-_" else "_" for c in self.session.volume.GetName()) or "volume"
        self.state.vc_export_names = {kind: f"{base}-{name}" for kind, (name, _) in EXPORT_FILES.items()}
        self.state.vc_contact, self.state.vc_contact_fix = "", None
        self.state.vc_sc_export_name = f"{base}-resection.stl"
        self._refresh_tool()
        self._refresh_tables()
        self.softcut.show_skin(bool(self.state.vc_sc_skin))
        self._refresh_softcut(error="")
        self.monitor_meter.refresh(force=True)
        self.sound.prepare()
        self._request_monitor_refresh()
        self.reset_camera()

    def _refresh_tables(self) -> None:
        rows = self.session.segment_rows()
        self.state.vc_segments = [
            {"id": r.segment_id, "name": r.name, "color": self._own_colour(r.segment_id, r.color), "role": r.role,
             "removed": round(r.removed_mm3, 2)}
            for r in rows
        ]
        self.state.vc_total_removed = round(sum(r.removed_mm3 for r in rows), 2)
        self.sound.note_removed(sum(r.removed_mm3 for r in rows))
        undo, redo = self.session.undo_redo_counts()
        self.state.vc_undo_count, self.state.vc_redo_count = undo, redo
        self.state.vc_contacts = self._contact_rows()
        self.report.refresh_counts()
        self._last_table_refresh = time.monotonic()

    def _own_colour(self, segment_id: str, colour: str) -> str:
        """A segment's colour in the table: its own, not the monitor's tint."""
        own = self.monitor_meter.tint.tinted.get(segment_id)
        return colour if own is None else monitormeter.rgb_to_hex(own)

    def _contact_rows(self) -> list[dict]:
        if not self.session.has_data:
            return []
        table = self.session.logic.GetContactTableNode(self.session.cut_node).GetTable()
        names = table.GetColumnByName("Name")
        depths = table.GetColumnByName("Depth")
        if names is None or depths is None:
            return []
        return [{"name": names.GetValue(row), "depth": round(float(depths.GetValue(row)), 2)}
                for row in range(table.GetNumberOfRows())]

    def _refresh_tool(self) -> None:
        if not self.session.has_data:
            return
        params = self.session.tool_parameters()
        self.state.vc_tool = {"shape": params.shape, "burr_type": params.burr_type, "diameter": params.diameter,
                              "length": params.length, "thickness": params.thickness, "width": params.width,
                              "power": params.power}
        self.state.vc_tool_ranges = self._tool_ranges(params.shape)

    def _observe_cut_node(self) -> None:
        if self._observed_cut_node is not None and self._contact_observer is not None:
            self._observed_cut_node.RemoveObserver(self._contact_observer)
        self._observed_cut_node = self.session.cut_node
        self._contact_observer = self.session.cut_node.AddObserver(slicer.vtkMRMLVolumeCutNode.ProtectedContactEvent,
                                                                   self._on_contact)

    def _on_contact(self, *_):
        contact = self.session.contact()
        if contact is None:
            return
        protected = self.session.cut_node.IsSegmentProtected(contact.segment_id)
        if protected:
            self.state.vc_contact = f"Contact with {contact.name} (protected): {contact.depth_mm:.2f} mm deep"
            self.state.vc_contact_fix = None
        else:
            # A role-less segment (every segment of a labelmap starts so) stops the burr like a protected
            # one; a newcomer needs the way forward, not only the reason.
            self.state.vc_contact = (f"Contact with {contact.name} (not cuttable by this tool): {contact.depth_mm:.2f} mm deep. "
                                     f"To drill it, make it cuttable here or set its role in the Segments panel.")
            self.state.vc_contact_fix = {"id": contact.segment_id, "name": contact.name}
        self.drill.set_glyph(in_contact=True)
        self.state.flush()

    # ------------------------------------------------------------------ drilling callbacks

    def _on_stroke_begin(self) -> None:
        self.progressive.stroke_started()
        # The slice views follow the tool when the stroke ends; meanwhile the 3D view has the processor.
        for view in self.slicer_app.view_manager.get_slice_views():
            view.set_render_blocked(True)
        self.state.vc_contact, self.state.vc_contact_fix = "", None
        self.drill.set_glyph(in_contact=False)
        self.sound.stroke_began(self.state.vc_total_removed)

    def _on_hover(self) -> None:
        self.progressive.pointer_moved()
        self._request_monitor_refresh()

    def _on_stroke_moved(self) -> None:
        self._request_monitor_refresh()
        # The removed volume follows live, a few times a second.
        if time.monotonic() - self._last_table_refresh > 0.25:
            self.session.update_removed_volumes()
            self._refresh_tables()

    def _on_stroke_end(self) -> None:
        self.sound.stroke_ended()
        self._request_monitor_refresh()
        self.progressive.stroke_ended()
        self._refresh_tables()
        self._jump_slices_to_tool()
        for view in self.slicer_app.view_manager.get_slice_views():
            view.set_render_blocked(False)

    def _jump_slices_to_tool(self) -> None:
        """The slice views go through the tool's centre, where the cut was just made."""
        transform = self.session.tool_node.GetParentTransformNode() if self.session.has_data else None
        if transform is None:
            return
        pose = vtk.vtkMatrix4x4()
        transform.GetMatrixTransformToWorld(pose)
        slicer.vtkMRMLSliceNode.JumpAllSlices(self.slicer_app.scene, pose.GetElement(0, 3), pose.GetElement(1, 3),
                                              pose.GetElement(2, 3), slicer.vtkMRMLSliceNode.OffsetJumpSlice)

    def _undo_redo(self, step) -> None:
        """Undo or redo a stroke; a contact warning belonged to the stroke that was drawn last."""
        if not self.session.has_data:
            return
        step()
        if self.progressive is not None:
            # A frame drawn before the step must not stand as the view at rest.
            self.progressive.content_changed()
        self.state.vc_contact, self.state.vc_contact_fix = "", None
        self.state.vc_sc_status = ""
        self.drill.set_glyph(in_contact=False)
        self._refresh_tables()

    def _on_depth_changed(self, depth: float) -> None:
        self.state.vc_depth = depth

    def _update_mode_hint(self) -> None:
        hints = {
            views.MODE_NAVIGATE: "Navigate: drag to rotate, right-drag to zoom, middle-drag to pan",
            views.MODE_DRILL: "Drill: press and drag on the bone; wheel sets the depth, Shift drills twice as deep",
            views.MODE_RESTORE: "Restore: press and drag to add bone back inside the cut",
            views.MODE_OUTLINE: "SoftCut outline: click on the skin to place the outline's points, in order around it",
        }
        self.state.vc_mode_hint = hints[self.drill.mode] + (
            f" ({self.state.vc_sc_points or 0} points)" if self.drill.mode == views.MODE_OUTLINE
            else f" (depth {self.drill.depth_mm:.2f} mm)")

    # ------------------------------------------------------------------ tabs and connections

    def client_closed(self, client_id: str) -> None:
        # A page in control that went away mid-stroke (closed, reloaded, network lost): the stroke ends, the cut stays.
        self.instructor.left(client_id)

    def _sender(self) -> str:
        """The connection whose message is being handled (wslink keeps it on its web server)."""
        web_server = getattr(self.server, "_server", None)
        sender = getattr(web_server, "last_active_client_id", None)
        return str(sender) if sender is not None else ""

    # ------------------------------------------------------------------ controller

    def _bind(self) -> None:
        ctrl, state = self.ctrl, self.state

        @ctrl.trigger("vc_hello")
        def hello():
            return self.instructor.hello()

        @ctrl.trigger("vc_take_over")
        def take_over():
            # A trainee tab takes control: from another tab, or back from the instructor.
            try:
                self.instructor.take_over(self._sender())
            except instructorlink.CoSessionRefused as refusal:
                self.instructor.notify(self._sender(), str(refusal))

        @ctrl.trigger("vc_diagnostics")
        def diagnostics():
            # For tests and benchmarks: what the server did and which mode it is in.
            return {"events": list(self.timing["events"]), "renders": list(self.timing["renders"]),
                    "frames": list(self.timing["frames"]), "ready_at": self.timing["ready_at"], "mode": self.drill.mode,
                    "monitor": self.monitor_meter.diagnostics(), "camera_frames_recorded": self.recording.camera_frame_count,
                    "tool": self._tool_centre(), "refused": dict(self.instructor.refused)}

        @ctrl.trigger("vc_place_tool")
        def place_tool(point):
            # The burr's centre to a point (RAS, mm) in the tool's orientation, as a tracker or a script places it;
            # for tests and demonstrations of the monitor. Refused during a stroke.
            if not self.session.has_data or self.session.in_stroke:
                return False
            try:
                moved = self.drill.place_tool_centre(point)
            except (TypeError, ValueError) as error:
                print(f"[place tool] {error}", flush=True)
                return False
            self.monitor_meter.refresh()
            self._jump_slices_to_tool()  # the slice views show the structures around the burr, tinted
            self.state.flush()
            return moved

        @ctrl.trigger("vc_load")
        async def load(source):
            await self.load_from_panel(source)

        @ctrl.trigger("vc_upload")
        def upload(kind, files):
            self.receive_upload(kind, files)

        @ctrl.trigger("vc_set_role")
        def set_role(segment_id, role):
            try:
                self.session.set_role(segment_id, role)
            except SessionError as error:
                state.vc_error = str(error)
            self._refresh_tables()

        @ctrl.trigger("vc_preset")
        def apply_preset(name):
            try:
                self.session.apply_preset(name)
                state.vc_tool_error = ""
            except (SessionError, toolconfig.ToolConfigError) as error:
                state.vc_tool_error = str(error)
            self._refresh_tool()

        @ctrl.trigger("vc_set_tool")
        def set_tool(name, value):
            try:
                value = value if name in ("shape", "burr_type") else float(value)
                self.session.set_tool(**{name: value})
                state.vc_tool_error = ""
            except (SessionError, toolconfig.ToolConfigError, ValueError, TypeError) as error:
                state.vc_tool_error = f"{name}: {error}" if not str(error).startswith(name) else str(error)
            self._refresh_tool()

        @ctrl.trigger("vc_undo")
        def undo():
            self._undo_redo(self.session.undo)

        @ctrl.trigger("vc_redo")
        def redo():
            self._undo_redo(self.session.redo)

        @ctrl.trigger("vc_export")
        def export(kind):
            self.monitor_meter.restore_colours()  # the files keep the segments' own colours, not the tint
            try:
                path = self.session.export(kind)
            except SessionError as error:
                state.vc_export_error = str(error)
                return None
            state.vc_export_error = ""
            return self.server.protocol.addAttachment(path.read_bytes())

        @ctrl.trigger("vc_sc_example")
        def softcut_example():
            self._softcut_action(self.softcut.use_example_outline, skin=True)
            if self.state.vc_sc_points:
                # The cheek from the patient's right front, as the main job shows it.
                self.three_d_view.look_at(softcutjob.CHEEK_CENTER, softcutjob.VIEW_DIRECTION, 260.0)

        @ctrl.trigger("vc_sc_undo_point")
        def softcut_undo_point():
            self._softcut_action(self.softcut.remove_last_point)

        @ctrl.trigger("vc_sc_clear")
        def softcut_clear():
            self._softcut_action(self.softcut.clear_outline)

        @ctrl.trigger("vc_sc_preview")
        def softcut_preview():
            self._softcut_action(lambda: self.softcut.preview(state.vc_sc_depth), skin=True)

        @ctrl.trigger("vc_sc_hide_preview")
        def softcut_hide_preview():
            self._softcut_action(self.softcut.clear_preview)

        @ctrl.trigger("vc_sc_carve")
        def softcut_carve():
            self._softcut_action(lambda: self.softcut.carve(state.vc_sc_depth), skin=True, carve=True)

        @ctrl.trigger("vc_sc_export")
        def softcut_export():
            try:
                self.softcut.set_depth(state.vc_sc_depth)
                path = self.softcut.export_stl()
            except SessionError as error:
                state.vc_sc_error = str(error)
                return None
            state.vc_sc_error = ""
            return self.server.protocol.addAttachment(path.read_bytes())

        @state.change("vc_sc_normal")
        def softcut_normal_changed(vc_sc_normal, **_):
            if vc_sc_normal != self.softcut.normal_mode:
                self._softcut_action(lambda: self.softcut.set_normal_mode(vc_sc_normal))

        @state.change("vc_sc_depth")
        def softcut_depth_changed(vc_sc_depth, **_):
            # The slider previews as it moves: the plan is reused, only the preview field is carved again.
            if self.softcut.previewing:
                self._softcut_action(lambda: self.softcut.preview(vc_sc_depth))

        @state.change("vc_sc_skin")
        def softcut_skin_changed(vc_sc_skin, **_):
            self.softcut.show_skin(bool(vc_sc_skin))
            if self.progressive is not None:
                self.progressive.pointer_moved()

        @ctrl.trigger("vc_set_mode")
        def set_mode(mode):
            # The mode buttons call this at the click. A state change would wait in the page while any
            # call to the server is unanswered (trame's client pushes state only when not busy), and a
            # press right after the click, sent at once by the view, would reach the server first and be
            # taken in the old mode: after a camera rotation the server refines the view for a second or
            # two, and the first drag after "Drill" did nothing.
            mode_changed(mode)

        @state.change("vc_mode")
        def mode_changed(vc_mode, **_):
            try:
                self.drill.set_mode(vc_mode)
            except ValueError:
                pass
            if state.vc_mode != self.drill.mode:
                state.vc_mode = self.drill.mode
            # The outline lies on the skin; drilling shows the bone.
            if self.drill.mode == views.MODE_OUTLINE:
                self.drill.set_glyph(placed=False)
                state.vc_sc_skin = True
            elif self.drill.mode in (views.MODE_DRILL, views.MODE_RESTORE):
                state.vc_sc_skin = False
            self._update_mode_hint()

        @state.change("vc_depth")
        def depth_changed(vc_depth, **_):
            try:
                depth = self.drill.set_depth(vc_depth)
            except (ValueError, TypeError):
                depth = self.drill.depth_mm
            if depth != vc_depth:
                state.vc_depth = depth
            self._update_mode_hint()

    # ------------------------------------------------------------------ SoftCut

    def _on_outline_pick(self, point) -> None:
        self._softcut_action(lambda: self.softcut.add_point(point))
        self.state.flush()

    def _softcut_action(self, action, skin: bool = False, carve: bool = False) -> None:
        """Run a SoftCut step; its error (the logic's message) shows in the panel, and nothing changes."""
        state = self.state
        if not self.session.has_data:
            state.vc_sc_error = "Load a CT first (Data panel)"
            return
        if skin:
            state.vc_sc_skin = True
            self.softcut.show_skin(True)
        try:
            action()
            error = ""
        except SessionError as failure:
            error = str(failure)
        if carve and not error:
            self._refresh_tables()
        self._refresh_softcut(error=error, carved=carve and not error)
        self.progressive.pointer_moved()

    def _refresh_softcut(self, error: str | None = None, carved: bool = False) -> None:
        state, softcut = self.state, self.softcut
        state.vc_sc_points = len(softcut.outline_points())
        state.vc_sc_example = softcut.has_example_outline()
        state.vc_sc_normal = softcut.normal_mode
        state.vc_sc_previewing = softcut.previewing
        units = {"mm3": "mm³", "mm2": "mm²"}
        state.vc_sc_measurements = [{"name": name, "value": round(softcut.measurements[name][0], 1),
                                     "unit": units.get(softcut.measurements[name][1], softcut.measurements[name][1])}
                                    for name in SOFTCUT_MEASUREMENTS if name in softcut.measurements]
        if carved:
            state.vc_sc_status = f"Carved {softcut.depth_mm:g} mm deep (undo takes it back)"
        elif softcut.previewing:
            state.vc_sc_status = f"Preview at {softcut.depth_mm:g} mm"
        else:
            state.vc_sc_status = ""
        if error is not None:
            state.vc_sc_error = error
        self._update_outline_model()
        self._update_mode_hint()

    def _update_outline_model(self) -> None:
        """The outline's points and the line through them, drawn over the skin."""
        if self._outline_model is None or self._outline_model.GetScene() is None:
            self._outline_model = self.slicer_app.scene.AddNewNodeByClass("vtkMRMLModelNode", "SoftCut outline (drawn)")
            self._outline_model.CreateDefaultDisplayNodes()
            display = self._outline_model.GetDisplayNode()
            display.SetColor(0.1, 0.75, 1.0)
            display.SetVisibility2D(False)
        self._outline_model.SetAndObservePolyData(self.softcut.outline_polydata())

    # ------------------------------------------------------------------ data

    async def load_from_panel(self, source: str) -> None:
        """The Data panel's Load button: own data comes from an upload or an allowed server path."""
        try:
            options = self._own_data_paths() if source == "own" else {}
        except (SessionError, owndata.InputError) as error:
            self.state.vc_error = str(error)
            return
        await self.load(source, **options)

    async def load(self, source: str, **options) -> None:
        """Load data with progress in the page; what cannot be loaded leaves the scene as it was."""
        state = self.state
        if state.vc_busy:
            return
        with state:
            state.vc_busy, state.vc_error, state.vc_progress, state.vc_status = True, "", 0, "Starting"
        self._ready_when_shown = None
        self.drill.end_stroke()
        try:
            for fraction, text in self.session.loading(source, **options):
                with state:
                    state.vc_progress, state.vc_status = round(100 * fraction), text
                # Let the page show the progress before the next step holds the server.
                await asyncio.sleep(0.05)
            self._refresh_after_data()
            with state:
                state.vc_progress, state.vc_status = 98, "Drawing the first picture"
            # A quick, coarse first picture now (the full one follows): the page never says Ready over a black view.
            # A page whose 3D view has no size yet (still opening) is told once its first frame is sent.
            if await self.progressive.first_frame():
                self.timing["ready_at"] = time.time() * 1000.0
                state.vc_status = "Ready: " + self.session.description
            else:
                self._ready_when_shown = "Ready: " + self.session.description
            state.vc_upload_message = ""  # a refused upload's message no longer applies to the data shown
        except (SessionError, owndata.InputError, headct.HeadCTUnavailableError, OSError) as error:
            state.vc_error = self._with_upload_names(str(error))
            state.vc_status = "Not loaded; the previous data stays" if self.session.has_data else "Not loaded"
        finally:
            with state:
                state.vc_busy = False

    def _with_upload_names(self, text: str) -> str:
        """Messages name uploaded files as the user named them, not by where the server keeps them."""
        for path, name in sorted(self._upload_names.items(), key=lambda item: -len(item[0])):
            text = text.replace(path, f"{name} (uploaded)")
        return text

    def _own_data_paths(self) -> dict:
        """The CT and segmentation to load: the uploaded ones, else the server paths (checked against the allowed folders)."""
        uploaded = self.state.vc_uploaded or {}
        paths = {}
        for key, upload_key, state_key in (("ct_path", "ct", "vc_ct_path"), ("segmentation_path", "segmentation", "vc_segmentation_path")):
            if uploaded.get(upload_key):
                paths[key] = Path(uploaded[upload_key])
                continue
            text = (self.state[state_key] or "").strip()
            if not text:
                continue
            path = Path(text).expanduser()
            if not path.is_absolute():
                raise SessionError(f"{text}: give the full path of the file or folder on the server")
            if not path_allowed(path, self.options.data_dirs):
                folders = ", ".join(str(d) for d in self.options.data_dirs)
                raise SessionError(f"{path}: this server only reads files inside {folders}. Copy the scan there, "
                                   "upload it instead, or ask the administrator to start the app with --data-dir")
            paths[key] = path
        if "ct_path" not in paths:
            raise SessionError("Give the CT: upload it, or type its path on the server")
        return paths

    def receive_upload(self, kind: str, files) -> None:
        """Store uploaded files (a file, a DICOM series as several files, or a .zip of either) for the next load."""
        state = self.state
        if kind not in ("ct", "segmentation"):
            state.vc_upload_message = f"Unknown upload {kind!r}"
            return
        files = files if isinstance(files, list) else [files]
        total = sum(len(f.get("content") or b"") for f in files)
        if total > self.options.max_upload_bytes:
            state.vc_upload_message = (f"{total / 2**20:.1f} MB is more than this server accepts "
                                       f"({self.options.max_upload_mb:.1f} MB)")
            return
        folder = self.session.work_directory / "uploads" / f"{kind}-{time.time_ns()}"
        folder.mkdir(parents=True)
        written = []
        for item in files:
            name = Path(str(item.get("name") or "upload")).name
            if not name or name in (".", ".."):
                name = "upload"
            path = folder / name
            path.write_bytes(item.get("content") or b"")
            written.append(path)
        try:
            target = unpack_upload(written, folder, self.options.max_upload_bytes)
        except (zipfile.BadZipFile, SessionError) as error:
            state.vc_upload_message = str(error)
            return
        names = [Path(str(item.get("name") or "upload")).name for item in files]
        self._upload_names[str(target)] = names[0] if len(names) == 1 else f"{len(names)} files ({names[0]}, ...)"
        uploaded = dict(state.vc_uploaded or {})
        uploaded[kind] = str(target)
        state.vc_uploaded = uploaded
        state.vc_upload_message = ""

    # ------------------------------------------------------------------ page

    def _build_ui(self) -> None:
        self._bind()
        with SinglePageWithDrawerLayout(self.server, full_height=True) as layout:
            self.ui = layout
            layout.title.set_text("VolumeCutting")
            client.ClientTriggers(mounted=instructorlink.InstructorLink.HELLO)
            with layout.toolbar:
                v3.VSpacer()
                self.instructor.toolbar_button()
                # The instructor's page drills (and so shows the modes) only while it holds control.
                with v3.VBtnToggle(v_if="vc_role !== 'instructor' || vc_owner === vc_client_id", v_model=("vc_mode",),
                                   mandatory=True, density="compact", classes="mr-2", raw_attrs=['data-testid="mode"']):
                    v3.VBtn("Navigate", value=views.MODE_NAVIGATE, click=f"trigger('vc_set_mode', ['{views.MODE_NAVIGATE}'])", prepend_icon="mdi-rotate-3d-variant", raw_attrs=['data-testid="mode-navigate"'])
                    v3.VBtn("Drill", value=views.MODE_DRILL, click=f"trigger('vc_set_mode', ['{views.MODE_DRILL}'])", prepend_icon="mdi-screw-machine-flat-top", raw_attrs=['data-testid="mode-drill"'])
                    v3.VBtn("Restore", value=views.MODE_RESTORE, click=f"trigger('vc_set_mode', ['{views.MODE_RESTORE}'])", prepend_icon="mdi-bandage", raw_attrs=['data-testid="mode-restore"'])
                    v3.VBtn("SoftCut outline", value=views.MODE_OUTLINE, click=f"trigger('vc_set_mode', ['{views.MODE_OUTLINE}'])", prepend_icon="mdi-vector-polygon",
                            raw_attrs=['data-testid="mode-outline"'])
                v3.VBtn(icon="mdi-undo", click="trigger('vc_undo')", disabled=("vc_undo_count === 0",), raw_attrs=['data-testid="undo"'])
                v3.VBtn(icon="mdi-redo", click="trigger('vc_redo')", disabled=("vc_redo_count === 0",), raw_attrs=['data-testid="redo"'])
            with layout.drawer as drawer:
                drawer.width = 380
                self._panels()
            with layout.content:
                with html.Div(style="position: relative; width: 100%; height: 100%;"):
                    with html.Div(style="position: absolute; inset: 0;"):
                        self.layout_manager.initialize_layout_grid(layout)
                    self._tab_overlay()
                    self.instructor.dialogs()

    def _tab_overlay(self) -> None:
        # Trainee tabs only: the instructor's page watches by design, and a trainee whose instructor holds
        # control takes it back from the toolbar.
        with v3.VOverlay(model_value=("vc_role === 'trainee' && vc_owner_role === 'trainee' && vc_owner && vc_client_id "
                                      "&& vc_owner !== vc_client_id",), persistent=True,
                         contained=False, classes="align-center justify-center", raw_attrs=['data-testid="tab-overlay"']):
            with v3.VCard(max_width=520, classes="pa-4"):
                v3.VCardTitle("This session is open in another tab")
                v3.VCardText("One drilling session follows one tab at a time, so that strokes from two places do not "
                             "mix. Everything done so far is kept on the server; the views here follow it.")
                with v3.VCardActions():
                    v3.VSpacer()
                    v3.VBtn("Drill from this tab", color="primary", click="trigger('vc_take_over')", raw_attrs=['data-testid="take-over"'])

    def _panels(self) -> None:
        with v3.VExpansionPanels(multiple=True, model_value=("vc_panels", ["instructor", "data", "segments", "tool", "drill", "softcut", "export"]),
                                 variant="accordion"):
            self.instructor.instructor_panel()
            # The instructor's page shows what they watch (segments, drill and monitor); the rest is the trainee's.
            with Template(v_if="vc_role !== 'instructor'"):
                self.instructor.trainee_panel()
                self._data_panel()
            self._segments_panel()
            with Template(v_if="vc_role !== 'instructor'"):
                self._tool_panel()
            self._drill_panel()
            with Template(v_if="vc_role !== 'instructor'"):
                self._softcut_panel()
                self._export_panel()
                self.progress.build()
                self.report.build()

    def _data_panel(self) -> None:
        with v3.VExpansionPanel(value="data", title="Data"), v3.VExpansionPanelText():
            v3.VSelect(v_model=("vc_source",), items=("vc_source_items",), label="Scan", density="compact",
                       hide_details=True, raw_attrs=['data-testid="source"'])
            with html.Div(v_if="vc_source === 'own'", classes="mt-2"):
                v3.VFileInput(label="CT: upload (DICOM files, .zip, .nrrd, .nii, .nii.gz, .mha)", multiple=True,
                              density="compact", hide_details=True, raw_attrs=['data-testid="upload-ct"'],
                              update_modelValue="vc_upload_message = utils.vc.upload('ct', $event, vc_max_upload_bytes)")
                v3.VTextField(v_model=("vc_ct_path",), label="... or its path on the server", density="compact",
                              hide_details=True, classes="mt-1", raw_attrs=['data-testid="ct-path"'])
                v3.VFileInput(label="Segmentation (optional): .seg.nrrd or labelmap", density="compact",
                              hide_details=True, classes="mt-2", raw_attrs=['data-testid="upload-segmentation"'],
                              update_modelValue="vc_upload_message = utils.vc.upload('segmentation', $event, vc_max_upload_bytes)")
                v3.VTextField(v_model=("vc_segmentation_path",), label="... or its path on the server",
                              density="compact", hide_details=True, classes="mt-1", raw_attrs=['data-testid="segmentation-path"'])
                html.Div("Server folders: {{ vc_data_dirs.join(', ') }}", classes="text-caption mt-1")
                v3.VAlert(v_if="vc_upload_message", text=("vc_upload_message",), type="error", density="compact",
                          classes="mt-2", raw_attrs=['data-testid="upload-message"'])
                html.Div(v_if="vc_uploaded.ct", classes="text-caption",
                         children=["Uploaded CT ready: {{ vc_uploaded.ct.split('/').pop() }}"])
            v3.VBtn("Load", block=True, color="primary", classes="mt-2", click="trigger('vc_load', [vc_source])",
                    disabled=("vc_busy",), raw_attrs=['data-testid="load"'])
            v3.VProgressLinear(v_show="vc_busy", model_value=("vc_progress",), height=6, classes="mt-2", color="primary",
                               raw_attrs=['data-testid="progress"'])
            html.Div("{{ vc_status }}", classes="text-caption mt-1", raw_attrs=['data-testid="status"'])
            v3.VAlert(v_if="vc_error", text=("vc_error",), type="error", density="compact", classes="mt-2",
                      raw_attrs=['data-testid="data-error"'])
            with html.Div(v_for="w in vc_warnings", classes="text-caption text-warning"):
                html.Span("{{ w }}")

    def _segments_panel(self) -> None:
        with v3.VExpansionPanel(value="segments", title="Segments"), v3.VExpansionPanelText():
            with v3.VTable(density="compact", raw_attrs=['data-testid="segments"'], style="font-size: 13px"):
                with html.Thead(), html.Tr():
                    html.Th("Segment", style="padding: 0 4px")
                    html.Th("Role", style="padding: 0 4px")
                    html.Th("Removed mm³", classes="text-right", style="padding: 0 4px")
                with html.Tbody():
                    with html.Tr(v_for="s in vc_segments", key="s.id", raw_attrs=[':data-segment="s.id"']):
                        with html.Td(style="padding: 0 4px; word-break: break-word"):
                            html.Span(style=("{ display: 'inline-block', width: '10px', height: '10px', marginRight: '6px', "
                                             "borderRadius: '2px', background: s.color }",))
                            html.Span("{{ s.name }}")
                        with html.Td(style="padding: 0 4px; width: 112px"):
                            v3.VSelect(model_value=("s.role",), items=("vc_role_items",), density="compact",
                                       variant="plain", hide_details=True, raw_attrs=[':data-role-of="s.id"'],
                                       disabled=("vc_role === 'instructor' && vc_owner !== vc_client_id",),
                                       style="font-size: 13px",
                                       update_modelValue="trigger('vc_set_role', [s.id, $event])")
                        html.Td("{{ s.removed.toFixed(2) }}", classes="text-right", style="padding: 0 4px",
                                raw_attrs=[':data-removed-of="s.id"'])
            html.Div("Removed in all: {{ vc_total_removed.toFixed(2) }} mm³", classes="text-body-2 mt-1",
                     raw_attrs=['data-testid="total-removed"'])

    def _tool_panel(self) -> None:
        with v3.VExpansionPanel(value="tool", title="Tool"), v3.VExpansionPanelText():
            v3.VSelect(model_value=("vc_preset",), items=("vc_presets",), label="Preset", density="compact",
                       hide_details=True, raw_attrs=['data-testid="preset"'],
                       update_modelValue="vc_preset = $event; trigger('vc_preset', [$event])")
            v3.VSelect(model_value=("vc_tool.shape",), items=("vc_shapes",), label="Shape", density="compact",
                       hide_details=True, classes="mt-2", raw_attrs=['data-testid="shape"'],
                       update_modelValue="trigger('vc_set_tool', ['shape', $event])")
            v3.VSelect(v_if="['Sphere', 'Cylinder'].includes(vc_tool.shape)", model_value=("vc_tool.burr_type",),
                       items=("vc_burr_types",), label="Burr", density="compact", hide_details=True, classes="mt-2",
                       update_modelValue="trigger('vc_set_tool', ['burr_type', $event])")
            for name, label, shapes in (("diameter", "Diameter (mm)", "['Sphere', 'Cylinder', 'DiskSaw']"),
                                        ("length", "Length (mm)", "['Cylinder', 'Blade']"),
                                        ("width", "Width (mm)", "['Blade']"),
                                        ("thickness", "Thickness (mm)", "['DiskSaw', 'Blade']")):
                v3.VTextField(v_if=f"{shapes}.includes(vc_tool.shape)", model_value=(f"vc_tool.{name}",), label=label,
                              type="number", step=0.5, density="compact", hide_details=True, classes="mt-2",
                              hint=(f"`${{vc_tool_ranges.{name}[0]}} to ${{vc_tool_ranges.{name}[1]}} mm`",),
                              raw_attrs=[f'data-testid="tool-{name}"'],
                              change=f"trigger('vc_set_tool', ['{name}', $event.target.value])")
            v3.VSlider(model_value=("vc_tool.power",), min=0, max=1, step=0.05, label="Power", density="compact",
                       hide_details=True, classes="mt-2", thumb_label=True,
                       end="trigger('vc_set_tool', ['power', $event])")
            html.Div("Power drives rate-based removal (haptic drilling); mouse strokes remove what the tool sweeps.",
                     classes="text-caption")
            v3.VAlert(v_if="vc_tool_error", text=("vc_tool_error",), type="error", density="compact", classes="mt-2",
                      raw_attrs=['data-testid="tool-error"'])

    def _drill_panel(self) -> None:
        with v3.VExpansionPanel(value="drill", title="Drill"), v3.VExpansionPanelText():
            v3.VSlider(v_model=("vc_depth",), min=views.DEPTH_RANGE_MM[0], max=views.DEPTH_RANGE_MM[1],
                       step=views.DEPTH_STEP_MM, label="Depth (mm)", thumb_label="always", density="compact",
                       hide_details=True, raw_attrs=['data-testid="depth"'])
            html.Div("Press and drag on the bone in Drill mode. The wheel changes the depth; "
                     "hold Shift to drill twice as deep. Restore mode adds bone back.", classes="text-caption")
            html.Div("Undo steps: {{ vc_undo_count }}, redo steps: {{ vc_redo_count }}", classes="text-caption mt-1")
            self._sound_controls()
            # Drawn by www/monitormeter.js from vc_monitor, outside the template (see there).
            HtmlElement("vc-monitor-meter", raw_attrs=['data-testid="monitor-meter"'])
            with html.Div(v_if="vc_contacts.length", classes="mt-2", raw_attrs=['data-testid="contacts"']):
                # The logic's contact table is a record of the session: undo takes the cut back, not the contact.
                html.Div("Touched so far (structures the tool may not cut; undo keeps this record):",
                         classes="text-body-2 text-error")
                with html.Div(v_for="(c, i) in vc_contacts", key="i", classes="text-caption"):
                    html.Span("{{ c.name }}: {{ c.depth.toFixed(2) }} mm")

    def _sound_controls(self) -> None:
        """The drill sound's switch and volume: the page plays it (Web Audio), each page at its own volume."""
        with html.Div(classes="d-flex align-center mt-1"):
            v3.VSwitch(v_model=("vc_sound_on",), label="Drill sound", density="compact", hide_details=True,
                       color="primary", raw_attrs=['data-testid="sound-switch"'],
                       update_modelValue=("$event ? utils.vc.sound.start(vc_sound_volume).then((ok) => "
                                          "{ vc_sound_message = utils.vc.sound.message; if (!ok) vc_sound_on = false; }) "
                                          ": utils.vc.sound.stop()"))
            v3.VSlider(v_model=("vc_sound_volume",), min=0, max=1, step=0.05, density="compact", hide_details=True,
                       prepend_icon="mdi-volume-high", classes="ml-3", disabled=("!vc_sound_on",),
                       raw_attrs=['data-testid="sound-volume"'], update_modelValue="utils.vc.sound.setVolume($event)")
        html.Div("{{ vc_sound_message }}", v_if="vc_sound_message", classes="text-caption text-warning",
                 raw_attrs=['data-testid="sound-message"'])

    def _softcut_panel(self) -> None:
        with v3.VExpansionPanel(value="softcut", title="SoftCut (soft-tissue resection)",
                                raw_attrs=['data-testid="softcut-panel"']), v3.VExpansionPanelText():
            html.Div("Outline the resection on the skin (SoftCut outline mode: click its points in order around it), "
                     "set the depth, preview, carve.", classes="text-caption")
            with html.Div(classes="d-flex flex-wrap ga-1 mt-1"):
                v3.VBtn("Example cheek outline", v_if="vc_sc_example", size="small", variant="tonal",
                        click="trigger('vc_sc_example')", raw_attrs=['data-testid="softcut-example"'])
                v3.VBtn("Last point", prepend_icon="mdi-undo-variant", size="small", variant="text",
                        disabled=("vc_sc_points === 0",), click="trigger('vc_sc_undo_point')",
                        raw_attrs=['data-testid="softcut-undo-point"'])
                v3.VBtn("Clear", size="small", variant="text", disabled=("vc_sc_points === 0",),
                        click="trigger('vc_sc_clear')", raw_attrs=['data-testid="softcut-clear"'])
            html.Div("Outline: {{ vc_sc_points }} points", classes="text-body-2 mt-1",
                     raw_attrs=['data-testid="softcut-points"'])
            with v3.VBtnToggle(v_model=("vc_sc_normal",), mandatory=True, density="compact", classes="mt-1",
                               raw_attrs=['data-testid="softcut-normal"']):
                for mode in NORMAL_MODES:
                    v3.VBtn(f"{mode} normal", value=mode, size="small", raw_attrs=[f'data-testid="softcut-normal-{mode}"'])
            v3.VSlider(v_model=("vc_sc_depth",), min=SOFTCUT_DEPTH_RANGE_MM[0], max=SOFTCUT_DEPTH_RANGE_MM[1],
                       step=SOFTCUT_DEPTH_STEP_MM, label="Depth (mm)", thumb_label="always", density="compact",
                       hide_details=True, classes="mt-6", raw_attrs=['data-testid="softcut-depth"'])
            v3.VSwitch(v_model=("vc_sc_skin",), label="Show the skin", density="compact", hide_details=True,
                       color="primary", raw_attrs=['data-testid="softcut-skin"'])
            with html.Div(classes="d-flex ga-1"):
                v3.VBtn("Preview", v_if="!vc_sc_previewing", size="small", variant="tonal", prepend_icon="mdi-eye",
                        click="trigger('vc_sc_preview')", raw_attrs=['data-testid="softcut-preview"'])
                v3.VBtn("Hide preview", v_else=True, size="small", variant="tonal", prepend_icon="mdi-eye-off",
                        click="trigger('vc_sc_hide_preview')", raw_attrs=['data-testid="softcut-hide-preview"'])
                v3.VBtn("Carve", size="small", color="primary", prepend_icon="mdi-content-cut",
                        click="trigger('vc_sc_carve')", raw_attrs=['data-testid="softcut-carve"'])
                v3.VBtn("STL", size="small", variant="tonal", prepend_icon="mdi-download",
                        click="trigger('vc_sc_export').then((content) => content && "
                              "utils.download(vc_sc_export_name, content, 'model/stl'))",
                        raw_attrs=['data-testid="softcut-export"'])
            html.Div("{{ vc_sc_status }}", classes="text-caption mt-1", raw_attrs=['data-testid="softcut-status"'])
            with v3.VTable(v_if="vc_sc_measurements.length", density="compact", style="font-size: 13px",
                           raw_attrs=['data-testid="softcut-measurements"']):
                with html.Tbody():
                    with html.Tr(v_for="m in vc_sc_measurements", key="m.name", raw_attrs=[':data-measurement="m.name"']):
                        html.Td("{{ m.name }}", style="padding: 0 4px")
                        html.Td("{{ m.value.toFixed(1) }} {{ m.unit }}", classes="text-right", style="padding: 0 4px")
            v3.VAlert(v_if="vc_sc_error", text=("vc_sc_error",), type="error", density="compact", classes="mt-2",
                      raw_attrs=['data-testid="softcut-error"'])

    def _export_panel(self) -> None:
        with v3.VExpansionPanel(value="export", title="Export"), v3.VExpansionPanelText():
            for kind, label, icon in (("stl", "Removed region (STL)", "mdi-cube-outline"),
                                      ("segmentation", "Removed segment (.seg.nrrd)", "mdi-shape-outline"),
                                      ("drilled_ct", "Drilled CT (.nrrd)", "mdi-file-image-outline"),
                                      ("scene", "Scene (.mrb)", "mdi-package-variant-closed")):
                mime = EXPORT_FILES[kind][1]
                v3.VBtn(label, block=True, variant="tonal", classes="mb-1", prepend_icon=icon, raw_attrs=[f'data-testid="export-{kind}"'],
                        click=f"trigger('vc_export', ['{kind}']).then((content) => content && "
                              f"utils.download(vc_export_names['{kind}'], content, '{mime}'))")
            v3.VAlert(v_if="vc_export_error", text=("vc_export_error",), type="error", density="compact", classes="mt-2",
                      raw_attrs=['data-testid="export-error"'])


def main(argv=None) -> int:
    from trame.app import get_server

    server = get_server(client_type="vue3")
    add_arguments(server.cli)
    args, _ = server.cli.parse_known_args(argv)
    options = options_from_arguments(args)
    app = VolumeCuttingApp(server, options)
    paths = {"ct_path": options.ct, "segmentation_path": options.segmentation, "cuttable_names": options.cuttable,
             "protected_names": options.protected} if options.source == "own" else {}

    def load_at_start(**_):
        # The data loads while the page opens: the page shows the progress.
        create_task(app.load(options.source, **paths))

    server.controller.on_server_ready.add(load_at_start)
    server.start(open_browser=False)
    return 0
