"""The desktop's nerve-monitor meter and drill sound (VolumeCuttingLib.feedback.desktopfeedback and
soundsource), headless against a real scene, with the audio output's no-device path and a stand-in stream.

The scene (``data.boneplate``): a plate of bone (cuttable) whose labelled
voxels end at x = 4.75 mm, and a nerve canal (protected) along z at x = 2,
y = 4.5 mm, radius ~1 mm, in the bone beside the burr's path. A 4 mm burr (radius 2) drills along +x at
y = z = 0 with its shaft behind it: the bone ahead of its tip is the plate's
far side, 4.75 - x - 2 mm away; the nerve is to its side, farther than the
wall is thin (the stand-in the sound used before, the distance to the nearest
protected structure, reads 0.5-1 mm more there).
"""

from __future__ import annotations


import numpy as np
import pytest

from VolumeCuttingLib.config import toolconfig
from VolumeCuttingLib.data import boneplate
from VolumeCuttingLib.feedback import desktopfeedback, drillsound, nervemonitor, soundanalysis, soundsource
from VolumeCuttingLib.scene.application import HeadlessSlicer

BURR_RADIUS = 2.0
HALF_VOXEL = 0.5 * boneplate.SPACING
FAR_FACE_X = boneplate.FAR_FACE_X
pose_along_x = boneplate.drilling_pose


@pytest.fixture(scope="module")
def scene():
    application = HeadlessSlicer()
    burr = toolconfig.from_preset(next(p for p in toolconfig.load_presets() if p.name == "Cutting burr 4 mm"))
    tool = toolconfig.create_tool_node(application.scene, burr, name="burr")
    cut = boneplate.plate_with_nerve(application, tool)
    assert nervemonitor.monitor_for(application.volume_cutting_logic, cut) is not None  # waits for the nerve's field
    return application, application.volume_cutting_logic, cut, tool


def test_the_sound_hears_the_wall_ahead_thin_not_the_nearest_structure(scene):
    application, logic, cut, tool = scene
    source = soundsource.DrillSoundSource(logic)
    source.stroke_began(0.0, time_s=0.0)
    assert logic.BeginStroke(cut)
    checked = 0
    for step, x in enumerate(np.arange(-8.0, 2.01, 0.25)):
        assert logic.MoveActiveTool(cut, pose_along_x(x), logic.ToolCut)
        source.note_removed(source.removed_bone_mm3(cut), time_s=0.02 * (step + 1))
        parameters = source.parameters(cut, tool)
        # Load is bone removed: the burr sweeping air (the plate's near face is at x = -5.25, its voxels' partial
        # volume half a voxel either side) is not on bone.
        tip = x + BURR_RADIUS
        if abs(tip + 5.25) > HALF_VOXEL:
            assert parameters.contact == (tip > -5.25), x
        if tip > -4.0:
            assert parameters.load > 0.5, x
        wall = FAR_FACE_X - x - BURR_RADIUS
        if wall < 4.0 - HALF_VOXEL:
            assert parameters.thickness_mm == pytest.approx(wall, abs=HALF_VOXEL), x
            checked += 1
        level, rate = nervemonitor.sound_input(logic.GetNerveMonitor(cut))
        assert (parameters.monitor_level, parameters.monitor_rate_hz) == (level, rate)
        assert parameters.drill_on and parameters.rpm == tool.GetSpeed() * tool.GetPower()
    assert logic.EndStroke(cut)
    assert checked >= 10
    # At x = 1.75 the wall is 1 mm; the nerve beside the path is farther: the old stand-in would not hear the wall.
    assert logic.MoveActiveTool(cut, pose_along_x(1.75), logic.ToolMove)
    assert nervemonitor.nearest_mm(logic.GetNerveMonitor(cut)) > source.bone_ahead_mm(cut) + 0.4
    parameters = source.parameters(cut, tool)
    assert parameters.contact and 0.0 < parameters.load <= 1.0
    assert drillsound.thinning_factor(parameters.thickness_mm, source.config) > 1.1  # the pitch rises
    source.stroke_ended()
    assert not source.parameters(cut, tool).drill_on
    assert source.parameters(None, None) == drillsound.SoundParameters()


