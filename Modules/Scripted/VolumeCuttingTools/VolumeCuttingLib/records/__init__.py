"""Trainee records: every assessed session of every trainee, in a relational database.

A residency program wants to know whether its residents get better. Each
assessment of a drilling session (``VolumeCuttingAssessment`` JSON: the
session's scan, recording and time, an overall score and flat metrics such as
``safety.contacts.FacialNerve``) becomes a row of ``sessions`` and one row of
``metrics`` per number, so a learning curve is one query. SQLite by default
(a file in the user's data folder, nothing to install), PostgreSQL when a
program runs a shared server (``postgresql+psycopg://...``). The schema is
migrated with Alembic from the scripts shipped in ``migrations/`` each time a
database is opened: an empty one is created at the current revision, an older
one upgraded.

    from VolumeCuttingLib.records import database
    with database.open() as records:     # or database.open("postgresql+psycopg://user@host/db")
        records.add_assessment("A. Resident", assessment)
        records.learning_curve("A. Resident", ["score", "safety.contacts.FacialNerve"])

Modules: ``assessment`` (what a valid assessment is), ``schema`` (the tables),
``database`` (open, add, query, migrate), ``pending`` (sessions kept while the
database cannot be reached, added later), ``localserver`` (a temporary
PostgreSQL cluster for tests and benchmarks), ``__main__`` (the command line,
``Utilities/vc records``). Builds on nothing else of the library; the web
application shows a trainee's progress from it.
"""
