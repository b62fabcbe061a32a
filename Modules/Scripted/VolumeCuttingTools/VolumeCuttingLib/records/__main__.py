"""The trainee records from the command line (``Utilities/vc records``).

    python -m VolumeCuttingLib.records [--database URL] list
    python -m VolumeCuttingLib.records [--database URL] show TRAINEE [--metric NAME ...] [--json]
    python -m VolumeCuttingLib.records [--database URL] add TRAINEE ASSESSMENT.json [--program P] [--cohort C]
    python -m VolumeCuttingLib.records [--database URL] sync [--pending FOLDER]

``--database`` takes a SQLAlchemy URL (``postgresql+psycopg://user:password@host/db``,
``sqlite:////path/records.sqlite``) or a file path; the default is
``$VOLUMECUTTING_RECORDS`` or ``records.sqlite`` in the user's data folder.
A refused assessment or an unreachable database ends with exit status 2 and
a message on stderr; the assessment file is only read, never changed, so it
can be added again. ``sync`` adds the sessions kept while the database
could not be reached (see ``pending``).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

from . import database, pending
from .assessment import AssessmentError


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="vc records", description="Trainee records: assessed drilling sessions.")
    parser.add_argument("--database", default=None,
                        help="SQLAlchemy URL or SQLite file (default: $VOLUMECUTTING_RECORDS or "
                             "~/.local/share/volumecutting/records.sqlite)")
    commands = parser.add_subparsers(dest="command", required=True)
    commands.add_parser("list", help="every trainee with their number of sessions")
    show = commands.add_parser("show", help="a trainee's sessions in time order")
    show.add_argument("trainee")
    show.add_argument("--metric", action="append", default=[], help="a metric to list beside the score (repeatable)")
    show.add_argument("--json", action="store_true", help="print the sessions and all their metrics as JSON")
    add = commands.add_parser("add", help="store an assessment (idempotent: a recording is stored once)")
    add.add_argument("trainee")
    add.add_argument("assessment", type=Path, help="the assessment JSON that Utilities/vc assess wrote")
    add.add_argument("--program", default=None, help="the trainee's residency program")
    add.add_argument("--cohort", default=None, help="the trainee's cohort (year group)")
    sync = commands.add_parser("sync", help="add the sessions kept while the database could not be reached")
    sync.add_argument("--pending", type=Path, default=None,
                      help="folder of kept sessions (default: ~/.local/share/volumecutting/pending)")
    return parser


def _time(moment) -> str:
    return moment.strftime("%Y-%m-%d %H:%M UTC") if moment else "-"


def _table(rows: list[list[str]]) -> str:
    widths = [max(len(row[i]) for row in rows) for i in range(len(rows[0]))]
    return "\n".join("  ".join(cell.ljust(width) for cell, width in zip(row, widths)).rstrip() for row in rows)


def _number(value) -> str:
    return "-" if value is None else f"{value:.4g}"


def _list(records, _args, out) -> None:
    trainees = records.trainees()
    if not trainees:
        print(f"no trainees in {records}", file=out)
        return
    rows = [["trainee", "program", "cohort", "sessions", "last session"]]
    rows += [[t.name, t.program or "-", t.cohort or "-", str(t.sessions), _time(t.last_started)] for t in trainees]
    print(_table(rows), file=out)


def _show(records, args, out) -> None:
    sessions = records.sessions(args.trainee)
    if args.json:
        json.dump([{"number": i + 1, "started": s.started.isoformat(), "scan": s.scan, "duration_s": s.duration_s,
                    "recording": s.recording, "sha256": s.recording_sha256, "score": s.score, "metrics": s.metrics}
                   for i, s in enumerate(sessions)], out, indent=1)
        print(file=out)
        return
    rows = [["#", "started", "scan", "minutes", "score", *args.metric]]
    rows += [[str(i + 1), _time(s.started), s.scan, f"{s.duration_s / 60:.1f}", f"{s.score:.1f}",
              *(_number(s.metrics.get(name)) for name in args.metric)] for i, s in enumerate(sessions)]
    print(f"{args.trainee}: {len(sessions)} sessions", file=out)
    print(_table(rows), file=out)


def _add(records, args, out) -> None:
    try:
        document = json.loads(args.assessment.read_text(encoding="utf-8"))
    except OSError as error:
        raise AssessmentError(f"cannot read {args.assessment}: {error.strerror or error}") from None
    except (UnicodeDecodeError, json.JSONDecodeError) as error:
        raise AssessmentError(f"{args.assessment} is not JSON: {error}") from None
    if args.program is not None or args.cohort is not None:
        records.set_trainee(args.trainee, args.program, args.cohort)
    stored = records.add_assessment(args.trainee, document, source=str(args.assessment))
    verb = "added" if stored.created else "already recorded, unchanged:"
    print(f"{verb} {stored.trainee}'s session of {_time(stored.started)} on {stored.scan}, score {stored.score:.1f} "
          f"({len(stored.metrics)} metrics) in {records}", file=out)


def _sync(records, args, out) -> None:
    stored, left = pending.sync(records, args.pending)
    print(f"{len(stored)} kept sessions added to {records}" + (f", {len(left)} left:" if left else ""), file=out)
    for path, reason in left:
        print(f"  {path}: {reason}", file=out)
    if left:
        raise database.RecordsError(f"{len(left)} kept sessions could not be added; they stay where they are")


def main(argv=None, out=None) -> int:
    args = _parser().parse_args(argv)
    out = out or sys.stdout
    try:
        with database.open(args.database) as records:
            {"list": _list, "show": _show, "add": _add, "sync": _sync}[args.command](records, args, out)
    except (database.RecordsError, AssessmentError) as error:
        print(f"vc records: {error}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
