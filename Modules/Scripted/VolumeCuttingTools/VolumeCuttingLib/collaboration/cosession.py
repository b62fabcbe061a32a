"""A trainee's drilling session shared with an instructor: who may join, who may do what, and the guide axis.

No web server here: the web application (``webapp.instructorlink``) asks
``CoSession`` about every message a page sends, so the rules are tested
without a browser.

* Secrets: the trainee's (the web server's own key: wslink's ``authKey``,
  the launcher's per-session secret) and the instructor's, made here, never
  equal to the trainee's. A page proves one or the other when it connects;
  both are compared in constant time (``hmac.compare_digest``). Renewing the
  instructor link makes a new secret: the old link and every instructor
  page that joined with it lose the session.
* Control: one page at a time steers the views and drills (the
  controller): a trainee page (another trainee tab may take over, as
  before), or the instructor's once the trainee has accepted the
  instructor's request; the trainee takes it back whenever they like.
* Instructor powers, whoever controls: point (a marker in the 3D view),
  draw a guide axis (``GuideAxis``: the mouse drill's fixture), freeze the
  drill (every stroke is refused while frozen, unless the instructor holds
  control) and undo.

Everything refused raises ``CoSessionRefused`` whose message tells the page
what to do instead.
"""

from __future__ import annotations

import hmac
import math
import secrets
from dataclasses import dataclass

import numpy as np

TRAINEE = "trainee"
INSTRUCTOR = "instructor"

# What an instructor may do in any case; the rest of the session belongs to whoever controls it.
INSTRUCTOR_ACTIONS = ("point", "axis", "clear_marks", "freeze", "undo", "request_control", "give_back")
TRAINEE_ACTIONS = ("answer_request", "renew_link", "take_over", "link")
SECRET_PREFIX = "vc-"  # the page reads URL parameters that look like numbers as numbers: a secret never does

WATCHING = ("You are watching: the trainee drills. To drill yourself, ask for control and wait until the "
            "trainee accepts.")
OTHER_TAB = "This session is steered from another tab: take over there, or here with 'Drill from this tab'."
NOT_JOINED = "This page is not part of the session: open the session's link (or the instructor link) again."
FROZEN = "Your instructor has frozen the drill: wait until they release it."


class CoSessionRefused(PermissionError):
    """A page asked for something its role does not allow; the message says why and what to do."""


@dataclass(frozen=True)
class GuideAxis:
    """A planned trajectory from ``entry`` (on the surface) to ``target`` (RAS, mm): the drill's fixture.

    The mouse drill's tool centre is held on the segment between the two
    points (``constrain``), its shaft along the axis: the trainee chooses how
    far along the path, the axis chooses where. The haptic loop's guide
    (``vtkHapticForceModel::SetGuideAxis``) takes the same point and direction.
    """

    entry: tuple[float, float, float]
    target: tuple[float, float, float]

    @classmethod
    def from_points(cls, entry, target) -> GuideAxis:
        a, b = (np.asarray(p, dtype=float) for p in (entry, target))
        if a.shape != (3,) or b.shape != (3,) or not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
            raise ValueError(f"A guide axis needs two points of three finite numbers (RAS, mm): {entry!r}, {target!r}")
        if np.linalg.norm(b - a) < 1e-6:
            raise ValueError("The two points of the guide axis coincide: click the entry, then a target elsewhere")
        return cls(tuple(float(v) for v in a), tuple(float(v) for v in b))

    @property
    def length(self) -> float:
        return float(np.linalg.norm(np.subtract(self.target, self.entry)))

    @property
    def direction(self) -> np.ndarray:
        """Unit vector from the entry towards the target (into the bone)."""
        return np.subtract(self.target, self.entry) / self.length

    def constrain(self, centre) -> np.ndarray:
        """The point of the segment entry-target nearest to ``centre``."""
        offset = np.asarray(centre, dtype=float) - np.asarray(self.entry)
        along = min(max(float(np.dot(offset, self.direction)), 0.0), self.length)
        return np.asarray(self.entry) + along * self.direction

    def distance(self, point) -> float:
        """How far (mm) ``point`` lies from the segment."""
        return float(np.linalg.norm(np.asarray(point, dtype=float) - self.constrain(point)))


def new_secret() -> str:
    return SECRET_PREFIX + secrets.token_urlsafe(32)


def same_secret(given, expected: str) -> bool:
    """Whether ``given`` is ``expected``, in time that does not depend on how much of it matches."""
    if not isinstance(given, str) or not expected:
        return False
    return hmac.compare_digest(given.encode("utf-8"), expected.encode("utf-8"))


