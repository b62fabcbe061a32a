"""The instructor link: a second page on a trainee's session that watches, points, guides, freezes and may take control.

The rules are ``collaboration.cosession.CoSession``'s; this module applies
them to the web server of one session:

* joining: wslink asks every page for a secret when it connects
  (``validate``): the trainee's (the server's ``authKey``) or the
  instructor's. Pages with neither get nothing, not even the views.
  ``GET /instructor?key=...`` checks a link and opens the page, or answers
  403 with what to do (a guessed key, or one the trainee has renewed);
* the gate (``bind``): every message of a page passes here before trame
  sees it. Mouse events and view sizes, state changes, triggers and every
  other RPC (trame-rca's frame pushes and encoder settings, wslink's exit)
  apply only from the page in control; an instructor page is shown
  everything trame pushes (views, segment table, nerve monitor, the drill
  sound's parameters), reads the state and may use its own triggers
  (``vc_co_*``); anything else is refused and the page told why (``notify``);
* the instructor's marks in the scene (a yellow marker, the guide axis in
  cyan), seen in every page. The axis enters the bone where the instructor
  clicks and runs along the line of sight for the depth they chose; it stays
  in the anatomy when the camera turns, and the mouse drill holds the burr
  on it (``views.DrillController.guide``);
* the pages' parts: the trainee's link panel and consent dialog, the
  instructor's panel, the frozen banner and the pick layer over the 3D view.

Built on wslink 2.6's handler (``functionMap``, ``authentified_client_ids``,
``last_active_client_id``) and trame-rca's RPC names, which the project pins.
"""

from __future__ import annotations

import hashlib
import html as html_text
import time

import numpy as np

from aiohttp import web
from trame.widgets import html
from trame.widgets import vuetify3 as v3

from ..collaboration.cosession import TRAINEE, CoSession, CoSessionRefused
from .session import balls_and_tube

# Triggers any joined page may call: they check their caller's role themselves (a trainee tab takes over, or
# takes control back from the instructor), as the co-session's own (vc_co_*) do.
OPEN_TRIGGERS = ("vc_hello", "vc_diagnostics", "vc_take_over")
COSESSION_PREFIX = "vc_co_"
# wslink RPCs any joined page may call: they read, or concern the page alone.
OPEN_RPCS = ("trame.state.get", "trame.error.client", "trame.force.push")
# The lifecycle names trame's page sends; any other would call a controller callback of the server (on_server_ready
# loads the data again).
PAGE_LIFECYCLE = ("client_connected", "client_exited", "client_unmounted")
# A page closing may end the server (wslink's application.exit*): only the trainee's page in control.
EXIT_RPCS = ("application.exit", "application.exit.later")
# A refused mouse press is told at most this often (a drag sends dozens of events).
NOTICE_INTERVAL_S = 1.0
POINTER_COLOR = (1.0, 0.85, 0.0)
AXIS_COLOR = (0.0, 0.9, 1.0)
POINTER_RADIUS_MM = 1.8
AXIS_RADIUS_MM = 0.5
AXIS_DEPTH_RANGE_MM = (1.0, 30.0)
DEFAULT_AXIS_DEPTH_MM = 8.0

STALE_PAGE = """<!doctype html><html><head><title>Instructor link refused</title></head>
<body style="font-family: sans-serif; max-width: 40em; margin: 4em auto;">
<h2 data-testid="link-refused">This instructor link is not valid</h2>
<p>{reason}</p><p>Ask the trainee for the current link: it is shown in their page, panel <b>Instructor link</b>.</p>
</body></html>"""


