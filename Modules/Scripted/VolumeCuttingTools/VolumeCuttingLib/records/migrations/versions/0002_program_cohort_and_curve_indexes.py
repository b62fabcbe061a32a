"""Trainees get a program and a cohort; indexes for a trainee's sessions in time order and for one metric.

Revision ID: 0002
Revises: 0001
Create Date: 2026-11-27

Programs compare year groups, so a trainee may carry the residency program and
cohort they belong to (both optional: existing trainees keep NULL). The
learning curve reads a trainee's sessions by time: an index on
(trainee_id, started) serves it without a sort; one on metrics.name serves a
metric across a cohort.
"""

import sqlalchemy as sa
from alembic import op

revision = "0002"
down_revision = "0001"
branch_labels = None
depends_on = None


def upgrade() -> None:
    with op.batch_alter_table("trainees") as batch:
        batch.add_column(sa.Column("program", sa.String(200), nullable=True))
        batch.add_column(sa.Column("cohort", sa.String(200), nullable=True))
    op.create_index("ix_sessions_trainee_id_started", "sessions", ["trainee_id", "started"])
    op.create_index("ix_metrics_name", "metrics", ["name"])


def downgrade() -> None:
    op.drop_index("ix_metrics_name", table_name="metrics")
    op.drop_index("ix_sessions_trainee_id_started", table_name="sessions")
    with op.batch_alter_table("trainees") as batch:
        batch.drop_column("cohort")
        batch.drop_column("program")
