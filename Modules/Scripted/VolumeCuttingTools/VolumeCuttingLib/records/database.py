"""Open the trainee records, migrate them, add assessments and read a trainee's progress.

``open(url)`` connects (an SQLite file by default, PostgreSQL through
``postgresql+psycopg://``), brings the schema to the newest revision of
``migrations/versions`` and returns a :class:`RecordStore`. Adding is
idempotent on the recording's SHA-256 and safe with several writers (each add
is one transaction, retried when another writer created the same trainee,
scan or session meanwhile). Every failure is a :class:`RecordsError` or an
``AssessmentError`` that says what and where, raised before anything is
written: a refused or unreachable database leaves the caller's assessment
untouched, to be added again later.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from datetime import datetime, timezone
from pathlib import Path

from alembic import command
from alembic.config import Config
from alembic.runtime.migration import MigrationContext
from alembic.script import ScriptDirectory
from alembic.util.exc import CommandError
from sqlalchemy import and_, create_engine, event, func, select
from sqlalchemy.engine import Engine, make_url
from sqlalchemy.exc import ArgumentError, DBAPIError, IntegrityError, NoSuchModuleError, OperationalError
from sqlalchemy.orm import Session as OrmSession
from sqlalchemy.orm import selectinload

from . import assessment as assessment_format
from .assessment import AssessmentError
from .schema import Metric, Scan, Session, Trainee

MIGRATIONS = Path(__file__).with_name("migrations")
#: Key of the PostgreSQL advisory lock that serialises migrations of one database.
MIGRATION_LOCK = 0x56435245  # "VCRE"
#: Columns of ``sessions`` that a learning curve may ask for beside the metrics.
SESSION_VALUES = ("score", "duration_s")
#: How often an add is retried when other writers keep creating the same rows.
ADD_ATTEMPTS = 5
ENVIRONMENT_VARIABLE = "VOLUMECUTTING_RECORDS"


class RecordsError(RuntimeError):
    """The records database cannot do what was asked: unreachable, newer than this software, or a conflict."""


class UnknownTrainee(RecordsError, LookupError):
    """No trainee of that name in the records."""


@dataclass(frozen=True)
class TraineeRecord:
    name: str
    program: str | None
    cohort: str | None
    sessions: int
    last_started: datetime | None


@dataclass(frozen=True)
class SessionRecord:
    id: int
    trainee: str
    scan: str
    started: datetime  # UTC
    duration_s: float
    recording: str
    recording_sha256: str
    score: float
    metrics: dict = field(default_factory=dict)
    #: False where the recording was already stored and this add changed nothing.
    created: bool = True


@dataclass(frozen=True)
class CurvePoint:
    """One session on a learning curve: its number in the trainee's history and the values asked for (None: not measured)."""

    number: int
    started: datetime  # UTC
    recording_sha256: str
    values: dict


def data_folder() -> Path:
    """Where the user's VolumeCutting data lives (XDG: ``~/.local/share/volumecutting``)."""
    base = os.environ.get("XDG_DATA_HOME") or str(Path.home() / ".local" / "share")
    return Path(base) / "volumecutting"


def default_database_url() -> str:
    """``$VOLUMECUTTING_RECORDS`` (a URL or a file path) if set, else the SQLite file ``records.sqlite`` in :func:`data_folder`."""
    configured = os.environ.get(ENVIRONMENT_VARIABLE)
    return as_url(configured) if configured else f"sqlite:///{data_folder() / 'records.sqlite'}"


def as_url(text: str) -> str:
    """A SQLAlchemy URL as given, or an SQLite URL for a file path."""
    text = str(text)
    return text if "://" in text else f"sqlite:///{Path(text).expanduser().resolve()}"


def _utc(moment: datetime | None) -> datetime | None:
    return None if moment is None else moment.replace(tzinfo=timezone.utc)


def _migration_config() -> Config:
    config = Config()
    config.set_main_option("script_location", str(MIGRATIONS))
    return config


def head_revision() -> str:
    """The newest schema revision this software knows."""
    return ScriptDirectory.from_config(_migration_config()).get_current_head()


def current_revision(engine: Engine) -> str | None:
    """The revision the database is at (None: empty)."""
    with engine.connect() as connection:
        return MigrationContext.configure(connection).get_current_revision()


