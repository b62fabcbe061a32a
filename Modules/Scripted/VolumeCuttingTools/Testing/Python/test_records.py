"""Trainee records (VolumeCuttingLib.records) on SQLite and on a real PostgreSQL server.

Every test that touches a database runs on both: an SQLite file in the test's
folder, and a fresh database on the PostgreSQL server that the session-wide
``postgres_server`` fixture starts (Debian's server, temporary cluster,
loopback port). Assessments are made up here in the documented format.
"""

import hashlib
import json
import math
import multiprocessing
import socket
import traceback
from itertools import count

import pytest
from alembic.autogenerate import compare_metadata
from alembic.runtime.migration import MigrationContext
from sqlalchemy import inspect, text

from VolumeCuttingLib.records import __main__ as cli
from VolumeCuttingLib.records import database
from VolumeCuttingLib.records.assessment import AssessmentError
from VolumeCuttingLib.records.schema import Base

DATABASE_NUMBERS = count(1)


def sha(seed) -> str:
    return hashlib.sha256(str(seed).encode()).hexdigest()


def make_assessment(seed, started="2026-11-20T09:00:00Z", score=50.0, metrics=None, scan="headct", trainee=None):
    return {"format": "VolumeCuttingAssessment", "version": 1,
            "session": {"scan": scan, "recording": f"/data/sessions/{seed}.vcrec", "sha256": sha(seed),
                        "started": started, "duration_s": 600.0, "trainee": trainee},
            "score": score,
            "metrics": {"safety.contacts.FacialNerve": 1, "efficiency.path_length_mm": 800.0, "final.dice": 0.8}
            if metrics is None else metrics,
            "reference": None}


@pytest.fixture(params=["sqlite", "postgresql"])
def url(request, tmp_path):
    """An empty database: an SQLite file, or a new database on the session's PostgreSQL server."""
    if request.param == "sqlite":
        return f"sqlite:///{tmp_path / 'records.sqlite'}"
    server = request.getfixturevalue("postgres_server")
    return server.create_database(f"records_{next(DATABASE_NUMBERS)}")


def table_counts(url) -> dict:
    engine = database.create_records_engine(url)
    try:
        with engine.connect() as connection:
            names = [n for n in inspect(connection).get_table_names() if n != "alembic_version"]
            return {n: connection.execute(text(f"SELECT count(*) FROM {n}")).scalar() for n in names}
    finally:
        engine.dispose()


# ---------------------------------------------------------------- schema and migrations

def test_an_empty_database_is_created_at_the_newest_revision_with_exactly_the_models_tables(url):
    with database.open(url) as records:
        assert database.current_revision(records.engine) == database.head_revision() == "0002"
        with records.engine.connect() as connection:
            differences = compare_metadata(MigrationContext.configure(connection), Base.metadata)
        assert differences == [], f"migrations and schema.py disagree: {differences}"
        assert records.trainees() == []
    # Opening again migrates nothing and keeps the database as it is.
    with database.open(url) as records:
        assert database.current_revision(records.engine) == "0002"