class CoSession:
    """Roles, control, consent, freeze and the instructor's marks of one trainee session (see the module)."""

    def __init__(self, trainee_secret: str, instructor_secret: str | None = None):
        if not isinstance(trainee_secret, str) or not trainee_secret:
            raise ValueError("The trainee's secret must be a non-empty string")
        self._trainee_secret = trainee_secret
        self.roles: dict[str, str] = {}  # joined pages: client id -> role, in joining order
        self.controller: str | None = None
        self.control_request: str | None = None  # the instructor page waiting for the trainee's consent
        self.frozen = False
        self.pointer: tuple[float, float, float] | None = None
        self.guide: GuideAxis | None = None
        self._instructor_secret = ""
        self.renew_instructor_link(instructor_secret)

    # ------------------------------------------------------------------ secrets and joining

    @property
    def instructor_secret(self) -> str:
        return self._instructor_secret

    def is_instructor_secret(self, token) -> bool:
        return same_secret(token, self._instructor_secret)

    def authenticate(self, token, client_id: str) -> str | None:
        """The role ``token`` proves (and the page joins with it), or None: the page may not connect."""
        # Both comparisons always run: how long this takes says nothing about which secret was close.
        trainee = same_secret(token, self._trainee_secret)
        instructor = same_secret(token, self._instructor_secret)
        role = TRAINEE if trainee else INSTRUCTOR if instructor else None
        if role is None:
            return None
        self.roles[client_id] = role
        if self.controller is None and role == TRAINEE:
            self.controller = client_id
        return role

    def renew_instructor_link(self, secret: str | None = None) -> list[str]:
        """A new instructor secret; returns the instructor pages that joined with the old one (they leave)."""
        secret = new_secret() if secret is None else secret
        if not isinstance(secret, str) or len(secret) < 16:
            raise ValueError("An instructor secret has at least 16 characters")
        if same_secret(secret, self._trainee_secret):
            raise ValueError("The instructor's secret must differ from the trainee's")
        self._instructor_secret = secret
        leaving = [client for client, role in self.roles.items() if role == INSTRUCTOR]
        for client in leaving:
            self.left(client)
        return leaving

    def left(self, client_id: str) -> None:
        """A page closed (or lost the session): control goes back to the first trainee page still here."""
        self.roles.pop(client_id, None)
        if self.control_request == client_id:
            self.control_request = None
        if self.controller == client_id:
            self.controller = next((c for c, r in self.roles.items() if r == TRAINEE), None)

    def role(self, client_id: str) -> str | None:
        return self.roles.get(client_id)

    @property
    def controller_role(self) -> str | None:
        return self.roles.get(self.controller) if self.controller else None

    @property
    def instructor_present(self) -> bool:
        return INSTRUCTOR in self.roles.values()

    # ------------------------------------------------------------------ permissions

    def check(self, client_id: str, action: str) -> None:
        """Raise ``CoSessionRefused`` unless the page may do ``action``: "drive" (views, drilling, panels),
        "observe" (be shown the session), an instructor action or a trainee action."""
        role = self.roles.get(client_id)
        if role is None:
            raise CoSessionRefused(NOT_JOINED)
        if action == "observe":
            return
        if action == "drive":
            if client_id == self.controller:
                return
            raise CoSessionRefused(WATCHING if role == INSTRUCTOR else OTHER_TAB)
        if action in INSTRUCTOR_ACTIONS:
            if role != INSTRUCTOR:
                raise CoSessionRefused(f"Only the instructor may {action.replace('_', ' ')}")
            return
        if action in TRAINEE_ACTIONS:
            if role != TRAINEE:
                raise CoSessionRefused(f"Only the trainee may {action.replace('_', ' ')}")
            return
        raise CoSessionRefused(f"Unknown action {action!r}")

    def may(self, client_id: str, action: str) -> bool:
        try:
            self.check(client_id, action)
        except CoSessionRefused:
            return False
        return True

    def check_stroke(self) -> None:
        """A stroke may begin: not while frozen, unless the instructor drills."""
        if self.frozen and self.controller_role != INSTRUCTOR:
            raise CoSessionRefused(FROZEN)

    # ------------------------------------------------------------------ control and consent

    def take_over(self, client_id: str) -> None:
        """A trainee page takes control (from another tab, or back from the instructor)."""
        self.check(client_id, "take_over")
        self.controller = client_id
        self.control_request = None

    def request_control(self, client_id: str) -> None:
        self.check(client_id, "request_control")
        if self.controller == client_id:
            return
        if not any(role == TRAINEE for role in self.roles.values()):
            raise CoSessionRefused("The trainee's page is not open: there is nobody to ask")
        self.control_request = client_id

    def answer_request(self, client_id: str, accept: bool) -> str | None:
        """The trainee's answer; returns the page that now controls when accepted."""
        self.check(client_id, "answer_request")
        requester, self.control_request = self.control_request, None
        if requester is None or requester not in self.roles:
            raise CoSessionRefused("No request for control is waiting (the instructor left or withdrew it)")
        if accept:
            self.controller = requester
            return requester
        return None

    def give_back(self, client_id: str) -> None:
        """The instructor hands control back to the trainee page that was steering first."""
        self.check(client_id, "give_back")
        if self.control_request == client_id:
            self.control_request = None
        if self.controller == client_id:
            self.controller = next((c for c, r in self.roles.items() if r == TRAINEE), None)

    # ------------------------------------------------------------------ instructor's marks

    def freeze(self, client_id: str, frozen: bool) -> None:
        self.check(client_id, "freeze")
        self.frozen = bool(frozen)

    def point(self, client_id: str, position) -> tuple[float, float, float]:
        self.check(client_id, "point")
        values = tuple(float(v) for v in position)
        if len(values) != 3 or not all(math.isfinite(v) for v in values):
            raise CoSessionRefused(f"A marker needs a point of three finite numbers (RAS, mm), not {position!r}")
        self.pointer = values
        return values

    def set_guide(self, client_id: str, entry, target) -> GuideAxis:
        self.check(client_id, "axis")
        try:
            self.guide = GuideAxis.from_points(entry, target)
        except ValueError as error:
            raise CoSessionRefused(str(error)) from error
        return self.guide

    def clear_marks(self, client_id: str) -> None:
        self.check(client_id, "clear_marks")
        self.pointer, self.guide = None, None
