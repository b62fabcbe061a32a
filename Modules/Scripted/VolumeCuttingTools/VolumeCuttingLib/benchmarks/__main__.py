"""Benchmarks: one JSON file of measurements per product area.

    python -m VolumeCuttingLib.benchmarks [--area AREA ...] [--out benchmarks/results] [--repeat N]

An area is a module of this package with a function ``(repeats) -> list of
measurements`` (see ``harness``); ``AREAS`` names it. Areas are imported only
when they run, so that one area's dependencies (a GPU, Chromium) do not stop
the others.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from pathlib import Path

from .harness import write_results

# Area name: (module of this package, its function that measures the area).
AREAS = {
    "foundation": ("foundation", "foundation"),
    "cutfield": ("cutfield", "cutfield"),
    "feedback": ("feedback", "feedback"),
    "mapper": ("mapper", "mapper"),
    "gpuprogram": ("gpuprogram", "gpuprogram"),
    "workflow": ("workflow", "workflow"),
    "haptics": ("haptics", "haptics"),
    "hapticsmachine": ("hapticsmachine", "hapticsmachine"),
    "interactive": ("interactive", "interactive"),
    "sliceview": ("sliceview", "sliceview"),
    "softcut": ("softcut", "softcut_area"),
    "webapp": ("webapp", "webapp"),
    "records": ("records", "records"),
    "assessment": ("assessment", "assessment"),
    "collaboration": ("collaboration", "collaboration"),
}


def run_area(area: str, repeats: int) -> list[dict]:
    module_name, function_name = AREAS[area]
    module = importlib.import_module(f"{__package__}.{module_name}")
    return getattr(module, function_name)(repeats)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog=f"python -m {__package__}", description=__doc__.splitlines()[0])
    parser.add_argument("--area", action="append", choices=sorted(AREAS), help="area to run (default: all)")
    parser.add_argument("--out", type=Path, default=Path("benchmarks") / "results")
    parser.add_argument("--repeat", type=int, default=3, help="runs per measurement; the median is reported")
    args = parser.parse_args(argv)
    if args.repeat < 1:
        parser.error("--repeat must be at least 1")
    args.out.mkdir(parents=True, exist_ok=True)
    for area in args.area or sorted(AREAS):
        results = run_area(area, args.repeat)
        path = write_results(results, args.out / f"{area}.json")
        print(f"{path}:")
        for result in results:
            print(f"  {result['value']:.4f} {result['unit']} vs {result['baseline_value']:.4f} "
                  f"(ratio {result['ratio']}): {result['name']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
