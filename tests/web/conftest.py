"""Fixtures of the browser receiver's tests: a headless Chromium (Debian's ``chromium``, driven
by Playwright's Python client; no browser is downloaded) and the built page.

Without Chromium or Playwright the browser tests are skipped, or fail when the environment
variable CI is set (CI installs both: see the README's test command)."""

import os
import shutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PAGE = ROOT / "python" / "facemime" / "web" / "index.html"
#: Chromium's flags for a closed network: no background connections, no sandbox as root.
CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run", "--disable-background-networking",
                 "--disable-component-update", "--disable-sync"]


def _unavailable(what: str) -> None:
    if os.environ.get("CI"):
        pytest.fail(f"the browser tests need {what}")
    pytest.skip(f"the browser tests need {what}")


@pytest.fixture(scope="session")
def browser():
    """A headless Chromium, for the session."""
    executable = shutil.which("chromium") or shutil.which("chromium-browser")
    if executable is None:
        _unavailable("Debian's chromium package (apt-get install chromium)")
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        _unavailable("the Python package playwright (pip install -e '.[test]')")
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=executable, args=CHROMIUM_ARGS)
        yield b
        b.close()


@pytest.fixture(scope="session")
def receiver_page() -> Path:
    """The receiver page as the package ships it."""
    return PAGE


@pytest.fixture
def page(browser):
    """A fresh page; fails the test on any uncaught error in it."""
    context = browser.new_context()
    pg = context.new_page()
    errors: list[str] = []
    pg.on("pageerror", lambda e: errors.append(str(e)))
    yield pg
    context.close()
    assert not errors, f"the page raised: {errors}"
