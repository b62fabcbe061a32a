"""Grade a recorded drilling session: ``vc assess RECORDING [--reference RECORDING] [--out DIR]``.

Writes ``assessment.json`` (every metric, the score) and ``report.html`` (a
self-contained report with plots) into DIR and prints the score. A recording
that cannot be graded (corrupt, truncated, empty, made on another scan than
its reference) is refused with a message naming the file; nothing is written.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ..cutting import recording as recordings
from . import metrics, report, scans


def _tool(text: str):
    try:
        key, spec = text.split("=", 1)
        burr_type, diameter = spec.split(":", 1)
        return key, {"burr_type": burr_type, "radius_mm": float(diameter) / 2.0}
    except ValueError:
        raise metrics.AssessmentError(f"--tool {text!r}: write KEY=TYPE:DIAMETER, e.g. cutting=Cutting:5") from None


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="vc assess", description=__doc__.splitlines()[0])
    parser.add_argument("recording", type=Path)
    parser.add_argument("--reference", type=Path, help="a recording on the same scan to compare the final product with")
    parser.add_argument("--out", type=Path, default=Path("assessment"), help="where to write assessment.json and report.html")
    parser.add_argument("--scan", choices=("phantom", "headct"),
                        help="the scan, for recordings that do not name it (version 1); default: the one the recording names")
    parser.add_argument("--tool", action="append", default=[], metavar="KEY=TYPE:DIAMETER",
                        help="what a version 1 recording's tool key is, e.g. cutting=Cutting:5 (burr type, diameter in mm)")
    args = parser.parse_args(argv)
    try:
        session = recordings.load(args.recording)
        if args.tool and session["version"] >= 2:
            raise metrics.AssessmentError(f"{args.recording}: --tool is for version 1 recordings; this one records its tools")
        if args.tool:
            session = dict(session, tools=dict(_tool(text) for text in args.tool))
        reference = recordings.load(args.reference) if args.reference else None
        scan = scans.by_name(args.scan) if args.scan else None
        graded = metrics.assess(session, scan, reference, recording_path=args.recording, reference_path=args.reference)
    except (recordings.RecordingError, scans.ScanError, metrics.AssessmentError) as error:
        print(f"vc assess: {error}", file=sys.stderr)
        return 2
    paths = report.write(graded, args.out)
    print(f"score {graded.score:.1f} / 100: {paths['html']} and {paths['json']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
