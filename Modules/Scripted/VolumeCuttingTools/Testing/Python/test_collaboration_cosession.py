"""The co-session's rules without a browser: secrets, roles, control with consent, freeze, the guide axis."""

import numpy as np
import pytest

from VolumeCuttingLib.collaboration import cosession
from VolumeCuttingLib.collaboration.cosession import INSTRUCTOR, TRAINEE, CoSession, CoSessionRefused, GuideAxis

TRAINEE_KEY = "wslink-secret"


def joined():
    session = CoSession(TRAINEE_KEY)
    assert session.authenticate(TRAINEE_KEY, "t1") == TRAINEE
    assert session.authenticate(session.instructor_secret, "i1") == INSTRUCTOR
    return session


def test_each_session_has_its_own_instructor_secret_distinct_from_the_trainees():
    first, second = CoSession(TRAINEE_KEY), CoSession(TRAINEE_KEY)
    assert first.instructor_secret != second.instructor_secret
    assert first.instructor_secret != TRAINEE_KEY and len(first.instructor_secret) >= 40
    with pytest.raises(ValueError, match="differ"):
        CoSession("same-secret-of-twenty", "same-secret-of-twenty")
    with pytest.raises(ValueError):
        CoSession("")


@pytest.mark.parametrize("token", ["", "wslink", "wslink-secret ", "WSLINK-SECRET", None, 42, b"wslink-secret",
                                   {"secret": "wslink-secret"}, ["wslink-secret"]])
def test_wrong_or_malformed_tokens_join_nothing(token):
    session = CoSession(TRAINEE_KEY)
    assert session.authenticate(token, "x") is None
    assert session.authenticate(session.instructor_secret[:-1], "y") is None
    assert session.roles == {} and session.controller is None
    with pytest.raises(CoSessionRefused, match="not part of the session"):
        session.check("x", "drive")


def test_secrets_are_compared_in_constant_time(monkeypatch):
    calls = []
    real = cosession.hmac.compare_digest
    monkeypatch.setattr(cosession.hmac, "compare_digest", lambda a, b: calls.append((a, b)) or real(a, b))
    session = CoSession(TRAINEE_KEY)
    calls.clear()
    session.authenticate("guess", "x")
    # Both secrets are compared, whichever matches: the time says nothing about which one was near.
    assert len(calls) == 2
    calls.clear()
    assert session.is_instructor_secret(session.instructor_secret)
    assert len(calls) == 1


def test_renewing_the_link_makes_the_old_one_stale_and_drops_its_pages():
    session = joined()
    old = session.instructor_secret
    session.request_control("i1")
    assert session.renew_instructor_link() == ["i1"]
    assert session.instructor_secret != old
    assert session.authenticate(old, "i2") is None
    assert session.role("i1") is None and session.control_request is None
    with pytest.raises(CoSessionRefused):
        session.check("i1", "point")


def test_observer_may_watch_but_not_drive_and_trainee_may_not_use_instructor_powers():
    session = joined()
    assert session.controller == "t1"
    session.check("i1", "observe")
    with pytest.raises(CoSessionRefused, match="You are watching"):
        session.check("i1", "drive")
    for action in cosession.INSTRUCTOR_ACTIONS:
        session.check("i1", action)
        with pytest.raises(CoSessionRefused, match="Only the instructor"):
            session.check("t1", action)
    for action in cosession.TRAINEE_ACTIONS:
        with pytest.raises(CoSessionRefused, match="Only the trainee"):
            session.check("i1", action)
    with pytest.raises(CoSessionRefused, match="Unknown action"):
        session.check("t1", "format_disk")
    # A second trainee tab is told to take over, as before.
    session.authenticate(TRAINEE_KEY, "t2")
    with pytest.raises(CoSessionRefused, match="another tab"):
        session.check("t2", "drive")


def test_control_passes_only_with_the_trainees_consent_and_comes_back():
    session = joined()
    with pytest.raises(CoSessionRefused, match="No request"):
        session.answer_request("t1", True)
    session.request_control("i1")
    assert session.controller == "t1" and session.control_request == "i1"
    with pytest.raises(CoSessionRefused):
        session.answer_request("i1", True)  # the instructor cannot consent for the trainee
    assert session.answer_request("t1", False) is None
    assert session.controller == "t1"
    session.request_control("i1")
    assert session.answer_request("t1", True) == "i1"
    assert session.controller == "i1" and session.controller_role == INSTRUCTOR
    session.check("i1", "drive")
    with pytest.raises(CoSessionRefused):
        session.check("t1", "drive")
    session.take_over("t1")  # the trainee takes it back whenever they like
    assert session.controller == "t1"
    session.request_control("i1")
    session.answer_request("t1", True)
    session.give_back("i1")
    assert session.controller == "t1"
    # The instructor leaving in control gives it back too.
    session.request_control("i1")
    session.answer_request("t1", True)
    session.left("i1")
    assert session.controller == "t1" and not session.instructor_present


def test_freeze_refuses_strokes_unless_the_instructor_drills():
    session = joined()
    session.check_stroke()
    session.freeze("i1", True)
    with pytest.raises(CoSessionRefused, match="frozen"):
        session.check_stroke()
    with pytest.raises(CoSessionRefused):
        session.freeze("t1", False)
    session.request_control("i1")
    session.answer_request("t1", True)
    session.check_stroke()
    session.freeze("i1", False)
    session.take_over("t1")
    session.check_stroke()


def test_marks_are_checked_points():
    session = joined()
    assert session.point("i1", [1, 2, 3]) == (1.0, 2.0, 3.0)
    with pytest.raises(CoSessionRefused, match="three finite"):
        session.point("i1", [1, float("nan"), 3])
    with pytest.raises(CoSessionRefused, match="coincide"):
        session.set_guide("i1", (0, 0, 0), (0, 0, 0))
    axis = session.set_guide("i1", (0, 0, 10), (0, 0, 0))
    assert axis.length == 10.0 and np.allclose(axis.direction, (0, 0, -1))
    session.clear_marks("i1")
    assert session.pointer is None and session.guide is None


def test_guide_axis_holds_the_tool_on_the_segment():
    axis = GuideAxis.from_points((1.0, 2.0, 3.0), (1.0, 2.0 + 6.0, 3.0 + 8.0))  # 10 mm along (0, 0.6, 0.8)
    # A point 5 mm along and 4 mm off the axis (perpendicular (1, 0, 0)) comes back onto it, 5 mm along.
    off = np.array((1.0, 2.0, 3.0)) + 5.0 * np.array((0.0, 0.6, 0.8)) + 4.0 * np.array((1.0, 0.0, 0.0))
    assert np.allclose(axis.constrain(off), (1.0, 5.0, 7.0))
    assert axis.distance(off) == pytest.approx(4.0)
    # Beyond the target or before the entry: held at the ends (the plan's depth is not exceeded).
    assert np.allclose(axis.constrain((1.0, 20.0, 30.0)), axis.target)
    assert np.allclose(axis.constrain((1.0, -20.0, -30.0)), axis.entry)
    with pytest.raises(ValueError):
        GuideAxis.from_points((0, 0), (1, 1, 1))
