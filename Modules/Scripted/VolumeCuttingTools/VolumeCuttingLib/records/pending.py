"""Sessions the records could not take yet: kept as files until the database is reachable, so nothing is lost.

A session ends, its assessment is stored with :func:`store_or_keep`; when
the database cannot be reached (the program's server is down, the network
is away) the assessment is written to the pending folder
(``~/.local/share/volumecutting/pending/<recording sha256>.json``) and the
caller gets a message saying where. :func:`sync` (``Utilities/vc records
sync``) adds what is pending once the database answers; adding is idempotent,
so a file added twice is still one session. An assessment the records refuse
(a bad document) is not kept: it would never be stored, and the caller is
told at once.
"""

from __future__ import annotations

import json
import os
import tempfile
from datetime import datetime, timezone
from pathlib import Path

from . import database
from .assessment import AssessmentError, check


def pending_folder() -> Path:
    return database.data_folder() / "pending"


def keep(trainee: str | None, assessment: dict, reason: str, folder: Path | None = None) -> Path:
    """Write ``assessment`` (already checked) to the pending folder, atomically; its path."""
    folder = Path(folder) if folder else pending_folder()
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / f"{check(assessment).recording_sha256}.json"
    record = {"trainee": trainee, "assessment": assessment, "reason": reason,
              "kept": datetime.now(timezone.utc).isoformat(timespec="seconds")}
    # A temporary file renamed into place: a crash leaves either the old file or the new one, never half.
    handle, temporary = tempfile.mkstemp(dir=folder, suffix=".part")
    with os.fdopen(handle, "w", encoding="utf-8") as stream:
        json.dump(record, stream, indent=1, allow_nan=False)
        stream.flush()
        os.fsync(stream.fileno())
    os.replace(temporary, path)
    return path


def store_or_keep(url: str | None, trainee: str | None, assessment: dict, folder: Path | None = None):
    """Add ``assessment`` to the records at ``url``, or keep it pending: (the stored session or None, a message).

    A refused assessment raises ``AssessmentError`` (it is not kept).
    """
    check(assessment)
    try:
        with database.open(url) as records:
            stored = records.add_assessment(trainee, assessment)
        return stored, f"stored in the trainee records ({records})"
    except database.RecordsError as error:
        path = keep(trainee, assessment, str(error), folder)
        return None, (f"{error}. The session is kept in {path}; `Utilities/vc records sync` adds it to the records "
                      "once the database can be reached")


def sync(records: database.RecordStore, folder: Path | None = None):
    """Add every pending assessment to ``records``: (sessions stored, [(file, why it stays)]).

    A file is removed once its session is in the records; one the records
    refuse stays where it is, with the reason.
    """
    folder = Path(folder) if folder else pending_folder()
    stored, left = [], []
    for path in sorted(folder.glob("*.json")) if folder.is_dir() else []:
        try:
            record = json.loads(path.read_text(encoding="utf-8"))
            stored.append(records.add_assessment(record.get("trainee"), record["assessment"], source=str(path)))
        except (OSError, ValueError, KeyError, TypeError, AssessmentError, database.RecordsError) as error:
            left.append((path, str(error)))
            continue
        path.unlink()
    return stored, left