class StandInStream:
    """Stands in for sounddevice.OutputStream (these machines have no device): pulls blocks on request."""

    def __init__(self, **kwargs):
        self.callback = kwargs["callback"]
        self.latency = 0.01

    def start(self):
        pass

    def stop(self):
        pass

    def close(self):
        pass

    def pull(self, frames):
        out = np.zeros((frames, 1), dtype=np.float32)
        self.callback(out, frames, None, None)
        return out[:, 0]


def test_without_an_audio_device_the_meter_runs_and_the_session_goes_on_silent(scene):
    pytest.importorskip("sounddevice", exc_type=ImportError)  # PortAudio present, as setup installs it
    application, logic, cut, tool = scene
    feedback = desktopfeedback.DesktopFeedback(logic)
    assert feedback.start(cut) is False and not feedback.playing
    assert "goes on without sound" in feedback.message
    assert logic.MoveActiveTool(cut, pose_along_x(-1.0), logic.ToolMove)
    rows = feedback.tick(drill_on=True, now_s=0.0)
    reading = nervemonitor.readings(logic.GetNerveMonitor(cut))["Nerve"]
    assert rows == nervemonitor.meter_rows({"Nerve": reading}) and feedback.rows_changed
    (row,) = rows
    assert row["colour"] == nervemonitor.LEVEL_COLOURS[row["level"]]
    assert row["bar"] == pytest.approx(min(reading["distance_mm"], 8.0) / 8.0, abs=1e-3)
    # The silent output still gets every tick's parameters.
    assert feedback.output._latest == feedback.parameters and feedback.parameters.drill_on
    feedback.tick(drill_on=True, now_s=0.016)
    assert not feedback.rows_changed  # the same pose: nothing to redraw
    assert not feedback.set_sound(False) and feedback.message == "Drill sound off."
    feedback.stop()
    assert feedback.rows == [] and feedback.cut_node is None


def test_the_controller_ticks_at_50_hz_or_more_and_the_stream_plays_its_parameters(scene, monkeypatch):
    import sys
    import types

    assert desktopfeedback.TICK_PERIOD_S <= 1.0 / 50.0
    application, logic, cut, tool = scene
    streams = []
    monkeypatch.setitem(sys.modules, "sounddevice",
                        types.SimpleNamespace(OutputStream=lambda **kwargs: streams.append(StandInStream(**kwargs)) or streams[-1]))
    feedback = desktopfeedback.DesktopFeedback(logic)
    assert feedback.start(cut) and feedback.playing and "playing" in feedback.message
    feedback.set_volume(0.5)
    with pytest.raises(drillsound.SoundParameterError, match="volume"):
        feedback.set_volume(1.5)
    # The burr on the plate's far wall, 1 mm thick: the stream's pitch is the drill's, raised by the thin wall.
    assert logic.MoveActiveTool(cut, pose_along_x(FAR_FACE_X - BURR_RADIUS - 1.0), logic.ToolMove)
    times = np.arange(0.0, 0.5, desktopfeedback.TICK_PERIOD_S)
    for now in times:
        feedback.tick(drill_on=True, now_s=float(now))
    parameters = feedback.parameters
    assert parameters.volume == 0.5 and parameters.drill_on
    assert parameters.thickness_mm == pytest.approx(1.0, abs=HALF_VOXEL)
    stream = streams[-1]
    # The motor spins up from standstill (95 % in 0.45 s): the last half second of 1.5 s is steady.
    samples = np.concatenate([stream.pull(drillsound.MAX_BLOCK) for _ in range(int(1.5 * drillsound.SAMPLE_RATE) // drillsound.MAX_BLOCK)])
    steady = samples[-drillsound.SAMPLE_RATE // 2:]
    # Without contact (nothing removed at this pose) the motor's idle partials sound, at the raised pitch.
    expected = drillsound.expected_fundamental(parameters, feedback.source.config)
    assert expected > parameters.rpm / 60.0 * 1.1
    assert soundanalysis.fundamental(steady, expected) == pytest.approx(expected, rel=0.02)
    feedback.stop()
    assert not feedback.playing
