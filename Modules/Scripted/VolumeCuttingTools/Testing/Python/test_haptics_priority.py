"""The haptic loop's real-time priority as the jobs and the benchmark ask for it and report it."""

import os

from VolumeCuttingLib.benchmarks.haptics import _busy
from VolumeCuttingLib.jobs import hapticsjob


def test_idle_loop_reports_the_priority_it_ran_at():
    # Asked for: granted (SCHED_FIFO at the loop's level) or refused with the system's reason, never silent.
    asked = hapticsjob.idle_loop(seconds=0.2)
    assert asked["ticks_run"] > 0
    status = asked["real_time_priority_status"]
    if asked["real_time_priority"]:
        assert status == "SCHED_FIFO priority 80"
    else:
        assert status.startswith(("refused", "not available")) and status.endswith("normal priority")
    # Turned off: normal priority, and the status says it was not asked for.
    off = hapticsjob.idle_loop(seconds=0.2, real_time_priority=False)
    assert off["ticks_run"] > 0 and not off["real_time_priority"]
    assert off["real_time_priority_status"].startswith("not requested")


def _busy_children() -> set:
    """This process's children that run ``yes``."""
    children = set()
    for entry in os.listdir("/proc"):
        try:
            with open(f"/proc/{entry}/stat") as stat:
                fields = stat.read().rsplit(")", 1)[1].split()
            with open(f"/proc/{entry}/comm") as comm:
                name = comm.read().strip()
        except (OSError, IndexError):
            continue
        # After the command's closing parenthesis: state, then the parent's id.
        if int(fields[1]) == os.getpid() and name == "yes" and fields[0] != "Z":
            children.add(entry)
    return children


def test_busy_processes_end_with_the_block():
    with _busy(2):
        assert len(_busy_children()) == 2
    assert not _busy_children()