def test_a_revision_1_database_is_upgraded_and_keeps_its_sessions(url):
    engine = database.create_records_engine(url)
    database.migrate(engine, "0001")
    with engine.begin() as connection:
        assert "program" not in {c["name"] for c in inspect(connection).get_columns("trainees")}
        connection.execute(text("INSERT INTO trainees (id, name) VALUES (1, 'Old Resident')"))
        connection.execute(text("INSERT INTO scans (id, name, content_sha256) VALUES (1, 'phantom', '')"))
        connection.execute(text(
            "INSERT INTO sessions (id, trainee_id, scan_id, started, duration_s, recording, recording_sha256, score, "
            "assessment_version, assessment, recorded) VALUES (1, 1, 1, :started, 300, '/old.vcrec', :sha, 42.5, 1, "
            "'{}', :started)"), {"started": "2025-01-02 03:04:05", "sha": sha("old")})
        connection.execute(text("INSERT INTO metrics (session_id, name, value) VALUES (1, 'final.dice', 0.5)"))
    engine.dispose()

    with database.open(url) as records:
        assert database.current_revision(records.engine) == "0002"
        with records.engine.connect() as connection:
            inspector = inspect(connection)
            assert {"program", "cohort"} <= {c["name"] for c in inspector.get_columns("trainees")}
            assert "ix_sessions_trainee_id_started" in {i["name"] for i in inspector.get_indexes("sessions")}
            assert "ix_metrics_name" in {i["name"] for i in inspector.get_indexes("metrics")}
        [old] = records.sessions("Old Resident")
        assert (old.scan, old.score, old.metrics, old.started.isoformat()) == \
            ("phantom", 42.5, {"final.dice": 0.5}, "2025-01-02T03:04:05+00:00")
        trainee = records.set_trainee("Old Resident", program="ENT Lyon", cohort="PGY-3")
        assert (trainee.program, trainee.cohort, trainee.sessions) == ("ENT Lyon", "PGY-3", 1)
        # The new session joins the old one on the same curve.
        records.add_assessment("Old Resident", make_assessment("new", score=61.0, metrics={"final.dice": 0.7}))
        assert [(p.number, p.values) for p in records.learning_curve("Old Resident", ["score", "final.dice"])] == \
            [(1, {"score": 42.5, "final.dice": 0.5}), (2, {"score": 61.0, "final.dice": 0.7})]


def test_a_database_newer_than_the_software_is_refused_untouched(url):
    database.open(url).close()
    engine = database.create_records_engine(url)
    with engine.begin() as connection:
        connection.execute(text("UPDATE alembic_version SET version_num = '0099'"))
    engine.dispose()
    with pytest.raises(database.RecordsError, match=r"revision 0099.*knows up to 0002.*update VolumeCutting"):
        database.open(url)
    engine = database.create_records_engine(url)
    with engine.connect() as connection:
        assert connection.execute(text("SELECT version_num FROM alembic_version")).scalar() == "0099"
    engine.dispose()


# ---------------------------------------------------------------- adding and reading

def test_adding_is_idempotent_on_the_recording(url):
    with database.open(url) as records:
        first = records.add_assessment("Ann", make_assessment("s1"))
        again = records.add_assessment("Ann", make_assessment("s1", score=99.0))
        assert first.created and not again.created
        assert again.id == first.id and again.score == 50.0  # the stored session, unchanged
        # The assessment's own trainee field, with no name given, finds the same session.
        assert not records.add_assessment(None, make_assessment("s1", trainee="Ann")).created
        with pytest.raises(database.RecordsError, match="already recorded for trainee 'Ann', not 'Bob'"):
            records.add_assessment("Bob", make_assessment("s1"))
        with pytest.raises(AssessmentError, match="belongs to trainee 'Ann', not 'Bob'"):
            records.add_assessment("Bob", make_assessment("s2", trainee="Ann"))
        with pytest.raises(AssessmentError, match="names no trainee"):
            records.add_assessment(None, make_assessment("s3"))
        assert [(t.name, t.sessions) for t in records.trainees()] == [("Ann", 1)]
        assert records.assessment(sha("s1"))["score"] == 50.0
    assert table_counts(url) == {"trainees": 1, "scans": 1, "sessions": 1, "metrics": 3}


