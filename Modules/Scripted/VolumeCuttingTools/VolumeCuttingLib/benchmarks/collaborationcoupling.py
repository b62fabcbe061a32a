"""Part of the benchmark area ``collaboration``: forces forwarded between two haptic loops, stable and cheap.

Two haptic loops (1 kHz, virtual devices limited to 3.3 N) coupled over UDP
on 127.0.0.1 by ``vtkHapticCoupling`` (spring 0.5 N/mm, damper 0.002 N s/mm,
energy tanks of 2 mJ), ticked in lockstep with simulated hands
(``collaboration.forcecoupling.rehearse``: an instructor's arm following a
figure and a 12 mm step over 4 s, a relaxed trainee's hand), for each
one-way delay of 0, 5 and 20 ms and loss of 0 and 10 % (seeded). Per case:
the largest device force against the limit, the energy bound's margin (the
tanks' initial energy less the most net energy the coupling ever gave the
two handles: negative would mean an active coupling), the trainee's tracking
RMS over the smooth part (0.5-2 s), and what one coupling update costs
(wall time, us, p50 / p99 / max, both ends, median over repeats). The
baseline is the whole haptic tick's p50 in the same run (coupling, 82-point
contact test in air, device exchange): the ratio is the coupling's share.
"""

from __future__ import annotations

import statistics

from ..collaboration import forcecoupling
from .harness import machine_description, measurement

DELAYS_S = (0.0, 0.005, 0.020)
LOSSES = (0.0, 0.1)


def coupling_measurements(repeats: int) -> list[dict]:
    machine = machine_description()
    results = []
    for delay in DELAYS_S:
        for loss in LOSSES:
            runs = [forcecoupling.rehearse(delay, loss, seconds=4.0, seed=1 + run) for run in range(repeats)]
            label = f"delay {1000.0 * delay:.0f} ms, loss {100.0 * loss:.0f} %"
            cost = {key: statistics.median(run["coupling_update_us"][key] for run in runs) for key in ("p50", "p99", "max")}
            tick = statistics.median(run["tick_p50_us"] for run in runs)
            result = measurement(f"coupling update p50 ({label})", cost["p50"], "us",
                                 "whole haptic tick p50, coupling included", tick, repeats, machine)
            result.update({
                "delay_ms": 1000.0 * delay,
                "loss_percent": 100.0 * loss,
                "device_force_limit_N": runs[0]["device_force_limit_N"],
                "max_force_N": max(run["max_force_N"] for run in runs),
                "clamped_forces": sum(run["clamped_forces"] for run in runs),
                "energy_bound_margin_mJ": min(run["energy_bound_margin_mJ"] for run in runs),
                "max_separation_mm": max(run["max_separation_mm"] for run in runs),
                "tracking_rms_mm": statistics.median(run["tracking_rms_mm"] for run in runs),
                "coupling_update_us": cost,
            })
            results.append(result)
    return results
