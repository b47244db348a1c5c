"""Shared fixtures. Tests that need real data use ../shared next to the repository (CI has it)."""

from pathlib import Path

import numpy as np
import pytest

from facemime.fit import fit_model
from facemime.fit.actor import smear_texture
from facemime.io.video import VideoReader
from facemime.model import generic_head
from facemime.face.mesh import reference_points as face_mesh_points

ROOT = Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared"


@pytest.fixture(scope="session")
def shared() -> Path:
    if not (SHARED / "data").is_dir():
        pytest.skip(f"shared data folder not found at {SHARED}")
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
    return smear_texture(model, frame, fit_model(model, points), points, {"file": "lp_d0.mp4", "frame": 0, "width": 512, "height": 512})


@pytest.fixture(scope="session")
def astronaut(tmp_path_factory) -> Path:
    """The astronaut photo the package ships (NASA, public domain), as a PNG file."""
    import cv2
    from importlib import resources

    path = tmp_path_factory.mktemp("photo") / "astronaut.png"
    jpg = np.frombuffer(resources.files("facemime.data").joinpath("astronaut.jpg").read_bytes(), np.uint8)
    cv2.imwrite(str(path), cv2.imdecode(jpg, cv2.IMREAD_COLOR))
    return path
