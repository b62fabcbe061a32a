"""pytest configuration for the VolumeCuttingTools Python tests.

Makes ``VolumeCuttingLib`` importable when the tests are run without
PYTHONPATH, and registers the ``realdata`` marker used by tests that need the
real head CT (downloaded once into the user cache, never into the repository).
"""

import sys
from pathlib import Path

import pytest

MODULE_DIR = Path(__file__).resolve().parents[2]
if str(MODULE_DIR) not in sys.path:
    sys.path.insert(0, str(MODULE_DIR))


def pytest_configure(config):
    config.addinivalue_line(
        "markers",
        "realdata: needs the real head CT from Debian's invesalius-examples package "
        "(fetched into the user cache on first use; skipped if it cannot be obtained)",
    )
    config.addinivalue_line(
        "markers",
        "browser: drives the web application in Debian's Chromium through Playwright (deselect with -m 'not browser')",
    )


@pytest.fixture(scope="module")
def browser():
    """Debian's Chromium through Playwright, one per test module (the browser tests and the journeys)."""
    from playwright.sync_api import sync_playwright

    from VolumeCuttingLib.webapp.browser import launch_chromium

    with sync_playwright() as playwright:
        chromium = launch_chromium(playwright)
        yield chromium
        chromium.close()


@pytest.fixture(scope="session")
def postgres_server():
    """A PostgreSQL server of Debian's package on a temporary cluster and a loopback port, one per test session."""
    from VolumeCuttingLib.records import localserver

    try:
        server = localserver.TemporaryPostgres()
    except localserver.PostgresUnavailable as error:
        pytest.skip(str(error))
    server.start()
    yield server
    server.stop()
