"""Several users: one application process per browser session, through wslink's launcher (how Kitware deploys trame).

    python -m VolumeCuttingLib.webapp.launcher [--host H] [--port N] [--sessions K] [--folder DIR] [--start-timeout S]
                                               [-- APP OPTIONS]

One application process holds one scene. The launcher serves the page; each
browser that opens it asks the launcher for a session, which starts
``python -m VolumeCuttingLib.webapp`` on a free port of its range with a
secret of its own, and the page connects to that process alone. Users share
nothing; a closed page's process ends after the application's timeout.

This writes, into ``--folder`` (default ``out/webapp-launcher``), the page's
static files (trame's ``www`` generator, with the modules the application
uses) and ``launcher.json``, then runs ``python -m wslink.launcher`` on it.
``APP OPTIONS`` (after ``--``) go to every session (``--phantom``,
``--data-dir DIR``, ...).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
from pathlib import Path

from trame.tools.www import StaticContentGenerator

from .app import CLIENT_MODULE

# The trame modules whose client code the page loads (those the application enables).
PAGE_MODULES = ("www", "vuetify3", "rca", "slicer")
READY_LINE = "App running at"


def write_page(folder: Path) -> Path:
    """The page's static files, as the application serves them itself."""
    generator = StaticContentGenerator()
    generator.client_type = "vue3"
    generator.enable_modules(*PAGE_MODULES)
    generator.enable_module(CLIENT_MODULE)
    www = folder / "www"
    generator.write(www)
    return www


def launcher_configuration(www: Path, host: str, port: int, sessions: int, log_dir: Path, app_options: list[str],
                           start_timeout_s: int = 120) -> dict:
    """wslink launcher configuration: the page at ``host:port``, sessions on the next ``sessions`` ports."""
    return {
        "configuration": {
            "host": host,
            "port": port,
            "endpoint": "paraview",  # where trame's page asks for a session by default
            "content": str(www),
            "sessionURL": "ws://${host}:${port}/ws",
            # A session not ready within this is ended and its page refused; several starting at once on a small
            # machine take longer than one.
            "timeout": start_timeout_s,
            "log_dir": str(log_dir),
            # The session-to-port table a reverse proxy (Apache's RewriteMap) can route by.
            "proxy_file": str(log_dir.parent / "proxy-mapping.txt"),
            "fields": ["secret"],
        },
        "resources": [{"host": host, "port_range": [port + 1, port + sessions]}],
        "properties": {"python": sys.executable},
        "apps": {
            "trame": {
                "cmd": ["${python}", "-m", "VolumeCuttingLib.webapp", "--host", "${host}", "--port", "${port}",
                        "--authKey", "${secret}", "--server", "--timeout", "60", *app_options],
                "ready_line": READY_LINE,
            }
        },
    }


def main(argv=None) -> int:
    arguments = list(sys.argv[1:] if argv is None else argv)
    app_options = []
    if "--" in arguments:
        index = arguments.index("--")
        arguments, app_options = arguments[:index], arguments[index + 1:]
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--host", default="127.0.0.1", help="address the page and the sessions listen on")
    parser.add_argument("--port", type=int, default=9000, help="port of the page; sessions use the next ports")
    parser.add_argument("--sessions", type=int, default=4, help="at most this many users at once (one process each)")
    parser.add_argument("--folder", type=Path, default=Path("out/webapp-launcher"), help="where the page and the configuration go")
    parser.add_argument("--start-timeout", type=int, default=120,
                        help="seconds a session may take to start before the launcher gives up on it")
    args = parser.parse_args(arguments)
    if args.sessions < 1:
        parser.error(f"--sessions {args.sessions}: at least one")
    if args.start_timeout < 1:
        parser.error(f"--start-timeout {args.start_timeout}: at least one second")
    folder = args.folder.resolve()
    (folder / "logs").mkdir(parents=True, exist_ok=True)
    www = write_page(folder)
    configuration = launcher_configuration(www, args.host, args.port, args.sessions, folder / "logs", app_options,
                                           args.start_timeout)
    config_path = folder / "launcher.json"
    config_path.write_text(json.dumps(configuration, indent=2) + "\n")
    print(f"Open http://{args.host}:{args.port}/ (up to {args.sessions} users; configuration: {config_path})", flush=True)
    # The launcher takes this process's place, so that stopping it (Ctrl+C) stops the launcher.
    os.execv(sys.executable, [sys.executable, "-m", "wslink.launcher", str(config_path)])


if __name__ == "__main__":
    sys.exit(main())
