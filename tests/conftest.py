"""Shared fixtures. Tests that need real data use ../shared next to the repository, through the
``shared`` fixture: without it they are skipped, or fail when the environment variable CI is set
(CI has it, and a missing folder there must not turn the real-data tests into silent skips).
Browser tests use ``browser``, a headless Chromium (Debian's ``chromium``, driven by Playwright's
Python client; no browser is downloaded): without it they are skipped, or fail when the
environment variable CI is set (CI installs it: see the README's test command)."""

import os
import shutil
from pathlib import Path

import numpy as np
import pytest

from facemime.fit import fit_model
from facemime.fit.actor import smear_texture
from facemime.head import generic_head
from facemime.io.video import VideoReader
from facemime.networks.mesh import reference_points as face_mesh_points

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared"


def unavailable(message: str) -> None:
    """Skip the test for want of ``message``'s thing, or fail it when the environment variable CI
    is set (CI provides everything the tests need)."""
    if os.environ.get("CI"):
        pytest.fail(message)
    pytest.skip(message)


@pytest.fixture(scope="session")
def shared() -> Path:
    """The shared real data (``../shared/data``)."""
    if not (SHARED / "data").is_dir():
        unavailable(f"shared data folder not found at {SHARED}")
    return SHARED / "data"


@pytest.fixture(scope="session")
def candide_path(shared: Path) -> Path:
    return shared / "models" / "candide3.wfm"


def reference_points(landmarks: np.ndarray) -> dict[str, np.ndarray]:
    """Reference points from one frame's Face Mesh landmarks (478, 2+), pixels, without the
    face outline (the points a user marks by hand)."""
    return {n: p for n, p in face_mesh_points(landmarks).items() if n != "face_outline"}


@pytest.fixture(scope="session")
def points_of():
    """The function that turns Face Mesh landmarks into reference points."""
    return reference_points


@pytest.fixture(scope="session")
def lp_d0(shared):
    """First frame of lp_d0, its reference points and IOD."""
    frame = next(iter(VideoReader(shared / "video" / "lp_d0.mp4")))
    z = np.load(shared / "video" / "lp_d0.landmarks.npz")
    return frame, reference_points(z["landmarks"][0]), float(z["iod"][0])


@pytest.fixture(scope="session")
def actor(lp_d0):
    """The generic head fitted to lp_d0's first frame on its reference points."""
    frame, points, _ = lp_d0
    model = generic_head()
    return smear_texture(
        model, frame, fit_model(model, points), points, {"file": "lp_d0.mp4", "frame": 0, "width": 512, "height": 512}
    )


@pytest.fixture(scope="session")
def astronaut(tmp_path_factory) -> Path:
    """The astronaut photo the package ships (NASA, public domain), as a PNG file."""
    from importlib import resources

    import cv2

    path = tmp_path_factory.mktemp("photo") / "astronaut.png"
    jpg = np.frombuffer(resources.files("facemime.data").joinpath("astronaut.jpg").read_bytes(), np.uint8)
    cv2.imwrite(str(path), cv2.imdecode(jpg, cv2.IMREAD_COLOR))
    return path


#: Chromium's flags for a closed network: no background connections, no sandbox as root.
CHROMIUM_ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]


def _unavailable(what: str) -> None:
    unavailable(f"the browser tests need {what}")


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


#: The browser receiver's sources and npm packages.
WEB = ROOT / "web"


@pytest.fixture(scope="session")
def node() -> str:
    """The ``node`` executable, with ``web/node_modules`` installed (``npm ci`` in web/): without
    them the tests that run Node are skipped, or fail when the environment variable CI is set."""
    node, npm = shutil.which("node"), shutil.which("npm")
    missing = (
        "node and npm"
        if node is None or npm is None
        else "web/node_modules (run `npm ci` in web/)"
        if not (WEB / "node_modules").is_dir()
        else None
    )
    if missing:
        unavailable(f"these tests need {missing}")
    return node
