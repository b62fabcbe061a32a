"""Alembic's environment: migrate the connection that ``database.migrate`` hands over, in its transaction.

Run only through ``database.migrate``, which opens the transaction (and, on
PostgreSQL, takes a lock) so that two processes opening one new database do
not both create it.
"""

from alembic import context

from VolumeCuttingLib.records.schema import Base

connection = context.config.attributes.get("connection")
if connection is None:
    raise RuntimeError("the records' migrations run through VolumeCuttingLib.records.database.migrate, "
                       "which passes the connection to migrate")
# Batch mode: SQLite cannot alter a column or a constraint in place, Alembic rebuilds the table instead.
context.configure(connection=connection, target_metadata=Base.metadata, render_as_batch=True,
                  transaction_per_migration=False)
with context.begin_transaction():
    context.run_migrations()
