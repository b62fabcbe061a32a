"""Forces forwarded from the command line: two real processes coupled over loopback (``jobs.couplejob``).

The trainee's side waits with a virtual device held still at its origin; the
instructor's side joins with a replayed hand held 3 mm away along +x. With
the coupling's spring (0.5 N/mm) and both proxies still, the trainee's device
must be pulled along +x by gain x 0.5 N/mm x 3 mm = 1.5 N once engaged, and
the instructor's along -x by the same; when the instructor's process ends,
the trainee's side says so, its force is gone 0.15 s after the last packet,
and it goes on until it is told to stop. Also: a bad address, an
unresolvable host and a trainee that never answers each end with a message
that says what to do.
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest
import slicer

from VolumeCuttingLib.collaboration import forcecoupling
from VolumeCuttingLib.jobs import couplejob

HOLD_MM = 3.0
STIFFNESS = 0.5
HOLD_S = 1.0


class Job:
    """A couplejob process whose output lines are read as they come."""

    def __init__(self, *args):
        self.lines: list[str] = []
        self.process = subprocess.Popen([sys.executable, "-m", "VolumeCuttingLib.jobs.couplejob", *args],
                                        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                                        env=dict(os.environ, PYTHONUNBUFFERED="1"))
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self):
        for line in self.process.stdout:
            self.lines.append(line.rstrip())

    def wait_for(self, pattern: str, timeout_s: float = 60.0) -> re.Match:
        deadline = time.monotonic() + timeout_s
        while time.monotonic() < deadline:
            for line in list(self.lines):
                found = re.search(pattern, line)
                if found:
                    return found
            if self.process.poll() is not None and not self._reader.is_alive():
                break
            time.sleep(0.02)
        raise AssertionError(f"no line matching {pattern!r} within {timeout_s} s; output:\n" + "\n".join(self.lines))

    def finish(self, timeout_s: float = 30.0) -> int:
        code = self.process.wait(timeout=timeout_s)
        self._reader.join(timeout=5.0)
        return code


def held_hand_recording(path, seconds: float) -> None:
    """A hand held still HOLD_MM along +x for ``seconds`` at 1 kHz."""
    recorder = slicer.vtkHapticRecorder()
    ticks = int(seconds * 1000)
    recorder.SetCapacity(ticks)
    recorder.SetRate(1000.0)
    recorder.GetCapabilities().DeepCopy(slicer.vtkVirtualHapticDevice().GetCapabilities())
    for _ in range(ticks):
        assert recorder.AppendInput([HOLD_MM, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0], 0, 0, True)
    assert recorder.WriteFile(str(path))


def test_the_trainees_device_feels_the_instructors_pull_and_goes_on_when_the_instructor_leaves(tmp_path):
    recording = tmp_path / "instructor_hand.vchr"
    held_hand_recording(recording, HOLD_S)
    port = str(forcecoupling.free_loopback_ports(1)[0])
    trainee = Job("--couple-listen", port, "--device", "virtual", "--summary", str(tmp_path / "trainee.json"))
    instructor = None
    try:
        # The instructor's replayed hand starts with its process: only once the trainee waits.
        trainee.wait_for(rf"waiting for the instructor on 127\.0\.0\.1:{port}")
        instructor = Job("--couple-to", f"127.0.0.1:{port}", "--device", "replay", "--replay", str(recording),
                         "--summary", str(tmp_path / "instructor.json"))
        trainee.wait_for(r"the instructor joined from 127\.0\.0\.1:\d+")
        assert instructor.finish() == 0, "\n".join(instructor.lines)  # its replay ended: the instructor leaves
        trainee.wait_for(r"the instructor is gone")
    finally:
        trainee.process.send_signal(signal.SIGINT)
        assert trainee.finish() == 0, "\n".join(trainee.lines)
        if instructor is not None and instructor.process.poll() is None:
            instructor.process.kill()
    felt = json.loads((tmp_path / "trainee.json").read_text())
    given = json.loads((tmp_path / "instructor.json").read_text())
    assert "the trainee joined from 127.0.0.1:" + port in given["events"][0]["event"]
    for summary, sign in ((felt, 1.0), (given, -1.0)):
        samples = np.array(summary["samples"])
        force, age, gain = samples[:, 1:4], samples[:, 4], samples[:, 5]
        engaged = (gain == 1.0) & (age >= 0.0) & (age < 0.05)
        assert engaged.sum() >= 20, f"{summary['role']}: too few engaged samples"
        # Both tools still: the spring alone, 0.5 N/mm x 3 mm, toward the peer.
        assert np.allclose(np.median(force[engaged], axis=0), [sign * STIFFNESS * HOLD_MM, 0.0, 0.0], atol=0.02)
        assert summary["largest_force_N"] <= summary["device_force_limit_N"]
    samples = np.array(felt["samples"])
    faded = samples[:, 4] > 0.16  # after the coupling's 50 ms timeout and 100 ms fade
    assert faded.sum() >= 5 and np.all(samples[faded, 1:4] == 0.0)
    assert [event["event"].split(" from")[0].split(" (")[0] for event in felt["events"]] == [
        "the instructor joined", "the instructor is gone"]


def test_an_instructor_whose_trainee_never_answers_is_told_what_to_do(tmp_path, capsys):
    port = forcecoupling.free_loopback_ports(1)[0]
    code = couplejob.main(["--couple-to", f"127.0.0.1:{port}", "--device", "virtual", "--couple-wait", "0.5",
                           "--summary", str(tmp_path / "alone.json")])
    assert code == 3
    error = capsys.readouterr().err
    assert f"no trainee answered at 127.0.0.1:{port} within 0.5 s" in error and f"--couple-listen {port}" in error
    assert "no trainee answered" in json.loads((tmp_path / "alone.json").read_text())["error"]


@pytest.mark.parametrize("arguments, message", [
    (["--couple-to", "trainee-machine"], "expected HOST:PORT"),
    (["--couple-to", "127.0.0.1:70000"], "expected HOST:PORT"),
    (["--couple-to", "no-such-host.invalid:47000"], "could not be found"),
    (["--couple-listen", "70000"], "give a port from 0"),
    (["--couple-listen", "47000", "--couple-host", "256.1.1.1"], "--couple-host"),
    (["--couple-listen", "47000", "--couple-stiffness", "0"], "--couple-stiffness"),
    (["--device", "virtual"], "say which side this is"),
    (["--couple-listen", "47000", "--segmentation", "anatomy.seg.nrrd"], "go with --ct"),
    (["--couple-listen", "47000", "--ct", "ct.nrrd", "--tool-at", "1,2"], "give R,A,S"),
    (["--couple-listen", "47000", "--ct", "ct.nrrd", "--device-scale", "0"], "--device-scale"),
])
def test_a_bad_address_or_setting_is_refused_with_a_message(arguments, message, capsys):
    with pytest.raises(SystemExit) as stopped:
        couplejob.main(arguments)
    assert stopped.value.code == 2
    assert message in capsys.readouterr().err


def test_a_port_in_use_is_reported_and_nothing_is_left_running(capsys):
    taken = forcecoupling.ForceCoupling(forcecoupling.CouplingSettings(local_port=0, peer_port=0))
    taken.attach(slicer.vtkHapticLoop())
    try:
        assert couplejob.main(["--couple-listen", str(taken.local_port), "--device", "virtual"]) == 3
    finally:
        taken.detach()
    assert "could not bind UDP 127.0.0.1:" in capsys.readouterr().err


def write_block_ct(path, bump: int = 0) -> None:
    """A 16-voxel cube of bone in air, as NRRD; ``bump`` changes one voxel (another scan)."""
    ct = np.full((16, 16, 16), -1000, np.int16)
    ct[4:12, 4:12, 4:12] = 1200
    ct[1, 1, 1] += bump
    header = ("NRRD0004\ntype: short\ndimension: 3\nspace: right-anterior-superior\nsizes: 16 16 16\n"
              "space directions: (0.5,0,0) (0,0.5,0) (0,0,0.5)\nkinds: domain domain domain\nendian: little\n"
              "encoding: raw\nspace origin: (-4,-4,-4)\n\n")
    path.write_bytes(header.encode() + ct.astype("<i2").tobytes())


def test_an_instructor_on_another_scan_is_refused_and_told_why(tmp_path, capsys):
    """The instructor's side loads a CT with one voxel changed: the trainee's packets are refused, it ends saying so."""
    write_block_ct(tmp_path / "trainee.nrrd")
    write_block_ct(tmp_path / "other.nrrd", bump=1)
    volume = slicer.vtkMRMLScalarVolumeNode()
    reader = slicer.vtkMRMLVolumeArchetypeStorageNode()
    reader.SetFileName(str(tmp_path / "trainee.nrrd"))
    assert reader.ReadData(volume)
    frame = forcecoupling.scan_fingerprint(volume)
    # The trainee's side: a free loop in the trainee's scan's frame, listening (its drilling is not what is tested).
    trainee = forcecoupling.ForceCoupling(forcecoupling.CouplingSettings(local_port=0, peer_port=0, frame_fingerprint=frame))
    device = slicer.vtkVirtualHapticDevice()
    assert device.Open()
    device.SetPose([0.0, 0.0, 0.0], 0)
    loop = slicer.vtkHapticLoop()
    loop.SetDevice(device)
    loop.SetForceModel(forcecoupling.air_force_model())
    trainee.attach(loop)
    assert loop.Start()
    try:
        code = couplejob.main(["--couple-to", f"127.0.0.1:{trainee.local_port}", "--device", "virtual",
                               "--ct", str(tmp_path / "other.nrrd"), "--couple-wait", "5",
                               "--summary", str(tmp_path / "instructor.json")])
    finally:
        loop.Stop()
        status = trainee.status()
        trainee.detach()
    assert code == 3
    error = capsys.readouterr().err
    assert f"the trainee loaded another scan (fingerprint {frame:016x})" in error and "Load the same CT" in error
    assert status["packets_accepted"] == 0 and status["frame_mismatches"] > 0
    assert "another scan" in json.loads((tmp_path / "instructor.json").read_text())["error"]
