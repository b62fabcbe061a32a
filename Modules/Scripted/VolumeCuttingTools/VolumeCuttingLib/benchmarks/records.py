"""Benchmark area ``records``: storing an assessed session and reading a learning curve, SQLite and PostgreSQL.

What a trainee waits for after a session is the session being stored: one
``add_assessment`` of an assessment with 60 metrics (one transaction: the
trainee and scan looked up, the session and its metric rows written,
committed to disk). Baseline: writing the same assessment as a JSON file and
syncing it to disk, what keeping the session without a database costs. The
learning curve (score and two metrics over 100 sessions, one query) is
compared with reading the same values from 100 JSON files. SQLite is a file
in a temporary folder; PostgreSQL is Debian's server 15 on a temporary
cluster on the loopback interface (``records.localserver``, fsync off as in
the tests: the figure is the database's work, not the disk's).
"""

from __future__ import annotations

import hashlib
import json
import os
import tempfile
from itertools import count
from pathlib import Path

from ..records import database, localserver
from .harness import machine_description, measurement, timed

METRICS = 60
CURVE_SESSIONS = 100
CURVE_NAMES = ("score", "final.dice", "safety.contacts.FacialNerve")


def _assessment(number: int) -> dict:
    metrics = {f"safety.metric_{i:02d}": float(i * number % 97) for i in range(METRICS - 2)}
    metrics.update({"final.dice": 0.5 + number % 50 / 100, "safety.contacts.FacialNerve": float(number % 4)})
    return {"format": "VolumeCuttingAssessment", "version": 1,
            "session": {"scan": "headct", "recording": f"/sessions/{number}.vcrec",
                        "sha256": hashlib.sha256(str(number).encode()).hexdigest(),
                        "started": f"2026-{1 + number // 28 % 12:02d}-{1 + number % 28:02d}T10:00:00Z",
                        "duration_s": 600.0, "trainee": None},
            "score": float(number % 100), "metrics": metrics, "reference": None}


def _write_json(folder: Path, document: dict) -> None:
    path = folder / f"{document['session']['sha256']}.json"
    with open(path, "w") as stream:
        json.dump(document, stream)
        stream.flush()
        os.fsync(stream.fileno())


def _read_curve_from_json(folder: Path) -> list:
    documents = [json.loads(path.read_text()) for path in folder.glob("*.json")]
    documents.sort(key=lambda d: d["session"]["started"])
    return [[d["score"], *(d["metrics"].get(name) for name in CURVE_NAMES[1:])] for d in documents]


def _measure(label: str, url: str, folder: Path, repeats: int, machine: dict) -> list[dict]:
    numbers = count(1)
    json_folder = folder / f"{label}-json"
    json_folder.mkdir()
    results = []
    with database.open(url) as records:
        records.add_assessment("Warm-up", _assessment(next(numbers)))
        store, _ = timed(lambda: records.add_assessment("Benchmark", _assessment(next(numbers))), max(repeats, 20))
        write, _ = timed(lambda: _write_json(json_folder, _assessment(next(numbers))), max(repeats, 20))
        results.append(measurement(f"store one assessed session ({METRICS} metrics), {label}", store * 1000, "ms",
                                   "write its assessment JSON to a file and fsync", write * 1000, max(repeats, 20),
                                   machine))
        curve_folder = folder / f"{label}-curve"
        curve_folder.mkdir()
        for _ in range(CURVE_SESSIONS):
            document = _assessment(next(numbers))
            records.add_assessment("Curve", document)
            (curve_folder / f"{document['session']['sha256']}.json").write_text(json.dumps(document))
        curve, points = timed(lambda: records.learning_curve("Curve", CURVE_NAMES), max(repeats, 10))
        files, rows = timed(lambda: _read_curve_from_json(curve_folder), max(repeats, 10))
        if len(points) != CURVE_SESSIONS or len(rows) != CURVE_SESSIONS:
            raise RuntimeError(f"learning curve of {len(points)} points, {len(rows)} from files, not {CURVE_SESSIONS}")
        results.append(measurement(f"learning curve of {len(CURVE_NAMES)} values over {CURVE_SESSIONS} sessions, "
                                   f"{label}", curve * 1000, "ms", f"read the same values from {CURVE_SESSIONS} JSON files",
                                   files * 1000, max(repeats, 10), machine))
    return results


def records(repeats: int) -> list[dict]:
    machine = machine_description()
    with tempfile.TemporaryDirectory(prefix="volumecutting-records-bench-") as folder:
        folder = Path(folder)
        results = _measure("SQLite file", f"sqlite:///{folder / 'records.sqlite'}", folder, repeats, machine)
        with localserver.TemporaryPostgres() as server:
            results += _measure("PostgreSQL 15 on loopback", server.create_database("records_bench"), folder, repeats,
                                machine)
    return results
