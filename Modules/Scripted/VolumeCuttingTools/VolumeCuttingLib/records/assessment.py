"""What the records accept: a ``VolumeCuttingAssessment`` document, checked before anything is written.

The assessment (``Utilities/vc assess``) is a JSON object::

    {"format": "VolumeCuttingAssessment", "version": 1,
     "session": {"scan": str, "recording": str, "sha256": str, "started": ISO time,
                 "duration_s": float, "trainee": str or null, "scan_sha256": str (optional)},
     "score": float 0-100,
     "metrics": {"safety.contacts.FacialNerve": 0, "efficiency.path_length_mm": 812.4, ...},
     "reference": {...} or null}

A document that is not exactly this is refused with every problem named, so
that nothing half-valid reaches the database and the caller still holds the
file it tried to store.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from datetime import datetime, timezone

FORMAT = "VolumeCuttingAssessment"
#: The versions of the format this code reads.
SUPPORTED_VERSIONS = (1,)
SHA256 = re.compile(r"^[0-9a-f]{64}$")
#: Longest names the schema stores (trainee, scan, metric) and recording path.
MAX_NAME_LENGTH = 200
MAX_PATH_LENGTH = 1000


class AssessmentError(ValueError):
    """An assessment the records refuse; the message lists every problem found."""


@dataclass(frozen=True)
class CheckedAssessment:
    """An assessment that passed :func:`check`, with its values in the types the database stores."""

    trainee: str | None
    scan: str
    scan_sha256: str
    recording: str
    recording_sha256: str
    started: datetime  # naive UTC, as both SQLite and PostgreSQL store it the same way
    duration_s: float
    score: float
    metrics: dict
    reference_sha256: str | None
    version: int


def _finite_number(value) -> bool:
    # bool is an int in Python, but True is no measurement.
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


def _utc_naive(text: str) -> datetime:
    moment = datetime.fromisoformat(text.replace("Z", "+00:00"))
    if moment.tzinfo is not None:
        moment = moment.astimezone(timezone.utc).replace(tzinfo=None)
    return moment  # a time without offset is taken as UTC (what the recorder writes)


def _name(value, what: str, problems: list) -> str | None:
    if not isinstance(value, str) or not value.strip():
        problems.append(f"{what} must be a non-empty text, got {value!r}")
        return None
    if len(value.strip()) > MAX_NAME_LENGTH:
        problems.append(f"{what} is longer than {MAX_NAME_LENGTH} characters")
        return None
    return value.strip()


def check(document, source: str = "the assessment") -> CheckedAssessment:
    """``document`` as a :class:`CheckedAssessment`, or :class:`AssessmentError` naming ``source`` and every problem."""
    if not isinstance(document, dict):
        raise AssessmentError(f"{source}: expected a JSON object, got {type(document).__name__}")
    if document.get("format") != FORMAT:
        raise AssessmentError(f"{source}: format is {document.get('format')!r}, expected {FORMAT!r}")
    version = document.get("version")
    if version not in SUPPORTED_VERSIONS or isinstance(version, bool):
        raise AssessmentError(f"{source}: version {version!r} of {FORMAT} is not one this software reads "
                              f"({', '.join(map(str, SUPPORTED_VERSIONS))}); update VolumeCutting")
    problems: list[str] = []
    session = document.get("session")
    if not isinstance(session, dict):
        problems.append(f"session must be an object, got {session!r}")
        session = {}
    for key in ("scan", "recording", "sha256", "started", "duration_s"):
        if key not in session:
            problems.append(f"session.{key} is missing")
    for key in ("score", "metrics"):
        if key not in document:
            problems.append(f"{key} is missing")

    scan = _name(session.get("scan"), "session.scan", problems) if "scan" in session else None
    recording = session.get("recording")
    if "recording" in session and (not isinstance(recording, str) or not recording or len(recording) > MAX_PATH_LENGTH):
        problems.append(f"session.recording must be a path of 1 to {MAX_PATH_LENGTH} characters, got {recording!r}")
    sha256 = session.get("sha256")
    if "sha256" in session and not (isinstance(sha256, str) and SHA256.match(sha256.lower())):
        problems.append(f"session.sha256 must be 64 hexadecimal digits, got {sha256!r}")
    scan_sha256 = session.get("scan_sha256") or ""
    if scan_sha256 and not (isinstance(scan_sha256, str) and SHA256.match(scan_sha256.lower())):
        problems.append(f"session.scan_sha256 must be 64 hexadecimal digits, got {scan_sha256!r}")
    started = None
    if "started" in session:
        try:
            started = _utc_naive(session["started"])
        except (TypeError, ValueError, AttributeError):
            problems.append(f"session.started must be an ISO 8601 time, got {session['started']!r}")
    duration = session.get("duration_s")
    if "duration_s" in session and not (_finite_number(duration) and duration >= 0):
        problems.append(f"session.duration_s must be a finite number of seconds >= 0, got {duration!r}")
    trainee = session.get("trainee")
    if trainee is not None:
        trainee = _name(trainee, "session.trainee", problems)

    score = document.get("score")
    if "score" in document and not (_finite_number(score) and 0 <= score <= 100):
        problems.append(f"score must be a finite number from 0 to 100, got {score!r}")
    metrics = document.get("metrics")
    checked_metrics = {}
    if "metrics" in document and not isinstance(metrics, dict):
        problems.append(f"metrics must be an object of name: number, got {type(metrics).__name__}")
    elif isinstance(metrics, dict):
        for name, value in metrics.items():
            if not isinstance(name, str) or not name or len(name) > MAX_NAME_LENGTH:
                problems.append(f"metric name {name!r} must have 1 to {MAX_NAME_LENGTH} characters")
            elif not _finite_number(value):
                problems.append(f"metric {name} must be a finite number, got {value!r}")
            else:
                checked_metrics[name] = float(value)
    reference = document.get("reference")
    reference_sha256 = None
    if reference is not None:
        if not isinstance(reference, dict):
            problems.append(f"reference must be an object or null, got {reference!r}")
        else:
            candidate = reference.get("sha256") or (reference.get("session") or {}).get("sha256")
            if isinstance(candidate, str) and SHA256.match(candidate.lower()):
                reference_sha256 = candidate.lower()
    if problems:
        raise AssessmentError(f"{source} is not a valid {FORMAT}: " + "; ".join(problems))
    return CheckedAssessment(trainee=trainee, scan=scan, scan_sha256=scan_sha256.lower(), recording=recording,
                             recording_sha256=sha256.lower(), started=started, duration_s=float(duration),
                             score=float(score), metrics=checked_metrics, reference_sha256=reference_sha256,
                             version=version)