def test_learning_curves_follow_time_not_the_order_of_adding(url):
    with database.open(url) as records:
        # Added out of order; times in several offsets (09:30+02:00 is 07:30 UTC, before 08:00Z).
        records.add_assessment("Ann", make_assessment("c", "2026-11-03T08:00:00Z", 70.0,
                                                      {"final.dice": 0.9, "safety.contacts.FacialNerve": 0}))
        records.add_assessment("Ann", make_assessment("a", "2026-11-01T10:00:00+00:00", 40.0,
                                                      {"final.dice": 0.6, "safety.contacts.FacialNerve": 3}))
        records.add_assessment("Ann", make_assessment("b", "2026-11-03T09:30:00+02:00", 55.0, {"final.dice": 0.75}))
        records.add_assessment("Ann", make_assessment("p", "2026-11-02T10:00:00Z", 20.0, {"final.dice": 0.1},
                                                      scan="phantom"))
        records.add_assessment("Bob", make_assessment("bob", "2026-11-02T11:00:00Z", 90.0))

        curve = records.learning_curve("Ann", ["score", "final.dice", "safety.contacts.FacialNerve", "duration_s"])
        assert [p.recording_sha256 for p in curve] == [sha("a"), sha("p"), sha("b"), sha("c")]
        assert [p.number for p in curve] == [1, 2, 3, 4]
        assert [p.started.isoformat() for p in curve] == ["2026-11-01T10:00:00+00:00", "2026-11-02T10:00:00+00:00",
                                                           "2026-11-03T07:30:00+00:00", "2026-11-03T08:00:00+00:00"]
        assert [p.values["score"] for p in curve] == [40.0, 20.0, 55.0, 70.0]
        assert [p.values["final.dice"] for p in curve] == [0.6, 0.1, 0.75, 0.9]
        # Session "b" measured no contacts: None, not zero.
        assert [p.values["safety.contacts.FacialNerve"] for p in curve] == [3.0, None, None, 0.0]
        assert {p.values["duration_s"] for p in curve} == {600.0}

        head_ct_only = records.learning_curve("Ann", ["score"], scan="headct")
        assert [(p.number, p.values["score"]) for p in head_ct_only] == [(1, 40.0), (2, 55.0), (3, 70.0)]
        assert records.metric_names("Ann") == ["final.dice", "safety.contacts.FacialNerve"]
        assert [s.score for s in records.sessions("Ann")] == [40.0, 20.0, 55.0, 70.0]
        assert [(t.name, t.sessions) for t in records.trainees()] == [("Ann", 4), ("Bob", 1)]
        with pytest.raises(database.UnknownTrainee, match="no trainee named 'Carol'"):
            records.learning_curve("Carol", ["score"])


def write_in_another_process(url, documents, barrier, results):
    """A writer process: wait for the other one, open the (empty) database, add every document."""
    try:
        barrier.wait(60)  # start together, so that both migrate the empty database and write at the same time
        with database.open(url) as records:
            results.put(sum(records.add_assessment("Shared", document).created for document in documents))
    except BaseException:
        results.put(traceback.format_exc())


def test_two_processes_writing_at_once_lose_nothing_and_store_each_recording_once(url):
    # Both open the database while it is still empty (both migrate), then add 12 sessions each, 6 of them the same.
    # Forked, not spawned: two real processes that need not import everything again (seconds on a busy machine).
    context = multiprocessing.get_context("fork")
    barrier, results = context.Barrier(2), context.Queue()
    common = [make_assessment(f"common{i}", f"2026-11-{i + 1:02d}T10:00:00Z", 10.0 * i) for i in range(6)]
    processes = []
    for writer in ("one", "two"):
        own = [make_assessment(f"{writer}{i}", f"2026-11-{i + 10:02d}T10:00:00Z", 50.0 + i) for i in range(6)]
        documents = common + own if writer == "one" else own + common[::-1]
        processes.append(context.Process(target=write_in_another_process, args=(url, documents, barrier, results)))
        processes[-1].start()
    created = [results.get(timeout=120) for _ in processes]
    for process in processes:
        process.join(30)
    assert all(isinstance(c, int) for c in created), "\n".join(c for c in created if isinstance(c, str))
    assert sum(created) == 18  # each of the 18 recordings created by exactly one writer
    with database.open(url) as records:
        sessions = records.sessions("Shared")
        assert len(sessions) == 18 and len({s.recording_sha256 for s in sessions}) == 18
    assert table_counts(url) == {"trainees": 1, "scans": 1, "sessions": 18, "metrics": 54}


# ---------------------------------------------------------------- bad input

BAD_DOCUMENTS = {
    "unknown format": (lambda d: d.update(format="SomethingElse"), "format is 'SomethingElse'"),
    "newer version": (lambda d: d.update(version=2), "version 2 .* not one this software reads"),
    "NaN score": (lambda d: d.update(score=math.nan), "score must be a finite number from 0 to 100, got nan"),
    "score over 100": (lambda d: d.update(score=120), "score must be .* got 120"),
    "missing sha256": (lambda d: d["session"].pop("sha256"), r"session\.sha256 is missing"),
    "missing metrics and start": (lambda d: (d.pop("metrics"), d["session"].pop("started")),
                                  r"session\.started is missing; metrics is missing"),
    "infinite metric": (lambda d: d["metrics"].update({"final.dice": math.inf}), "metric final.dice must be a finite"),
    "true as a metric": (lambda d: d["metrics"].update({"safety.burr": True}), "metric safety.burr must be a finite"),
    "bad time": (lambda d: d["session"].update(started="yesterday"), "ISO 8601 time, got 'yesterday'"),
    "NaN in the reference": (lambda d: d.update(reference={"dice": math.nan}), "cannot be stored as JSON: Out of range"),
    "not an object": (lambda d: d.clear() or d.update(format="VolumeCuttingAssessment", version=1, session=[]),
                      "session must be an object"),
}


