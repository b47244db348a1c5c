"""``facemime demo``: the main job on data the package ships or generates.

For now (synthesis only) it shows the built-in generic head: a sheet of views from several
angles (textured, shaded, wireframe), one frontal still per deformation unit, and a short video
in which the head turns and talks, rendered by the texture-mapping core.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from facemime.io import VideoWriter, check_outputs, write_image
from facemime.model import generic_head, painted_texture
from facemime.progress import track
from facemime.render import Pose
from facemime.render.head_view import render_head, views_sheet

FPS = 25


@dataclass
class DemoResult:
    files: list[Path]
    frames: int
    render_seconds: float


def performance(t: float) -> tuple[dict[str, float], dict[str, float]]:
    """Scripted motion at time ``t`` seconds: (deformation unit weights, pose angles in degrees)."""
    talk = max(0.0, np.sin(2 * np.pi * 2.1 * t)) * (0.5 + 0.5 * np.sin(2 * np.pi * 0.37 * t) ** 2)
    units = {
        "jaw_drop": 0.8 * talk,
        "lip_stretch": 0.3 * np.sin(2 * np.pi * 0.5 * t) ** 2,
        "lip_corner_raise": 0.8 * np.sin(2 * np.pi * 0.23 * t),
        "brow_raise": 0.9 * max(0.0, np.sin(2 * np.pi * 0.4 * t)) - 0.3 * max(0.0, -np.sin(2 * np.pi * 0.4 * t)),
        "eyes_closed": 1.0 if (t % 2.7) < 0.12 else 0.0,
    }
    angles = {"yaw": 35 * np.sin(2 * np.pi * t / 4.0), "pitch": 8 * np.sin(2 * np.pi * t / 3.1), "roll": 6 * np.sin(2 * np.pi * t / 5.3)}
    return units, angles


def run_demo(out_dir: Path, force: bool = False, seconds: float = 6.0, size: tuple[int, int] = (640, 480)) -> DemoResult:
    """Write the demo files into ``out_dir``; refuses to overwrite them unless ``force``."""
    files = [out_dir / n for n in ("head_views.png", "deformation_units.png", "head.mp4")]
    check_outputs(files, force)
    out_dir.mkdir(parents=True, exist_ok=True)
    head = generic_head()
    texture = painted_texture(head, 512)
    write_image(files[0], views_sheet(head, texture))
    stills = [render_head(head, texture, Pose.framing(head.vertices, (240, 280), 0.9), (240, 280),
                          vertices=head.deform({name: 1.0}), background=(36, 36, 40)) for name in head.units]
    write_image(files[1], np.hstack(stills))
    frames = int(seconds * FPS)
    base = Pose.framing(head.vertices, size, 0.85)
    busy = 0.0
    with VideoWriter(files[2], FPS) as video:
        for i in track(range(frames), frames, "rendering"):
            units, angles = performance(i / FPS)
            t0 = time.perf_counter()
            pose = Pose(scale=base.scale, tx=base.tx, ty=base.ty, **angles)
            frame = render_head(head, texture, pose, size, vertices=head.deform(units), background=(36, 36, 40))
            busy += time.perf_counter() - t0
            video.write(frame)
    return DemoResult(files, frames, busy)