def migrate(engine: Engine, revision: str = "head") -> None:
    """Bring the database to ``revision`` (an empty one is created), in one transaction that other openers wait for."""
    config = _migration_config()
    script = ScriptDirectory.from_config(config)
    with engine.begin() as connection:
        if connection.dialect.name == "postgresql":
            # Two processes opening one new database: the second waits here, then finds it migrated.
            connection.exec_driver_sql(f"SELECT pg_advisory_xact_lock({MIGRATION_LOCK})")
        current = MigrationContext.configure(connection).get_current_revision()
        if current is not None:
            try:
                script.get_revision(current)
            except CommandError:
                raise RecordsError(f"the records database {_shown(engine)} is at schema revision {current}, which this "
                                   f"software does not know (it knows up to {script.get_current_head()}): "
                                   "update VolumeCutting to use it") from None
        config.attributes["connection"] = connection
        command.upgrade(config, revision)


def _shown(engine: Engine) -> str:
    return engine.url.render_as_string(hide_password=True)


def _sqlite_engine(url) -> Engine:
    database = url.database
    if database and database != ":memory:" and not database.startswith("file:"):
        folder = Path(database).expanduser().resolve().parent
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as error:
            raise RecordsError(f"cannot create the folder {folder} for the records database: {error}") from None
    # Writers wait for each other up to 30 s instead of failing at once.
    engine = create_engine(url, connect_args={"timeout": 30.0})

    @event.listens_for(engine, "connect")
    def _connect(dbapi_connection, _record):
        # Python's sqlite3 would open transactions lazily (BEGIN DEFERRED at the first write): a reader that then
        # writes can deadlock with another writer. Let SQLAlchemy's "begin" event say BEGIN IMMEDIATE instead.
        dbapi_connection.isolation_level = None
        dbapi_connection.execute("PRAGMA foreign_keys = ON")

    @event.listens_for(engine, "begin")
    def _begin(connection):
        connection.exec_driver_sql("BEGIN IMMEDIATE")

    return engine


def create_records_engine(url: str, connect_timeout_s: float = 10.0) -> Engine:
    """An engine for ``url``: SQLite or PostgreSQL (psycopg 3), refused with a reason for anything else."""
    try:
        parsed = make_url(url)
    except (ArgumentError, ValueError) as error:  # ValueError: a port that is no number
        raise RecordsError(f"{url!r} is not a database URL ({error}); give e.g. sqlite:////path/records.sqlite or "
                           "postgresql+psycopg://user@host/database") from None
    backend = parsed.get_backend_name()
    if backend == "sqlite":
        return _sqlite_engine(parsed)
    if backend == "postgresql":
        if parsed.drivername == "postgresql":
            parsed = parsed.set(drivername="postgresql+psycopg")  # the driver this product ships
        try:
            return create_engine(parsed, connect_args={"connect_timeout": max(1, int(round(connect_timeout_s)))},
                                 pool_pre_ping=True)
        except NoSuchModuleError as error:
            raise RecordsError(f"{parsed.render_as_string(hide_password=True)}: {error}; use postgresql+psycopg://") from None
    raise RecordsError(f"{parsed.render_as_string(hide_password=True)}: the records use SQLite or PostgreSQL, not {backend}")


