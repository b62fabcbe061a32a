"""Progressive rendering of the 3D view: a reduced-resolution preview while the user drags, full resolution at rest.

The product's ray caster runs on the CPU here (llvmpipe): a whole 1024x768
frame of the head CT takes seconds on 2 cores, but it keeps its last image
and, while the camera stays, recasts only the pixels covering the bricks a
stroke changed. Switching one window between two sizes would throw that image
away each time, so the 3D view has two windows on the same scene:

* the main window, at the page's size: what the page shows at rest;
* a preview window (its own view node, its camera a copy of the main one) at
  ``drill_scale`` of that size while drilling and ``navigate_scale`` while
  the camera moves.

Each keeps its own ray-cast image, so each stroke frame of the preview and
the refinement of the main window when the mouse stops both recast only what
changed since that window last drew. trame-rca streams whichever window
drew last (``ProgressiveArea``); JPEG quality drops while interacting and
rises for still frames (trame-rca's interactive and still qualities).
``ProgressiveRendering`` decides which window draws.

While the camera moves, every pixel changes, so no cached image helps: the
preview then asks for interactive frames (its window's DesiredUpdateRate at
``navigate_fps``, as VTK's interactor styles do), and the product's mapper
casts one ray per few pixels, as many as fit in the frame's time, without
ambient occlusion (``vtkVolumeCutVolumeMapper``'s progressive refinement).
Every still frame (the drill preview at rest, the main window's refinement)
casts every pixel at full quality. ``ProgressiveScheduler`` sends each frame
to the page before it draws the next, so a frame never waits behind a newer
one.
"""

from __future__ import annotations

import asyncio
from time import monotonic

import numpy as np

import slicer
import vtk
from trame_rca.schedulers import RcaImageRenderScheduler
from trame_rca.utils import RcaViewAdapter
from trame_server.utils.asynchronous import create_task
from trame_slicer.app.logic import get_view_trame_id
from trame_slicer.rca_view.rca_view_factory import RcaRenderStrategy, RcaView, RcaWindow, RemoteViewFactory
from trame_slicer.views import CursorId, ViewLayout, ViewType
from vtkmodules.util.numpy_support import vtk_to_numpy

from .views import VolumeCutThreeDView

PREVIEW_SUFFIX = "Preview"
# The render window's DesiredUpdateRate of still frames (VTK's interactor default).
STILL_UPDATE_RATE = 0.0001
# The coarsest interactive frame still casts this many rays across the view's width: on a loaded machine the
# mapper would otherwise go to one ray per 16 x 16 pixels (32 x 24 rays at 512 x 384), a blur in which the
# skull's outline is lost, to save milliseconds that the rest of the frame (drawing, reading back, encoding) spends anyway.
MINIMUM_RAYS_ACROSS = 64
# Between two frames the server takes the events that arrived meanwhile, so
# that the next frame shows where the mouse is now, not where it was.
EVENT_GAP_S = 0.004


def camera_signature(camera) -> tuple:
    """Where the camera looks from and how: two equal signatures see the same scene (clipping aside,
    which renderers adjust to what they draw)."""
    return (camera.GetPosition(), camera.GetFocalPoint(), camera.GetViewUp(), camera.GetViewAngle(),
            camera.GetParallelProjection(), camera.GetParallelScale())


