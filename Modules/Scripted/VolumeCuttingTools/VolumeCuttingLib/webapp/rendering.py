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
"""

from __future__ import annotations

import asyncio

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
        scheduler = RcaImageRenderScheduler(window=area, interactive_quality=self._interactive_quality,
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

    * While the camera moves (drags, wheel zoom, camera buttons) and right
      after the view is resized, the preview draws at ``navigate_scale``
      (every pixel is recast then).
    * While the user drills, the preview draws at ``drill_scale``.
    * At rest, the preview is first brought up to date at ``drill_scale`` if
      the camera moved (so that the next stroke recasts only what it
      changes), then, ``delay_s`` after the last interaction, the main
      window draws at full resolution.
    """

    def __init__(self, area: ProgressiveArea, scheduler, navigate_scale: float, drill_scale: float, delay_s: float,
                 interactive_quality: int = 60, still_quality: int = 90):
        self.area = area
        self.scheduler = scheduler
        self.interactive_quality = interactive_quality
        self.still_quality = still_quality
        self.navigate_scale = navigate_scale
        self.drill_scale = drill_scale
        self.delay_s = delay_s
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
        self._stroke = True
        self._show(True, self.drill_scale)

    def stroke_ended(self) -> None:
        self._stroke = False
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
        self._show(True, self.navigate_scale)
        if not self._button_down:
            # Wheel zoom, camera buttons: no release comes; rest once this coarse frame is drawn.
            self._after_preview = self._rest

    def _resized(self) -> None:
        if self.interacting:
            self._show(True, self.area.preview_scale)
            return
        self._cancel()
        self._show(True, self.navigate_scale)
        self._after_preview = self._rest

    def _sync_camera(self, *_):
        """The preview looks through the main window's camera."""
        source = self.area.main_view.renderer().GetActiveCamera()
        camera_node = self.area.preview_view.get_camera_node()
        target = camera_node.GetCamera() if camera_node is not None else self.area.preview_view.renderer().GetActiveCamera()
        target.DeepCopy(source)
        target.SetClippingRange(source.GetClippingRange())

    def _preview_drawn(self, *_):
        if self.area.preview_scale == self.drill_scale:
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

    def _show(self, preview: bool, scale: float | None = None) -> None:
        if scale is not None:
            self.area.set_preview_scale(scale)
        self.area.use_preview = preview
        # One encoding per frame (no second, finer one of the same image): coarse while
        # interacting, fine at rest.
        quality = self.interactive_quality if preview else self.still_quality
        self.scheduler.update_quality(quality, quality)
        self.scheduler.schedule_render()

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