class RecordStore:
    """The trainee records in one database (see the module's docstring); use :func:`open`."""

    def __init__(self, url: str | None = None, connect_timeout_s: float = 10.0):
        self.url = as_url(url) if url else default_database_url()
        self.engine = create_records_engine(self.url, connect_timeout_s)
        try:
            migrate(self.engine)
        except (OperationalError, DBAPIError) as error:
            self.engine.dispose()
            raise RecordsError(f"cannot open the records database {self}: {_reason(error)}") from None
        except BaseException:
            self.engine.dispose()
            raise

    def __str__(self) -> str:
        return _shown(self.engine)

    def __enter__(self) -> RecordStore:
        return self

    def __exit__(self, *_) -> None:
        self.close()

    def close(self) -> None:
        self.engine.dispose()

    # ------------------------------------------------------------------ writing

    def add_assessment(self, trainee: str | None, assessment, source: str = "the assessment") -> SessionRecord:
        """Store ``assessment`` (a ``VolumeCuttingAssessment`` dict) as a session of ``trainee``; idempotent.

        ``trainee`` None takes the assessment's ``session.trainee``; if both are
        given they must agree. A recording already stored for the same trainee
        returns its session unchanged (``created`` False); for another trainee
        it is refused.
        """
        checked = assessment_format.check(assessment, source)
        given = trainee.strip() if isinstance(trainee, str) and trainee.strip() else None
        if given and checked.trainee and given != checked.trainee:
            raise AssessmentError(f"{source} belongs to trainee {checked.trainee!r}, not {given!r}")
        name = given or checked.trainee
        if name is None:
            raise AssessmentError(f"{source} names no trainee (session.trainee is null): say whose session it is")
        if len(name) > assessment_format.MAX_NAME_LENGTH:
            raise AssessmentError(f"trainee name longer than {assessment_format.MAX_NAME_LENGTH} characters")
        try:
            document = json.dumps(assessment, sort_keys=True, allow_nan=False)
        except (TypeError, ValueError) as error:  # NaN or an object JSON cannot hold, in a part not checked field by field
            raise AssessmentError(f"{source} cannot be stored as JSON: {error}") from None
        for _attempt in range(ADD_ATTEMPTS):
            try:
                with OrmSession(self.engine, expire_on_commit=False) as db, db.begin():
                    existing = db.scalar(select(Session).options(selectinload(Session.metrics))
                                         .where(Session.recording_sha256 == checked.recording_sha256))
                    if existing is not None:
                        if existing.trainee.name != name:
                            raise RecordsError(f"the recording {checked.recording_sha256[:12]}... ({checked.recording}) is "
                                               f"already recorded for trainee {existing.trainee.name!r}, not {name!r}")
                        return _session_record(existing, created=False)
                    row = Session(trainee=self._trainee_row(db, name), scan=self._scan_row(db, checked),
                                  started=checked.started, duration_s=checked.duration_s, recording=checked.recording,
                                  recording_sha256=checked.recording_sha256, score=checked.score,
                                  reference_sha256=checked.reference_sha256, assessment_version=checked.version,
                                  assessment=document, recorded=datetime.now(timezone.utc).replace(tzinfo=None),
                                  metrics=[Metric(name=k, value=v) for k, v in checked.metrics.items()])
                    db.add(row)
                    db.flush()
                    return _session_record(row, created=True)
            except IntegrityError:
                continue  # another writer created this trainee, scan or session meanwhile: read it next time
            except (OperationalError, DBAPIError) as error:
                raise RecordsError(f"could not store the session in {self}: {_reason(error)}; "
                                   "nothing was written, add it again later") from None
        raise RecordsError(f"could not store the session in {self}: {ADD_ATTEMPTS} attempts conflicted with other writers")

    def set_trainee(self, name: str, program: str | None = None, cohort: str | None = None) -> TraineeRecord:
        """Create the trainee ``name`` or update its program and cohort (None leaves a value as it is)."""
        for _attempt in range(ADD_ATTEMPTS):
            try:
                with OrmSession(self.engine) as db, db.begin():
                    row = self._trainee_row(db, name.strip())
                    row.program = program if program is not None else row.program
                    row.cohort = cohort if cohort is not None else row.cohort
                break
            except IntegrityError:
                continue
            except (OperationalError, DBAPIError) as error:
                raise RecordsError(f"could not store trainee {name!r} in {self}: {_reason(error)}") from None
        else:
            raise RecordsError(f"could not store trainee {name!r} in {self}: {ADD_ATTEMPTS} attempts conflicted "
                               "with other writers")
        return next(t for t in self.trainees() if t.name == name.strip())

    @staticmethod
    def _trainee_row(db, name: str) -> Trainee:
        row = db.scalar(select(Trainee).where(Trainee.name == name))
        if row is None:
            row = Trainee(name=name)
            db.add(row)
            db.flush()  # a concurrent creator makes this raise IntegrityError: the add is retried
        return row

    @staticmethod
    def _scan_row(db, checked) -> Scan:
        row = db.scalar(select(Scan).where(Scan.name == checked.scan, Scan.content_sha256 == checked.scan_sha256))
        if row is None:
            row = Scan(name=checked.scan, content_sha256=checked.scan_sha256)
            db.add(row)
            db.flush()
        return row

    # ------------------------------------------------------------------ reading

    def _read(self, query):
        try:
            with OrmSession(self.engine) as db:
                return query(db)
        except (OperationalError, DBAPIError) as error:
            raise RecordsError(f"could not read the records in {self}: {_reason(error)}") from None

    def trainees(self) -> list[TraineeRecord]:
        """Every trainee, by name, with their number of sessions and the time of the last one."""
        def query(db):
            rows = db.execute(select(Trainee, func.count(Session.id), func.max(Session.started))
                              .outerjoin(Session).group_by(Trainee.id).order_by(Trainee.name))
            return [TraineeRecord(t.name, t.program, t.cohort, count, _utc(last)) for t, count, last in rows]
        return self._read(query)

    def _trainee_id(self, db, name: str) -> int:
        trainee_id = db.scalar(select(Trainee.id).where(Trainee.name == name))
        if trainee_id is None:
            raise UnknownTrainee(f"no trainee named {name!r} in {self}")
        return trainee_id

    def sessions(self, trainee: str) -> list[SessionRecord]:
        """The sessions of ``trainee`` in time order, with their metrics."""
        def query(db):
            trainee_id = self._trainee_id(db, trainee)
            rows = db.scalars(select(Session).options(selectinload(Session.metrics), selectinload(Session.scan),
                                                      selectinload(Session.trainee))
                              .where(Session.trainee_id == trainee_id).order_by(Session.started, Session.id))
            return [_session_record(row) for row in rows]
        return self._read(query)

    def assessment(self, recording_sha256: str) -> dict:
        """The assessment document stored for a recording, as it was added."""
        def query(db):
            text = db.scalar(select(Session.assessment).where(Session.recording_sha256 == recording_sha256.lower()))
            if text is None:
                raise RecordsError(f"no session with recording {recording_sha256} in {self}")
            return json.loads(text)
        return self._read(query)

    def metric_names(self, trainee: str) -> list[str]:
        """The names of every metric measured in ``trainee``'s sessions, sorted."""
        def query(db):
            trainee_id = self._trainee_id(db, trainee)
            return list(db.scalars(select(Metric.name).join(Session).where(Session.trainee_id == trainee_id)
                                   .distinct().order_by(Metric.name)))
        return self._read(query)

    def learning_curve(self, trainee: str, names=("score",), scan: str | None = None) -> list[CurvePoint]:
        """``trainee``'s sessions in time order with the values ``names`` (metric names, ``score``, ``duration_s``).

        One query: the trainee's sessions joined to the metrics asked for. A
        metric a session did not measure is None. ``scan`` keeps only the
        sessions on that scan (a curve compares like with like).
        """
        names = list(dict.fromkeys(names))
        metric_names = [n for n in names if n not in SESSION_VALUES]

        def query(db):
            trainee_id = self._trainee_id(db, trainee)
            statement = (select(Session.id, Session.started, Session.recording_sha256, Session.score, Session.duration_s,
                                Metric.name, Metric.value)
                         .outerjoin(Metric, and_(Metric.session_id == Session.id, Metric.name.in_(metric_names)))
                         .where(Session.trainee_id == trainee_id).order_by(Session.started, Session.id))
            if scan is not None:
                statement = statement.join(Scan, Scan.id == Session.scan_id).where(Scan.name == scan)
            points: dict[int, CurvePoint] = {}
            for session_id, started, sha256, score, duration, metric, value in db.execute(statement):
                point = points.get(session_id)
                if point is None:
                    own = {"score": score, "duration_s": duration}
                    point = CurvePoint(len(points) + 1, _utc(started), sha256,
                                       {n: own[n] if n in SESSION_VALUES else None for n in names})
                    points[session_id] = point
                if metric is not None:
                    point.values[metric] = value
            return list(points.values())
        return self._read(query)


def _session_record(row: Session, created: bool = True) -> SessionRecord:
    return SessionRecord(id=row.id, trainee=row.trainee.name, scan=row.scan.name, started=_utc(row.started),
                         duration_s=row.duration_s, recording=row.recording, recording_sha256=row.recording_sha256,
                         score=row.score, metrics={m.name: m.value for m in row.metrics}, created=created)


def _reason(error: DBAPIError) -> str:
    """The driver's own words, first line (a connection refusal, a locked file), without SQLAlchemy's boilerplate."""
    text = str(getattr(error, "orig", None) or error).strip()
    return text.splitlines()[0] if text else type(error).__name__


def open(url: str | None = None, connect_timeout_s: float = 10.0) -> RecordStore:  # noqa: A001 - reads as database.open
    """The record store at ``url`` (SQLAlchemy URL or file path; None: :func:`default_database_url`), migrated."""
    return RecordStore(url, connect_timeout_s)
