"""Fixtures of the export tests: a synthetic track on the generic head, a real one from
``facemime run`` on a short clip of lp_d0 driving the actor fitted on its first frame, both
exported; Node with ``web/node_modules`` for the validator and three.js (skipped without them,
failed when the environment variable CI is set)."""

import json
import shutil
import subprocess
from pathlib import Path

import av
import numpy as np
import pytest

from facemime.animate.deform import Deformer
from facemime.app.export import export_track
from facemime.head import generic_head
from facemime.types.head import model_iod
from facemime.types.pose import Pose

ROOT = Path(__file__).resolve().parents[2]
WEB = ROOT / "web"


def write_track(path: Path, frames: int = 12, fps: float = 25.0, size=(320, 240), weights=None) -> Path:
    """A ``facemime.track/1`` file of the generic head turning, tilting, rolling, zooming and
    moving (degrees and pixels as facemime measures them), its lips and brows moving a little;
    ``weights``: name -> (frames,) values stored per frame."""
    head = generic_head()
    d = Deformer(head)
    base = Pose.framing(head.vertices, size, 0.6)
    out = []
    for n in range(frames):
        pose = {
            "yaw": 20 * np.sin(n / 4),
            "pitch": 10 * np.sin(n / 3),
            "roll": 8 * np.cos(n / 5),
            "scale": base.scale * (1 + 0.15 * np.sin(n / 6)),
            "tx": base.tx + 12 * np.sin(n / 3.5),
            "ty": base.ty + 8 * np.cos(n / 2.5),
        }
        offsets = np.zeros((len(d.knots), 2))
        offsets[:, 1] = -0.8 * np.sin(n / 2) ** 2 * (d.knots % 3 == 0)
        f = {
            "index": n,
            "contours": {},
            "pose": {k: round(float(v), 4) for k, v in pose.items()},
            "offsets": np.round(offsets, 3).tolist(),
            "look": {"eye_left_closure": round(0.5 * np.sin(n) ** 2, 4)},
        }
        if weights is not None:
            f["weights"] = {k: float(v[n]) for k, v in weights.items()}
        out.append(f)
    doc = {
        "format": "facemime.track/1",
        "frames": out,
        "video": {"width": size[0], "height": size[1], "fps": fps, "frames": frames},
        "model": {
            "unit": "mm",
            "knots": d.knots.tolist(),
            "feature_sizes": d.feature_sizes().round(3).tolist(),
            "iod": round(model_iod(head), 3),
        },
    }
    path.write_text(json.dumps(doc))
    return path


@pytest.fixture(scope="session")
def generic_export(tmp_path_factory) -> tuple[Path, Path]:
    """(track, .glb) of a synthetic 12-frame track exported on the generic head."""
    folder = tmp_path_factory.mktemp("generic")
    track = write_track(folder / "track.json")
    export_track(track, folder / "head.glb")
    return track, folder / "head.glb"


@pytest.fixture(scope="session")
def real_export(shared, actor, tmp_path_factory) -> tuple[Path, Path, Path]:
    """(track, .actor, .glb): ``facemime run`` on lp_d0's first 12 frames, exported on the actor
    fitted on its first frame."""
    from facemime.app.run import run_video
    from facemime.io.actor_file import save_actor
    from facemime.io.video import VideoWriter

    folder = tmp_path_factory.mktemp("real")
    clip = folder / "clip.mp4"
    with av.open(str(shared / "video" / "lp_d0.mp4")) as c, VideoWriter(clip, fps=25) as w:
        for _, frame in zip(range(12), c.decode(video=0)):
            w.write(frame.to_ndarray(format="rgb24"))
    run_video(clip, folder / "run.mp4")
    save_actor(folder / "lp_d0.actor", actor)
    export_track(folder / "run.json", folder / "lp_d0.glb", folder / "lp_d0.actor")
    return folder / "run.json", folder / "lp_d0.actor", folder / "lp_d0.glb"


@pytest.fixture(scope="session")
def three_page(node) -> str:
    """The three.js test page's script (``web/test/gltf-page.mjs`` bundled)."""
    subprocess.run([shutil.which("npm"), "run", "--silent", "build-gltf-page"], cwd=WEB, check=True)
    return (WEB / ".test-build" / "gltf-page.js").read_text()