class ProgressiveArea(RcaWindow):
    """trame-rca's remote area over two windows of one 3D view: events and size go to the main window,
    images come from the main window or, while the user interacts, from the preview window."""

    def __init__(self, main_view, preview_view, state, active_view_cursor):
        super().__init__(main_view.render_window(), state, active_view_cursor)
        self.main_view = main_view
        self.preview_view = preview_view
        self.use_preview = False
        self.preview_scale = 1.0
        self.size = (300, 300)
        self.sized = False
        self.on_resize = lambda: None
        preview_window = preview_view.render_window()
        preview_window.ShowWindowOff()
        preview_window.SetOffScreenRendering(1)
        self._preview_image = vtk.vtkImageData()

    @property
    def img_cols_rows(self):
        if not self.sized:
            # The page has not said how large the view is: nothing worth drawing yet.
            return np.zeros((10, 10, 3), dtype=np.uint8), 10, 10
        view = self.preview_view if self.use_preview else self.main_view
        window = view.render_window()
        window.Render()
        image = self._preview_image if self.use_preview else self.image_data
        slicer.vtkMRMLLayerDisplayableManager.RenderWindowBufferToImage(window, image)
        columns, rows, _ = image.GetDimensions()
        pixels = vtk_to_numpy(image.GetPointData().GetScalars()).reshape((rows, columns, -1))
        return pixels[::-1, :, :].copy(), columns, rows

    def process_resize_event(self, width, height):
        super().process_resize_event(width, height)
        self.size = (int(width), int(height))
        self.sized = True
        self.set_preview_scale(self.preview_scale, force=True)
        self.on_resize()

    def set_preview_scale(self, scale: float, force: bool = False) -> None:
        if scale == self.preview_scale and not force:
            return
        self.preview_scale = scale
        width, height = (max(10, round(side * scale)) for side in self.size)
        interactor = self.preview_view.interactor()
        interactor.UpdateSize(width, height)
        interactor.InvokeEvent(vtk.vtkCommand.WindowResizeEvent)


class ProgressiveScheduler(RcaImageRenderScheduler):
    """trame-rca's image scheduler, with each frame encoded and sent before the next is drawn.

    trame-rca encodes on a thread and sends from another task, which runs only
    when the event loop is free; drawing is synchronous, so on a busy
    machine a frame drawn while the mouse moved waited behind the next
    frame's drawing (up to seconds on 2 shared cores) before it left. Here
    the loop awaits the encoding (the loop takes events meanwhile), sends
    the frame, then leaves ``EVENT_GAP_S`` for the events that arrived
    during the frame. Built on trame-rca 2.11's scheduler internals
    (``_render``, ``_render_frame``), which the project pins.
    """

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self._frame_sent = asyncio.Event()
        # Called after each frame left for the page.
        self.on_frame_sent = lambda: None

    async def send_frame(self, timeout_s: float) -> bool:
        """Draw a frame and wait until it has been sent to the page (False if that took longer than ``timeout_s``)."""
        self._frame_sent.clear()
        self.schedule_render()
        try:
            await asyncio.wait_for(self._frame_sent.wait(), timeout_s)
        except asyncio.TimeoutError:
            return False
        return True

    async def _render(self):
        while not self._is_closing:
            await self._request_event.wait()
            if self._is_closing:
                break
            self._request_event.clear()
            started = monotonic()
            image, meta, m_time = await self._encode_frame(self._interactive_quality)
            if m_time >= self._last_push_time_ms and self._push_callback is not None:
                self._last_push_time_ms = m_time
                self._push_callback(image, meta)
            self._frame_sent.set()
            self.on_frame_sent()
            await asyncio.sleep(max(EVENT_GAP_S, self._target_period_s - (monotonic() - started)))

    def _encode_frame(self, quality):
        np_img, cols, rows = self._rca.img_cols_rows
        return asyncio.get_running_loop().run_in_executor(self._encode_pool, self._rca_encoder.encode, np_img, cols,
                                                          rows, quality)


class ProgressiveThreeDViewFactory(RemoteViewFactory):
    """trame-slicer's remote 3D view factory, with the preview window and ``ProgressiveArea``."""

    def __init__(self, server, **kwargs):
        super().__init__(server, VolumeCutThreeDView, ViewType.THREE_D_VIEW, **kwargs)
        self.previews = {}
        self.areas = {}
        self.schedulers = {}

    def _create_view(self, view, scene, app_logic) -> RcaView:
        view_id = view.singleton_tag
        main_view = VolumeCutThreeDView(scene=scene, app_logic=app_logic, name=view_id)
        main_view.set_view_properties(view.properties)
        preview = VolumeCutThreeDView(scene=scene, app_logic=app_logic, name=view_id + PREVIEW_SUFFIX)
        preview.set_view_properties(view.properties)
        preview.get_view_node().SetMappedInLayout(True)
        cursor = f"{view_id}_active_view_cursor"
        self._server.state.setdefault(cursor, CursorId.DEFAULT.value)
        area = ProgressiveArea(main_view, preview, self._server.state, cursor)
        scheduler = ProgressiveScheduler(window=area, interactive_quality=self._interactive_quality,
                                            rca_encoder=self._rca_encoder, target_fps=self._target_fps)
        trame_id = get_view_trame_id(self._server, main_view)
        with ViewLayout(self._server, template_name=trame_id) as layout:
            self._create_vuetify_ui(trame_id, main_view, scheduler, active_view_cursor=cursor)
        adapter = RcaViewAdapter(window=area, name=trame_id, scheduler=scheduler, do_schedule_render_on_interaction=False)
        strategy = RcaRenderStrategy(scheduler)
        main_view.set_scheduled_render(strategy)
        preview.set_scheduled_render(RcaRenderStrategy(scheduler))
        self.previews[view_id] = preview
        self.areas[view_id] = area
        self.schedulers[view_id] = scheduler

        async def register():
            await self._server.ready
            self._server.root_server.controller.rc_area_register(adapter)

        create_task(register())
        return RcaView(layout, main_view, adapter)