@pytest.mark.parametrize("problem", list(BAD_DOCUMENTS))
def test_a_bad_assessment_is_refused_with_its_problem_named_and_nothing_written(problem, tmp_path):
    change, message = BAD_DOCUMENTS[problem]
    document = make_assessment("bad")
    change(document)
    url = f"sqlite:///{tmp_path / 'records.sqlite'}"
    with database.open(url) as records:
        records.add_assessment("Ann", make_assessment("good"))
        with pytest.raises(AssessmentError, match=message):
            records.add_assessment("Ann", document, source="bad.json")
    assert table_counts(url) == {"trainees": 1, "scans": 1, "sessions": 1, "metrics": 3}


def test_bad_input_writes_nothing_on_postgresql_either(postgres_server):
    url = postgres_server.create_database(f"records_{next(DATABASE_NUMBERS)}")
    with database.open(url) as records:
        with pytest.raises(AssessmentError, match="score must be a finite number"):
            records.add_assessment("Ann", make_assessment("nan", score=math.nan))
    assert table_counts(url) == {"trainees": 0, "scans": 0, "sessions": 0, "metrics": 0}


def closed_loopback_port() -> int:
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]  # closed again when the block ends: nothing listens there


def test_an_unreachable_database_is_a_clear_error_and_the_assessment_file_is_kept(tmp_path, capsys):
    url = f"postgresql+psycopg://trainer:secret@127.0.0.1:{closed_loopback_port()}/records"
    with pytest.raises(database.RecordsError, match=r"cannot open the records database postgresql\+psycopg://"
                                                    r"trainer:\*\*\*@127\.0\.0\.1:\d+/records: .*(refused|failed)"):
        database.open(url, connect_timeout_s=2)
    with pytest.raises(database.RecordsError, match="cannot create the folder /proc/no-such"):
        database.open("/proc/no-such/records.sqlite")
    with pytest.raises(database.RecordsError, match="not a database URL"):
        database.open("postgresql+psycopg://host:notaport/db")
    with pytest.raises(database.RecordsError, match="SQLite or PostgreSQL, not mysql"):
        database.open("mysql://host/db")

    assessment = tmp_path / "session.assessment.json"
    assessment.write_text(json.dumps(make_assessment("kept")))
    before = assessment.read_bytes()
    assert cli.main(["--database", url, "add", "Ann", str(assessment)]) == 2
    error = capsys.readouterr().err
    assert error.startswith("vc records: cannot open the records database") and "secret" not in error
    assert assessment.read_bytes() == before


# ---------------------------------------------------------------- command line and defaults

