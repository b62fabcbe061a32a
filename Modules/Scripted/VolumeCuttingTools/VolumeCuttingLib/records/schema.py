"""The tables of the trainee records (SQLAlchemy 2 declarative models).

Normalised so that a learning curve is a join, not a parse: a trainee has
sessions, a session was drilled on a scan and has one ``metrics`` row per
measured number. The assessment document is kept as it came (``sessions.assessment``)
so that nothing it said is lost to the schema's choice of columns.

These models describe the schema at the newest revision of ``migrations/``;
the migrations create it (a test compares the two).
"""

from __future__ import annotations

from datetime import datetime

from sqlalchemy import (Double, ForeignKey, Index, Integer, MetaData, String, Text, UniqueConstraint)
from sqlalchemy.orm import DeclarativeBase, Mapped, mapped_column, relationship

from .assessment import MAX_NAME_LENGTH, MAX_PATH_LENGTH

# Constraint names spelled out, so that migrations on SQLite (which rebuild tables) and PostgreSQL agree.
NAMING = {"ix": "ix_%(table_name)s_%(column_0_N_name)s", "uq": "uq_%(table_name)s_%(column_0_N_name)s",
          "fk": "fk_%(table_name)s_%(column_0_name)s_%(referred_table_name)s", "pk": "pk_%(table_name)s"}


class Base(DeclarativeBase):
    metadata = MetaData(naming_convention=NAMING)


class Trainee(Base):
    __tablename__ = "trainees"

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    name: Mapped[str] = mapped_column(String(MAX_NAME_LENGTH), unique=True)
    # Revision 2: which residency program and year group the trainee belongs to.
    program: Mapped[str | None] = mapped_column(String(MAX_NAME_LENGTH))
    cohort: Mapped[str | None] = mapped_column(String(MAX_NAME_LENGTH))

    sessions: Mapped[list[Session]] = relationship(back_populates="trainee")


class Scan(Base):
    __tablename__ = "scans"
    __table_args__ = (UniqueConstraint("name", "content_sha256"),)

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    name: Mapped[str] = mapped_column(String(MAX_NAME_LENGTH))
    # SHA-256 of the scan's voxels where the assessment gives it, "" where it does not (NULL would not be unique).
    content_sha256: Mapped[str] = mapped_column(String(64), default="")


class Session(Base):
    __tablename__ = "sessions"
    # Revision 2: a trainee's sessions in time order without a sort (the learning curve's query).
    __table_args__ = (Index("ix_sessions_trainee_id_started", "trainee_id", "started"),)

    id: Mapped[int] = mapped_column(Integer, primary_key=True)
    trainee_id: Mapped[int] = mapped_column(ForeignKey("trainees.id"))
    scan_id: Mapped[int] = mapped_column(ForeignKey("scans.id"))
    started: Mapped[datetime]  # UTC
    duration_s: Mapped[float] = mapped_column(Double)
    recording: Mapped[str] = mapped_column(String(MAX_PATH_LENGTH))
    # A recording is stored once, whoever adds it how often: what makes adding idempotent.
    recording_sha256: Mapped[str] = mapped_column(String(64), unique=True)
    score: Mapped[float] = mapped_column(Double)
    reference_sha256: Mapped[str | None] = mapped_column(String(64))
    assessment_version: Mapped[int] = mapped_column(Integer)
    assessment: Mapped[str] = mapped_column(Text)  # the JSON document as added
    recorded: Mapped[datetime]  # UTC, when the row was written

    trainee: Mapped[Trainee] = relationship(back_populates="sessions")
    scan: Mapped[Scan] = relationship()
    metrics: Mapped[list[Metric]] = relationship(back_populates="session", cascade="all, delete-orphan")


class Metric(Base):
    __tablename__ = "metrics"
    # Revision 2: one metric across every session (a cohort's figures).
    __table_args__ = (Index("ix_metrics_name", "name"),)

    session_id: Mapped[int] = mapped_column(ForeignKey("sessions.id", ondelete="CASCADE"), primary_key=True)
    name: Mapped[str] = mapped_column(String(MAX_NAME_LENGTH), primary_key=True)
    value: Mapped[float] = mapped_column(Double)

    session: Mapped[Session] = relationship(back_populates="metrics")