class ProgressiveRendering:
    """Which window of the 3D view draws, and when the main window refines.

    * While the camera moves (drags, wheel zoom, camera buttons), right
      after the view is resized and for the first picture of new data, the
      preview draws interactive frames at ``navigate_scale``: the mapper
      casts as many rays as fit in 1 / ``navigate_fps`` seconds, without
      ambient occlusion.
    * While the user drills, the preview draws at ``drill_scale``.
    * At rest, the preview is first brought up to date at ``drill_scale`` if
      the camera moved (a still frame, so that the next stroke recasts only
      what it changes), then, ``delay_s`` after the last interaction, the
      main window draws at full resolution and full quality.
    """

    def __init__(self, area: ProgressiveArea, scheduler, navigate_scale: float, drill_scale: float, delay_s: float,
                 interactive_quality: int = 60, still_quality: int = 90, navigate_fps: float = 20.0):
        self.area = area
        self.scheduler = scheduler
        self.interactive_quality = interactive_quality
        self.still_quality = still_quality
        self.navigate_scale = navigate_scale
        self.drill_scale = drill_scale
        self.navigate_fps = navigate_fps
        self.delay_s = delay_s
        self._draft = False
        self._stroke_sample_distance = None
        self._timer = None
        self._navigating = False
        self._stroke = False
        self._button_down = False
        self._after_preview = None
        self._preview_signature = None
        self._camera = None
        area.main_view.renderer().GetActiveCamera().AddObserver(vtk.vtkCommand.ModifiedEvent, self._camera_moved)
        area.preview_view.renderer().AddObserver(vtk.vtkCommand.EndEvent, self._preview_drawn)
        area.on_resize = self._resized
        self._sync_camera()

    @property
    def interacting(self) -> bool:
        return self._navigating or self._stroke

    def button_pressed(self) -> None:
        self._button_down = True

    def button_released(self) -> None:
        self._button_down = False
        if self._navigating:
            self._navigating = False
            self._rest()

    def stroke_started(self) -> None:
        self._cancel()
        # A stroke right after a camera move starts from still frames: its frames keep the mapper's own settings.
        self._set_draft(False)
        self._stroke = True
        self._show(True, self.drill_scale)

    def stroke_ended(self) -> None:
        self._stroke = False
        self._rest()

    def content_changed(self) -> None:
        """The cut changed without a stroke (undo, redo): both windows draw it anew, the preview first, then the main window."""
        if self.interacting:
            return
        self._cancel()
        self._preview_signature = None
        self._rest()

    def pointer_moved(self) -> None:
        """The drill hovers over the bone: its glyph moves in the drill preview, which refines at rest."""
        if self.interacting:
            return
        self._cancel()
        self._show(True, self.drill_scale)
        if self._preview_current():
            self._arm_refine()
        else:
            self._after_preview = self._arm_refine

    def _camera_moved(self, *_):
        """A camera that moves outside a stroke is navigation: the view previews coarsely until it rests."""
        self._sync_camera()
        signature = camera_signature(self.area.main_view.renderer().GetActiveCamera())
        if signature == self._camera:
            return
        self._camera = signature
        if self._stroke:
            return
        self._cancel()
        self._navigating = self._button_down
        self._show(True, self.navigate_scale, draft=True)
        if not self._button_down:
            # Wheel zoom, camera buttons: no release comes; rest once this coarse frame is drawn.
            self._after_preview = self._rest

    def _resized(self) -> None:
        if self.interacting:
            self._show(True, self.area.preview_scale, draft=self._draft)
            return
        self._cancel()
        self._show(True, self.navigate_scale, draft=True)
        self._after_preview = self._rest

    async def first_frame(self, timeout_s: float = 30.0) -> bool:
        """New data is in the scene: send its first picture now, as an interactive frame (quick), then refine.

        The first frame of a mapper also prepares its scene (bricks, empty
        space, segment surfaces), so the loading step that awaits this takes
        that time while the page still shows progress, and the picture is in
        the page when it says Ready. False when the page has not said how
        large the view is (the preview window still draws once, unseen, to
        prepare its scene: the picture its first size draws is then quick) or
        the frame took longer than ``timeout_s``.
        """
        if not self.area.sized:
            self._set_draft(True)
            self.area.preview_view.render_window().Render()
            return False
        self._cancel()
        self._show(True, self.navigate_scale, draft=True)
        sent = await self.scheduler.send_frame(timeout_s)
        self._rest()
        return sent

    def _sync_camera(self, *_):
        """The preview looks through the main window's camera."""
        source = self.area.main_view.renderer().GetActiveCamera()
        camera_node = self.area.preview_view.get_camera_node()
        target = camera_node.GetCamera() if camera_node is not None else self.area.preview_view.renderer().GetActiveCamera()
        target.DeepCopy(source)
        target.SetClippingRange(source.GetClippingRange())

    def _preview_drawn(self, *_):
        if self.area.preview_scale == self.drill_scale and not self._draft:
            self._preview_signature = (camera_signature(self.area.main_view.renderer().GetActiveCamera()), self.area.size)
        follow, self._after_preview = self._after_preview, None
        if follow is not None:
            asyncio.get_event_loop().call_soon(follow)

    def _preview_current(self) -> bool:
        return self._preview_signature == (camera_signature(self.area.main_view.renderer().GetActiveCamera()), self.area.size)

    def _cancel(self) -> None:
        self._after_preview = None
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None

    def _show(self, preview: bool, scale: float | None = None, draft: bool = False) -> None:
        if scale is not None:
            self.area.set_preview_scale(scale)
        self._set_draft(preview and draft)
        self.area.use_preview = preview
        # One encoding per frame (no second, finer one of the same image): coarse while
        # interacting, fine at rest.
        quality = self.interactive_quality if preview else self.still_quality
        self.scheduler.update_quality(quality, quality)
        self.scheduler.schedule_render()

    def _set_draft(self, draft: bool) -> None:
        """Interactive frames in the preview, or still ones (a stroke's rate is the displayable manager's)."""
        if draft == self._draft or self._stroke:
            # During a stroke the flag stays as the mapper is, so that the call after the stroke restores it.
            return
        self._draft = draft
        window = self.area.preview_view.render_window()
        coarsest = max(1, round(window.GetSize()[0] / MINIMUM_RAYS_ACROSS))
        for volume in self.area.preview_view.renderer().GetVolumes():
            mapper = volume.GetMapper()
            if not isinstance(mapper, slicer.vtkVolumeCutVolumeMapper):
                continue
            # The cap holds for the camera's motion only: a stroke's frames keep the mapper's own.
            if draft:
                self._stroke_sample_distance = mapper.GetMaximumImageSampleDistance()
                mapper.SetMaximumImageSampleDistance(min(coarsest, self._stroke_sample_distance))
            elif self._stroke_sample_distance is not None:
                mapper.SetMaximumImageSampleDistance(self._stroke_sample_distance)
        window.SetDesiredUpdateRate(self.navigate_fps if draft else STILL_UPDATE_RATE)

    def _rest(self) -> None:
        self._cancel()
        if self.interacting:
            return
        if not self._preview_current():
            # The drill preview redraws now, at its scale, while the user looks; then the main window refines.
            self._show(True, self.drill_scale)
            self._after_preview = self._arm_refine
            return
        self._arm_refine()

    def _arm_refine(self) -> None:
        if self._timer is not None:
            self._timer.cancel()
        self._timer = asyncio.get_event_loop().call_later(self.delay_s, self._refine)

    def _refine(self) -> None:
        self._timer = None
        if not self.interacting:
            self._show(False)