class CutDigest:
    """SHA-256 of a cut field's samples, brought up to date brick by brick: equal digests, the same cut bit for bit.

    The test hook ``vc_co_checksum`` asks for it after each action a test
    checks; hashing every sample each time would cost the whole cut. Each
    allocated brick's digest is kept with the brick's stamp, so a call hashes
    only the bricks written since the last (``CopyBrick`` returns the stamp
    of the samples it copied) and reads the other bricks' stamps. Bricks
    holding only "far outside" samples count as absent, as unallocated ones are.
    """

    FAR_OUTSIDE = 32767

    def __init__(self):
        self._field = None
        self._stamp = 0
        self._bricks: dict[int, tuple[int, bytes]] = {}  # brick id -> (stamp, digest; b"" if all far outside)
        self._values = np.zeros(512, dtype=np.int16)

    def hexdigest(self, field) -> str:
        if field is None:
            return ""
        current = field.GetCurrentStamp()
        if field is not self._field or current < self._stamp:  # another field, or this one started over
            self._field, self._bricks = field, {}
        self._stamp = current
        digest = hashlib.sha256()
        for n in range(field.GetNumberOfAllocatedBricks()):
            brick = field.GetAllocatedBrickId(n)
            known = self._bricks.get(brick)
            if known is None or known[0] != field.GetBrickStamp(brick):
                stamp = field.CopyBrick(brick, self._values)
                far = bool(np.all(self._values == self.FAR_OUTSIDE))
                known = self._bricks[brick] = (stamp, b"" if far else hashlib.sha256(self._values.tobytes()).digest())
            if known[1]:
                digest.update(int(brick).to_bytes(8, "little") + known[1])
        return digest.hexdigest()


