"""A throw-away PostgreSQL server: a cluster in a temporary folder on a loopback port, for tests and benchmarks.

Uses the server binaries of Debian's ``postgresql`` package (``initdb``,
``pg_ctl``, ``postgres`` in ``/usr/lib/postgresql/<version>/bin``, or on
PATH). PostgreSQL refuses to run as root; as root the cluster belongs to the
unprivileged ``postgres`` system user that the Debian package creates (its
files and processes), run through ``subprocess``'s ``user``/``group``. The
server listens on 127.0.0.1 only, without a Unix socket, with a password
(SCRAM) made up for this run; ``fsync`` is off, as nothing of it is kept.

    with TemporaryPostgres() as server:
        url = server.create_database("records_test")   # postgresql+psycopg://...
"""

from __future__ import annotations

import glob
import os
import pwd
import secrets
import shutil
import socket
import subprocess
import tempfile
from pathlib import Path

#: Environment variable naming the folder of initdb and pg_ctl, where they are neither on PATH nor in Debian's place.
BINDIR_VARIABLE = "VOLUMECUTTING_PG_BINDIR"
SUPERUSER = "volumecutting"
UNPRIVILEGED_USERS = ("postgres", "nobody")


class PostgresUnavailable(RuntimeError):
    """No PostgreSQL server binaries on this machine (install Debian's ``postgresql``)."""


def server_bindir() -> Path:
    """The folder holding ``initdb`` and ``pg_ctl``: ``$VOLUMECUTTING_PG_BINDIR``, PATH, or the newest Debian one."""
    candidates = []
    if os.environ.get(BINDIR_VARIABLE):
        candidates.append(Path(os.environ[BINDIR_VARIABLE]))
    on_path = shutil.which("initdb")
    if on_path:
        candidates.append(Path(on_path).resolve().parent)
    versions = sorted(glob.glob("/usr/lib/postgresql/*/bin"), key=lambda p: int(Path(p).parent.name)
                      if Path(p).parent.name.isdigit() else 0, reverse=True)
    candidates.extend(Path(p) for p in versions)
    for folder in candidates:
        if all(os.access(folder / tool, os.X_OK) for tool in ("initdb", "pg_ctl", "postgres")):
            return folder
    raise PostgresUnavailable("no PostgreSQL server binaries (initdb, pg_ctl, postgres) found on PATH, in "
                              f"/usr/lib/postgresql/*/bin or in ${BINDIR_VARIABLE}: install Debian's postgresql "
                              "package (Utilities/vc setup does)")


def _free_loopback_port() -> int:
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


class TemporaryPostgres:
    """A PostgreSQL cluster that exists between :meth:`start` and :meth:`stop` (or a ``with`` block)."""

    def __init__(self, bindir: Path | None = None):
        self.bindir = Path(bindir) if bindir else server_bindir()
        self.folder: Path | None = None
        self.port: int | None = None
        self.password = secrets.token_urlsafe(18)
        self._run_as: dict = {}

    @property
    def data_dir(self) -> Path:
        return self.folder / "data"

    @property
    def log_file(self) -> Path:
        return self.folder / "server.log"

    def _unprivileged(self) -> dict:
        """``subprocess`` arguments that drop root for the server's programs ({} when not root)."""
        if os.geteuid() != 0:
            return {}
        for name in UNPRIVILEGED_USERS:
            try:
                entry = pwd.getpwnam(name)
            except KeyError:
                continue
            return {"user": entry.pw_uid, "group": entry.pw_gid, "extra_groups": []}
        raise PostgresUnavailable(f"PostgreSQL does not run as root and none of the users {UNPRIVILEGED_USERS} exists")

    def _run(self, arguments: list, what: str) -> None:
        result = subprocess.run(arguments, capture_output=True, text=True, timeout=120, **self._run_as)
        if result.returncode != 0:
            log = self.log_file.read_text(errors="replace")[-2000:] if self.log_file.exists() else ""
            raise RuntimeError(f"{what} failed ({' '.join(map(str, arguments))}):\n{result.stdout}{result.stderr}{log}")

    def start(self) -> TemporaryPostgres:
        self._run_as = self._unprivileged()
        # Not pytest's tmp_path: its folders are private to root, and the server's user must reach its files.
        self.folder = Path(tempfile.mkdtemp(prefix="volumecutting-pg-"))
        if self._run_as:
            os.chmod(self.folder, 0o700)
            os.chown(self.folder, self._run_as["user"], self._run_as["group"])
        password_file = self.folder / "password"
        password_file.write_text(self.password + "\n")
        if self._run_as:
            os.chown(password_file, self._run_as["user"], self._run_as["group"])
        try:
            self._run([self.bindir / "initdb", "-D", self.data_dir, "-U", SUPERUSER, "--auth=scram-sha-256",
                       f"--pwfile={password_file}", "-E", "UTF8", "--locale=C", "--no-sync"], "initdb")
            password_file.unlink()
            for _attempt in range(3):  # another program may take the free port before the server binds it
                self.port = _free_loopback_port()
                options = (f"-c listen_addresses=127.0.0.1 -p {self.port} -c unix_socket_directories='' "
                           "-c fsync=off -c synchronous_commit=off -c full_page_writes=off")
                try:
                    self._run([self.bindir / "pg_ctl", "start", "-w", "-t", "60", "-D", self.data_dir,
                               "-l", self.log_file, "-o", options], "pg_ctl start")
                    return self
                except RuntimeError:
                    if "could not bind" not in self.log_file.read_text(errors="replace"):
                        raise
            raise RuntimeError(f"the PostgreSQL server could not bind a loopback port; see {self.log_file}")
        except BaseException:
            self.stop()
            raise

    def url(self, database: str = "postgres") -> str:
        return f"postgresql+psycopg://{SUPERUSER}:{self.password}@127.0.0.1:{self.port}/{database}"

    def create_database(self, name: str) -> str:
        """Create the database ``name`` (letters, digits, _) and return its URL."""
        if not name.replace("_", "").isalnum():
            raise ValueError(f"database name {name!r}: letters, digits and _ only")
        import psycopg

        with psycopg.connect(host="127.0.0.1", port=self.port, user=SUPERUSER, password=self.password,
                             dbname="postgres", autocommit=True) as connection:
            connection.execute(f'CREATE DATABASE "{name}"')
        return self.url(name)

    def stop(self) -> None:
        """Stop the server (fast shutdown) and remove its folder."""
        if self.folder is None:
            return
        if (self.data_dir / "postmaster.pid").exists():
            subprocess.run([self.bindir / "pg_ctl", "stop", "-w", "-m", "fast", "-D", self.data_dir],
                           capture_output=True, timeout=60, **self._run_as)
        shutil.rmtree(self.folder, ignore_errors=True)
        self.folder = None

    def __enter__(self) -> TemporaryPostgres:
        return self.start()

    def __exit__(self, *_) -> None:
        self.stop()