def test_the_command_line_adds_lists_and_shows(tmp_path, capsys):
    url = str(tmp_path / "cli.sqlite")  # a plain path works as well as a URL
    files = []
    for i, score in enumerate((35.0, 62.5)):
        path = tmp_path / f"s{i}.json"
        path.write_text(json.dumps(make_assessment(f"cli{i}", f"2026-11-0{i + 1}T10:00:00Z", score)))
        files.append(path)
    assert cli.main(["--database", url, "add", "Ann Resident", str(files[0]), "--program", "ENT", "--cohort", "PGY-2"]) == 0
    assert cli.main(["--database", url, "add", "Ann Resident", str(files[1])]) == 0
    assert cli.main(["--database", url, "add", "Ann Resident", str(files[1])]) == 0
    out = capsys.readouterr().out.splitlines()
    assert out[0].startswith("added Ann Resident's session of 2026-11-01 10:00 UTC on headct, score 35.0 (3 metrics)")
    assert out[2].startswith("already recorded, unchanged: Ann Resident's session of 2026-11-02 10:00 UTC")

    assert cli.main(["--database", url, "list"]) == 0
    listing = capsys.readouterr().out.splitlines()
    assert listing[0].split() == ["trainee", "program", "cohort", "sessions", "last", "session"]
    assert listing[1].split() == ["Ann", "Resident", "ENT", "PGY-2", "2", "2026-11-02", "10:00", "UTC"]

    assert cli.main(["--database", url, "show", "Ann Resident", "--metric", "final.dice"]) == 0
    shown = capsys.readouterr().out.splitlines()
    assert shown[0] == "Ann Resident: 2 sessions"
    assert [line.split()[-2:] for line in shown[2:]] == [["35.0", "0.8"], ["62.5", "0.8"]]

    assert cli.main(["--database", url, "show", "Ann Resident", "--json"]) == 0
    sessions = json.loads(capsys.readouterr().out)
    assert [s["score"] for s in sessions] == [35.0, 62.5] and sessions[1]["metrics"]["final.dice"] == 0.8

    broken = tmp_path / "broken.json"
    broken.write_text('{"format": "VolumeCuttingAssessment", "version": 1, "sess')
    assert cli.main(["--database", url, "add", "Ann Resident", str(broken)]) == 2
    assert f"{broken} is not JSON" in capsys.readouterr().err
    assert cli.main(["--database", url, "add", "Ann Resident", str(tmp_path / "missing.json")]) == 2
    assert "missing.json: No such file" in capsys.readouterr().err
    assert cli.main(["--database", url, "show", "Nobody"]) == 2
    assert "no trainee named 'Nobody'" in capsys.readouterr().err


def test_the_default_database_is_a_file_in_the_users_data_folder(tmp_path, monkeypatch):
    monkeypatch.delenv(database.ENVIRONMENT_VARIABLE, raising=False)
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "share"))
    assert database.default_database_url() == f"sqlite:///{tmp_path / 'share' / 'volumecutting' / 'records.sqlite'}"
    with database.open() as records:
        records.add_assessment("Ann", make_assessment("default"))
    assert (tmp_path / "share" / "volumecutting" / "records.sqlite").is_file()
    monkeypatch.setenv(database.ENVIRONMENT_VARIABLE, "postgresql+psycopg://program-server/records")
    assert database.default_database_url() == "postgresql+psycopg://program-server/records"


def test_a_session_that_cannot_reach_the_database_is_kept_and_added_later(tmp_path, capsys):
    from VolumeCuttingLib.records import pending

    unreachable = f"postgresql+psycopg://trainer:secret@127.0.0.1:{closed_loopback_port()}/records"
    folder = tmp_path / "pending"
    stored, message = pending.store_or_keep(unreachable, "Ann", make_assessment("offline", score=64.0), folder)
    assert stored is None
    kept = folder / f"{sha('offline')}.json"
    assert message.startswith("cannot open the records database") and str(kept) in message and "secret" not in message
    assert json.loads(kept.read_text())["assessment"]["score"] == 64.0
    with pytest.raises(AssessmentError, match="score must be"):  # a bad assessment is refused, not kept
        pending.store_or_keep(unreachable, "Ann", make_assessment("bad", score=math.nan), folder)
    assert sorted(p.name for p in folder.iterdir()) == [kept.name]
    (folder / "garbled.json").write_text("{not json")

    # The database is back: sync adds what was kept and leaves what it cannot read, saying why.
    url = f"sqlite:///{tmp_path / 'records.sqlite'}"
    assert cli.main(["--database", url, "sync", "--pending", str(folder)]) == 2
    out, err = capsys.readouterr()
    assert out.startswith("1 kept sessions added to sqlite:///") and "garbled.json" in out
    assert "1 kept sessions could not be added" in err
    assert not kept.exists() and (folder / "garbled.json").exists()
    with database.open(url) as records:
        assert [(s.trainee, s.score) for s in records.sessions("Ann")] == [("Ann", 64.0)]
        # Reachable now: store_or_keep stores, and a second time changes nothing.
        stored, message = pending.store_or_keep(url, "Ann", make_assessment("offline", score=64.0), folder)
        assert not stored.created and message.startswith("stored in the trainee records")