class InstructorLink:
    """The co-session of one application (``webapp.app.VolumeCuttingApp``)."""

    def __init__(self, app):
        self.app = app
        self.server = app.server
        self._cosession = None
        self._sizes: dict[str, dict[str, tuple]] = {}  # client -> area -> (origin, size) it last reported
        self._size_call = None  # trame-rca's size RPC, to apply the new controller's sizes
        self._handlers = []
        self._last_notice: dict[str, float] = {}
        self._marks = {}
        self._cut_digest = CutDigest()
        self.refused = {"events": 0, "sizes": 0, "state": 0, "triggers": 0, "other": 0}  # for tests
        self.server.controller.on_server_bind.add(self.bind)
        self._bind_triggers()

    @property
    def cosession(self) -> CoSession:
        # The trainee's secret is the server's key, known once wslink configured its protocol.
        if self._cosession is None:
            self._cosession = CoSession(self.server.protocol.secret)
        return self._cosession

    # ------------------------------------------------------------------ joining

    def validate(self, token, client_id: str) -> bool:
        """wslink's hello: the page joins as trainee or instructor, or not at all."""
        role = self.cosession.authenticate(token, client_id)
        if role is not None:
            self.publish()
        return role is not None

    def left(self, client_id: str) -> None:
        controller = self.cosession.controller
        self.cosession.left(client_id)
        self._sizes.pop(client_id, None)
        if self.cosession.controller != controller:
            self._control_changed()
        self.publish()

    def _drop(self, client_id: str) -> None:
        """Take a page out of the session now: nothing more is sent to it, and its connection closes."""
        from trame_server.utils.asynchronous import create_task

        for handler in self._handlers:
            handler.authentified_client_ids.discard(client_id)
            connection = handler.connections.get(client_id)
            if connection is not None:
                create_task(connection.close(code=4001, message=b"instructor link renewed"))

    async def _link_page(self, request):
        key = request.query.get("key", "")
        if self._cosession is not None and self.cosession.is_instructor_secret(key):
            raise web.HTTPFound(f"/?secret={key}")
        reason = ("The link has no key." if not key else
                  "Its key is wrong, or the trainee has made a new link (the old one stops working), "
                  "or the session has ended.")
        return web.Response(status=403, text=STALE_PAGE.format(reason=html_text.escape(reason)), content_type="text/html")

    # ------------------------------------------------------------------ the gate

    def bind(self, web_server) -> None:
        """Put the gate in front of wslink's RPCs and serve the link's page."""
        web_server.app.router.add_get("/instructor", self._link_page)
        gates = {"trame.rca.event": self._gate_event, "trame.rca.size": self._gate_size,
                 "trame.state.update": self._gate_state, "trame.trigger": self._gate_trigger,
                 "trame.lifecycle.update": self._gate_lifecycle}
        gates.update({uri: self._gate_open for uri in OPEN_RPCS})
        gates.update({uri: self._gate_exit for uri in EXIT_RPCS})
        for handler in getattr(web_server, "_ws_handlers", []):
            self._handlers.append(handler)
            for uri in gates:
                if uri not in handler.functionMap and uri not in EXIT_RPCS:
                    raise RuntimeError(f"wslink has no {uri}: the instructor link's gate needs the pinned trame")
            for uri, (protocol, function) in list(handler.functionMap.items()):
                if uri == "trame.rca.size":
                    self._size_call = (protocol, function)
                gate = gates.get(uri, self._gate_controller)
                handler.functionMap[uri] = (protocol, self._gated(handler, function, gate))

    @staticmethod
    def _gated(handler, function, gate):
        def call(*args, **kwargs):
            return gate(str(handler.web_app.last_active_client_id), function, args, kwargs)

        return call

    def _gate_open(self, client, function, args, kwargs):
        return function(*args, **kwargs) if self.cosession.may(client, "observe") else None

    def _gate_controller(self, client, function, args, kwargs):
        if self.cosession.may(client, "drive"):
            return function(*args, **kwargs)
        self.refused["other"] += 1
        return None

    def _gate_lifecycle(self, client, function, args, kwargs):
        if len(args) > 1 and args[1] in PAGE_LIFECYCLE and self.cosession.may(client, "observe"):
            return function(*args, **kwargs)
        return None

    def _gate_exit(self, client, function, args, kwargs):
        if self.cosession.may(client, "drive") and self.cosession.role(client) == TRAINEE:
            return function(*args, **kwargs)
        return None

    def _gate_event(self, client, function, args, kwargs):
        if self.cosession.may(client, "drive"):
            return function(*args, **kwargs)
        self.refused["events"] += 1
        event = args[3] if len(args) > 3 and isinstance(args[3], dict) else {}
        kind = str(event.get("type", ""))
        if "Press" in kind or "Wheel" in kind:
            self._refuse(client, "drive", throttle=True)
        return None

    def _gate_size(self, client, function, args, kwargs):
        if len(args) >= 4:
            self._sizes.setdefault(client, {})[args[1]] = (args[2], args[3])
        if self.cosession.may(client, "drive"):
            return function(*args, **kwargs)
        self.refused["sizes"] += 1
        return None

    def _gate_state(self, client, function, args, kwargs):
        if self.cosession.may(client, "drive"):
            return function(*args, **kwargs)
        self.refused["state"] += 1
        changes = args[1] if len(args) > 1 and isinstance(args[1], list) else []
        # The page shows the session's values again, not what it tried to set.
        keys = [c.get("key") for c in changes if isinstance(c, dict) and c.get("key") in self.server.state]
        if keys:
            self._tell(client, {key: self.server.state[key] for key in keys})
        return None

    def _gate_trigger(self, client, function, args, kwargs):
        name = args[1] if len(args) > 1 else ""
        if name in OPEN_TRIGGERS or (isinstance(name, str) and name.startswith(COSESSION_PREFIX)) \
                or self.cosession.may(client, "drive"):
            return function(*args, **kwargs)
        self.refused["triggers"] += 1
        self._refuse(client, "drive")
        return None

    def _refuse(self, client, action, throttle=False) -> None:
        try:
            self.cosession.check(client, action)
        except CoSessionRefused as refusal:
            self.notify(client, str(refusal), throttle)

    def notify(self, client: str, text: str, throttle: bool = False) -> None:
        """Show ``text`` in one page only (its ``vc_notice``)."""
        now = time.monotonic()
        if throttle and now - self._last_notice.get(client, -1e9) < NOTICE_INTERVAL_S:
            return
        self._last_notice[client] = now
        self._tell(client, {"vc_notice": text, "vc_notice_at": time.time()})

    def _tell(self, client: str, values: dict) -> None:
        protocol = self.server.protocol
        if protocol is not None and client:
            protocol.publish("trame.state.topic", values, client_id=client)

    # ------------------------------------------------------------------ control

    def _sender(self) -> str:
        return self.app._sender()

    def _control_changed(self) -> None:
        """The new controller's page sizes the views (its mouse lands where it points); an open stroke ends."""
        if self.app.drill.end_stroke():
            self.app._refresh_tables()
        controller = self.cosession.controller
        if self._size_call is not None and controller in self._sizes:
            protocol, function = self._size_call
            for area, (origin, size) in self._sizes[controller].items():
                function(protocol, area, origin, size)

    def take_over(self, client: str) -> None:
        controller = self.cosession.controller
        self.cosession.take_over(client)
        if self.cosession.controller != controller:
            self._control_changed()
        self.publish()

    def publish(self) -> None:
        """The co-session's shared state: who controls, whether an instructor is here, a request, the freeze."""
        cosession = self.cosession
        with self.server.state as state:
            state.vc_owner = cosession.controller or ""
            state.vc_owner_role = cosession.controller_role or ""
            state.vc_instructor_present = cosession.instructor_present
            state.vc_control_request = cosession.control_request is not None
            state.vc_frozen = cosession.frozen
            state.vc_guide = ({"entry": list(cosession.guide.entry), "target": list(cosession.guide.target),
                               "length": round(cosession.guide.length, 2)} if cosession.guide else None)
            state.vc_pointer = list(cosession.pointer) if cosession.pointer else None

    # ------------------------------------------------------------------ marks in the scene

    def _pick(self, fx, fy):
        """The surface point (RAS) under a point of the 3D view given as fractions (0 at the left and bottom)."""
        fx, fy = float(fx), float(fy)
        if not (0.0 <= fx <= 1.0 and 0.0 <= fy <= 1.0):
            raise CoSessionRefused("Click inside the 3D view")
        sources = [s for s in self.app.drill.depth_sources() if s.depth is not None]
        if not sources:
            raise CoSessionRefused("The 3D view has not been drawn yet: wait for the picture")
        hit = max(sources, key=lambda s: s.captured_at).surface_point(fx, fy)
        if hit is None:
            raise CoSessionRefused("Nothing is under that point: click on the bone")
        return hit

    def _mark_model(self, name: str, color) -> object:
        node = self._marks.get(name)
        if node is None or node.GetScene() is None:
            node = self.app.slicer_app.scene.AddNewNodeByClass("vtkMRMLModelNode", name)
            node.CreateDefaultDisplayNodes()
            node.GetDisplayNode().SetColor(*color)
            node.GetDisplayNode().SetVisibility2D(True)
            self._marks[name] = node
        return node

    def _draw_marks(self) -> None:
        cosession = self.cosession
        pointer = [cosession.pointer] if cosession.pointer else []
        self._mark_model("Instructor marker", POINTER_COLOR).SetAndObservePolyData(
            balls_and_tube(pointer, POINTER_RADIUS_MM, 0.0))
        axis = [cosession.guide.entry, cosession.guide.target] if cosession.guide else []
        self._mark_model("Instructor guide axis", AXIS_COLOR).SetAndObservePolyData(
            balls_and_tube(axis, 2.0 * AXIS_RADIUS_MM, AXIS_RADIUS_MM))
        self.app.drill.guide = cosession.guide
        if self.app.progressive is not None:
            self.app.progressive.content_changed()

    # ------------------------------------------------------------------ triggers

    def _bind_triggers(self) -> None:
        ctrl = self.server.controller

        def answer(action):
            """Run a co-session step for the page that asked; a refusal is told to that page and returned."""
            client = self._sender()
            try:
                result = action(client)
            except CoSessionRefused as refusal:
                self.notify(client, str(refusal))
                return {"refused": str(refusal)}
            self.publish()
            return {"ok": True, "result": result}

        @ctrl.trigger("vc_co_link")
        def link():
            # The trainee's page shows the link; only a trainee page is given the key.
            return answer(lambda client: self.cosession.check(client, "link") or self.cosession.instructor_secret)

        @ctrl.trigger("vc_co_renew")
        def renew():
            def renew_link(client):
                self.cosession.check(client, "renew_link")
                for instructor in self.cosession.renew_instructor_link():
                    self._drop(instructor)
                    self._sizes.pop(instructor, None)
                self._control_changed()
                return self.cosession.instructor_secret
            return answer(renew_link)

        @ctrl.trigger("vc_co_pick")
        def pick(tool, fx, fy, depth_mm=DEFAULT_AXIS_DEPTH_MM):
            def place(client):
                if tool not in ("point", "axis"):
                    raise CoSessionRefused(f"Unknown instructor tool {tool!r}")
                self.cosession.check(client, tool)
                point, direction = self._pick(fx, fy)
                if tool == "point":
                    self.cosession.point(client, point)
                else:
                    depth = float(depth_mm)
                    if not AXIS_DEPTH_RANGE_MM[0] <= depth <= AXIS_DEPTH_RANGE_MM[1]:
                        raise CoSessionRefused(f"Axis depth {depth_mm!r} mm: give {AXIS_DEPTH_RANGE_MM[0]:g} to "
                                               f"{AXIS_DEPTH_RANGE_MM[1]:g} mm")
                    self.cosession.set_guide(client, point, point + depth * direction)
                self._draw_marks()
                return [float(v) for v in point]
            return answer(place)

        @ctrl.trigger("vc_co_clear")
        def clear():
            def clear_marks(client):
                self.cosession.clear_marks(client)
                self._draw_marks()
            return answer(clear_marks)

        @ctrl.trigger("vc_co_freeze")
        def freeze(frozen):
            def set_frozen(client):
                self.cosession.freeze(client, bool(frozen))
                if self.cosession.frozen:
                    self.app.drill.end_stroke()  # a stroke under way stops now; what it cut stays
            return answer(set_frozen)

        @ctrl.trigger("vc_co_undo")
        def undo():
            def undo_stroke(client):
                self.cosession.check(client, "undo")
                self.app.drill.end_stroke()
                self.app._undo_redo(self.app.session.undo)
            return answer(undo_stroke)

        @ctrl.trigger("vc_co_request")
        def request():
            return answer(self.cosession.request_control)

        @ctrl.trigger("vc_co_answer")
        def consent(accept):
            def reply(client):
                controller = self.cosession.answer_request(client, bool(accept))
                if controller is not None:
                    self._control_changed()
                return controller is not None
            return answer(reply)

        @ctrl.trigger("vc_co_give_back")
        def give_back():
            def hand_back(client):
                self.cosession.give_back(client)
                self._control_changed()
            return answer(hand_back)

        if self.app.options.test_hooks:
            # Tests only (--test-hooks): the cut as it is, to show that refused pages changed nothing.
            @ctrl.trigger("vc_co_checksum")
            def checksum():
                def digest(client):
                    self.cosession.check(client, "observe")
                    session = self.app.session
                    return self._cut_digest.hexdigest(session.logic.GetCutField(session.cut_node) if session.has_data else None)
                return answer(digest)

    def stroke_refusal(self) -> str | None:
        """Why a stroke may not begin now (the drill frozen), told to the page that drills; None when it may."""
        try:
            self.cosession.check_stroke()
        except CoSessionRefused as refusal:
            if self.cosession.controller:
                self.notify(self.cosession.controller, str(refusal), throttle=True)
            return str(refusal)
        return None

    # ------------------------------------------------------------------ page

    def three_d_overlay(self) -> None:
        """Over the 3D view: the frozen banner, and the instructor's pick layer while pointing or drawing the axis."""
        with html.Div(v_show="vc_frozen", raw_attrs=['data-testid="frozen-banner"'],
                      style="position: absolute; bottom: 32px; left: 50%; transform: translateX(-50%); z-index: 3; "
                            "background: #1565c0; color: white; padding: 4px 12px; border-radius: 4px; "
                            "pointer-events: none; font-size: 13px;"):
            html.Span("Drill frozen by the instructor")
        html.Div(v_if="vc_role === 'instructor' && vc_ins_tool !== 'watch' && vc_owner !== vc_client_id",
                 raw_attrs=['data-testid="instructor-pick"'],
                 style="position: absolute; inset: 0; z-index: 2; cursor: crosshair;",
                 click="trigger('vc_co_pick', utils.vc.pickArguments(vc_ins_tool, $event, vc_ins_axis_depth))"
                       ".then((r) => { if (r && r.ok && vc_ins_tool === 'point') vc_ins_tool = 'watch'; })")

    def trainee_panel(self) -> None:
        with v3.VExpansionPanel(v_if="vc_role === 'trainee'", value="instructor", title="Instructor link",
                                raw_attrs=['data-testid="instructor-link-panel"']), v3.VExpansionPanelText():
            html.Div("Your instructor joins with this link: they see your views, the segments and the nerve monitor, "
                     "can point, draw a guide axis, freeze the drill and undo; they drill only if you accept.",
                     classes="text-caption")
            v3.VTextField(model_value=("vc_co_link",), readonly=True, density="compact", hide_details=True,
                          classes="mt-1", raw_attrs=['data-testid="instructor-link"'],
                          append_inner_icon="mdi-content-copy",
                          click_appendInner="navigator.clipboard && navigator.clipboard.writeText(vc_co_link)")
            with html.Div(classes="d-flex align-center mt-1"):
                html.Span("{{ vc_instructor_present ? 'Instructor connected' : 'No instructor connected' }}",
                          classes="text-caption", raw_attrs=['data-testid="instructor-presence"'])
                v3.VSpacer()
                v3.VBtn("New link", size="small", variant="text", prepend_icon="mdi-link-variant-off",
                        raw_attrs=['data-testid="renew-link"'],
                        click="trigger('vc_co_renew').then((r) => { if (r && r.ok) vc_co_link = "
                              "utils.vc.instructorLink(r.result); })")

    def instructor_panel(self) -> None:
        with v3.VExpansionPanel(v_if="vc_role === 'instructor'", value="instructor", title="Instructor",
                                raw_attrs=['data-testid="instructor-panel"']), v3.VExpansionPanelText():
            html.Div("{{ vc_owner === vc_client_id ? 'You have control: drill in the 3D view.' : "
                     "vc_control_request ? 'Waiting for the trainee to accept...' : 'Watching the trainee.' }}",
                     classes="text-body-2", raw_attrs=['data-testid="instructor-status"'])
            with v3.VBtnToggle(v_model=("vc_ins_tool",), mandatory=True, density="compact", classes="mt-2",
                               raw_attrs=['data-testid="instructor-tool"']):
                for tool, label, icon in (("watch", "Watch", "mdi-eye"), ("point", "Point", "mdi-map-marker"),
                                          ("axis", "Guide axis", "mdi-vector-line")):
                    v3.VBtn(label, value=tool, size="small", prepend_icon=icon, raw_attrs=[f'data-testid="tool-{tool}"'])
            html.Div("{{ vc_ins_tool === 'axis' ? 'Click the entry: the axis runs into the bone along your line of "
                     "sight.' : vc_ins_tool === 'point' ? 'Click where the trainee should look.' : '' }}",
                     classes="text-caption")
            v3.VSlider(v_if="vc_ins_tool === 'axis'", v_model=("vc_ins_axis_depth",), min=AXIS_DEPTH_RANGE_MM[0],
                       max=AXIS_DEPTH_RANGE_MM[1], step=0.5, label="Axis depth (mm)", thumb_label=True,
                       density="compact", hide_details=True, raw_attrs=['data-testid="axis-depth"'])
            html.Div("Guide axis: {{ vc_guide ? vc_guide.length.toFixed(1) + ' mm; the trainee drills along it' : 'none' }}",
                     classes="text-caption", raw_attrs=['data-testid="guide-status"'])
            with html.Div(classes="d-flex flex-wrap ga-1 mt-2"):
                v3.VBtn("{{ vc_frozen ? 'Release the drill' : 'Freeze the drill' }}", size="small",
                        color=("vc_frozen ? 'primary' : undefined",), prepend_icon="mdi-snowflake",
                        click="trigger('vc_co_freeze', [!vc_frozen])", raw_attrs=['data-testid="freeze"'])
                v3.VBtn("Undo", size="small", prepend_icon="mdi-undo", click="trigger('vc_co_undo')",
                        disabled=("vc_undo_count === 0",), raw_attrs=['data-testid="instructor-undo"'])
                v3.VBtn("Clear marks", size="small", variant="text", click="trigger('vc_co_clear')",
                        raw_attrs=['data-testid="clear-marks"'])
                v3.VBtn("Ask for control", v_if="vc_owner !== vc_client_id", size="small", color="primary",
                        disabled=("vc_control_request",), click="trigger('vc_co_request')",
                        raw_attrs=['data-testid="request-control"'])
                v3.VBtn("Give control back", v_else=True, size="small", color="primary",
                        click="trigger('vc_co_give_back')", raw_attrs=['data-testid="give-back"'])

    def dialogs(self) -> None:
        """The trainee's consent, the notice of a refused action, and the trainee's way back to control."""
        with v3.VDialog(model_value=("vc_role === 'trainee' && vc_control_request",), persistent=True, max_width=460,
                        raw_attrs=['data-testid="consent-dialog"']):
            with v3.VCard(classes="pa-2"):
                v3.VCardTitle("Your instructor asks for control")
                v3.VCardText("They would drill in this session until you take control back (button at the top). "
                             "Everything stays undoable.")
                with v3.VCardActions():
                    v3.VSpacer()
                    v3.VBtn("Decline", click="trigger('vc_co_answer', [false])", raw_attrs=['data-testid="decline"'])
                    v3.VBtn("Accept", color="primary", click="trigger('vc_co_answer', [true])",
                            raw_attrs=['data-testid="accept"'])
        v3.VSnackbar(model_value=("!!vc_notice",), update_modelValue="vc_notice = $event ? vc_notice : ''", text=("vc_notice",),
                     color="warning", timeout=8000, max_width=640, raw_attrs=['data-testid="notice"'])

    def toolbar_button(self) -> None:
        v3.VBtn("Take back control", v_if="vc_role === 'trainee' && vc_owner_role === 'instructor'", color="warning",
                variant="flat", classes="mr-2", click="trigger('vc_take_over')", raw_attrs=['data-testid="take-back"'])

    def initial_state(self) -> dict:
        return {"vc_role": "", "vc_owner_role": "", "vc_instructor_present": False, "vc_control_request": False,
                "vc_frozen": False, "vc_guide": None, "vc_pointer": None, "vc_co_link": "", "vc_ins_tool": "watch",
                "vc_ins_axis_depth": DEFAULT_AXIS_DEPTH_MM, "vc_notice": "", "vc_notice_at": 0}

    CLIENT_ONLY = ("vc_role", "vc_co_link", "vc_ins_tool", "vc_ins_axis_depth", "vc_notice", "vc_notice_at")

    HELLO = ("trigger('vc_hello').then((me) => { vc_client_id = me.id; vc_role = me.role; "
             "if (me.role === 'trainee') trigger('vc_co_link').then((r) => { "
             "if (r && r.ok) vc_co_link = utils.vc.instructorLink(r.result); }); })")

    def hello(self) -> dict:
        """A page has mounted its views: it is told who it is, and every view draws once more for it (the views
        draw only when something changes, and a page that joins later would otherwise stay black)."""
        client = self._sender()
        self.app.three_d_view.schedule_render()
        for view in self.app.slicer_app.view_manager.get_slice_views():
            view.schedule_render()
        return {"id": client, "role": self.cosession.role(client) or ""}

