"""Fixtures of the browser receiver's tests: the built page, and a fresh page of the session's
headless Chromium (``browser``, tests/conftest.py)."""

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PAGE = ROOT / "python" / "facemime" / "web" / "index.html"


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
