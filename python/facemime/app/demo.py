"""``facemime demo``: the whole system on data the package ships or generates.

1. Fit the generic head to the astronaut photo (NASA, public domain; shipped as
   ``facemime/data/astronaut.jpg``) and write her actor file and fit preview.
2. Animate the actor with a scripted performance (she talks, opens the mouth wide, raises the
   brows, turns and tilts the head) into a video whose true contours and pose are known.
3. Track that video back (automatic start, no ground truth used) and measure the tracking error
   against the truth (NME, as in the shared data README) and the pose error.
4. Re-synthesise the tracked motion on the astronaut, in her photo (her scene: the photo warped
   to follow the head), and on a second face (the generic head with its painted texture, alone
   on the backdrop): a three-panel video.
5. Write ``report.html`` with stills, the errors and the timings.
"""

from __future__ import annotations

import html
import shutil
import time
from dataclasses import dataclass, replace
from importlib import resources
from pathlib import Path

import cv2
import numpy as np

from facemime.animate.analysis import analysed
from facemime.animate.synth import Puppet, key_frame, scene_mesh, synthesize
from facemime.fit.actor import fit_actor, generic_actor
from facemime.fit.preview import preview_sheet
from facemime.io import VideoWriter, write_image
from facemime.io.actor_file import actor_bytes
from facemime.io.contours_json import track_document, write_json
from facemime.io.outputs import Outputs, write_bytes, write_text
from facemime.metrics import group_nme, summarize
from facemime.progress import track
from facemime.track.overlay import draw_contours
from facemime.types.contours import CONTOUR_NAMES, GROUPS
from facemime.types.head import model_iod
from facemime.types.pose import project

FPS = 25
SIZE = (512, 512)
#: The part of the astronaut photo the demo shows, (x, y, side) pixels: her head and shoulders,
#: enlarged to :data:`SIZE` (the distance between her outer eye corners becomes about 130 px).
FRAMING = (105, 10, 240)
FILES = (
    "astronaut.actor",
    "astronaut.png",
    "performance.mp4",
    "resynthesis.mp4",
    "track.json",
    "stills.png",
    "report.html",
)


@dataclass
class DemoResult:
    """The files written, frames per video, errors (feature group -> mean NME; pose angle -> mean
    absolute error, degrees) and seconds per stage."""

    files: list[Path]
    frames: int
    nme: dict[str, float]
    pose_error: dict[str, float]
    seconds: dict[str, float]


def performance(t: float) -> tuple[dict[str, float], dict[str, float]]:
    """Scripted motion: she talks throughout, opens the mouth wide around 2.5 s, raises the brows
    twice and frowns once, smiles, and turns and tilts the head.

    Parameters
    ----------
    t
        Time from the performance's start, seconds.

    Returns
    -------
    units : dict of str to float
        Expression weights: the head model's deformation unit name (``jawOpen``, ...) to its
        weight (0 to 0.4), for :meth:`~facemime.types.head.HeadModel.deform`.
    angles : dict of str to float
        ``yaw``, ``pitch``, ``roll``: degrees added to the actor's rest pose (within ±16, ±5
        and ±6).
    """
    talk = max(0.0, np.sin(2 * np.pi * 2.1 * t)) * (0.35 + 0.25 * np.sin(2 * np.pi * 0.37 * t) ** 2)
    wide = np.exp(-(((t - 2.6) / 0.35) ** 2))
    # expression weights (facemime.animate.expressions): the lower lip down up to 12 mm, the
    # corners out up to 2 mm each and up 3 mm, the brows up 6 mm and down 4 mm on the generic head
    stretch = 0.08 * np.sin(2 * np.pi * 0.3 * t) ** 2
    smile = 0.19 * np.exp(-(((t - 4.4) / 0.5) ** 2))
    brows = 0.9 * np.exp(-(((t - 1.2) / 0.35) ** 2)) + 0.9 * np.exp(-(((t - 3.6) / 0.35) ** 2))
    down = 0.6 * np.exp(-(((t - 5.2) / 0.3) ** 2))
    units = {
        "jawOpen": 0.33 * min(1.0, 0.7 * talk + 1.0 * wide),
        "mouthStretchLeft": stretch,
        "mouthStretchRight": stretch,
        "mouthSmileLeft": smile,
        "mouthSmileRight": smile,
        "browInnerUp": 0.4 * brows,
        "browOuterUpLeft": 0.4 * brows,
        "browOuterUpRight": 0.4 * brows,
        "browDownLeft": 0.48 * down,
        "browDownRight": 0.48 * down,
    }
    angles = {
        "yaw": 16 * np.sin(2 * np.pi * t / 4.0),
        "pitch": 5 * np.sin(2 * np.pi * t / 3.1),
        "roll": 6 * np.sin(2 * np.pi * t / 5.3),
    }
    return units, angles


def _backdrop(size: tuple[int, int]) -> np.ndarray:
    """A soft studio backdrop: a vertical grey-blue gradient with a little grain."""
    w, h = size
    ramp = np.linspace(0.0, 1.0, h)[:, None, None]
    img = (1 - ramp) * np.array([118, 128, 142]) + ramp * np.array([64, 70, 84])
    grain = np.random.default_rng(7).normal(0, 2.0, (h, w, 1))
    return np.clip(np.broadcast_to(img, (h, w, 3)) + grain, 0, 255).astype(np.uint8)


def _still_sheet(rows: list[np.ndarray]) -> np.ndarray:
    return np.vstack([cv2.resize(r, (r.shape[1] // 2, r.shape[0] // 2), interpolation=cv2.INTER_AREA) for r in rows])


def run_demo(out_dir: Path, force: bool = False, seconds: float = 6.0) -> DemoResult:
    """Write the demo files, all or none. A failed or interrupted demo leaves no folder it
    created.

    Parameters
    ----------
    out_dir
        The folder to write into (created if missing): ``astronaut.actor``, ``astronaut.png`` (the
        fit preview), ``performance.mp4``, ``resynthesis.mp4``, ``track.json``, ``stills.png`` and
        ``report.html`` (:data:`FILES`).
    force
        Overwrite those files where they exist (refused otherwise).
    seconds
        Length of the scripted performance, seconds (at :data:`FPS`, 25 frames/s).

    Returns
    -------
    DemoResult
        The files written, frames per video, the tracking and pose errors, and seconds per stage.
    """
    files = [out_dir / n for n in FILES]
    created = not out_dir.exists()
    try:
        with Outputs(files, force) as outputs:
            return _demo(files, [outputs.stage(f) for f in files], seconds)
    except BaseException:
        if created:
            shutil.rmtree(out_dir, ignore_errors=True)
        raise


def astronaut_photo() -> np.ndarray:
    """The demo's photo: the astronaut the package ships, framed by :data:`FRAMING`.

    Returns
    -------
    (512, 512, 3) uint8 array
        RGB, the framed part scaled to :data:`SIZE` (bicubic).
    """
    photo = cv2.cvtColor(
        cv2.imdecode(
            np.frombuffer(resources.files("facemime.data").joinpath("astronaut.jpg").read_bytes(), np.uint8),
            cv2.IMREAD_COLOR,
        ),
        cv2.COLOR_BGR2RGB,
    )
    x0, y0, side = FRAMING
    return cv2.resize(photo[y0 : y0 + side, x0 : x0 + side], SIZE, interpolation=cv2.INTER_CUBIC)


def _demo(files: list[Path], paths: list[Path], seconds: float) -> DemoResult:
    """The demo's work: ``files`` are the outputs' names, ``paths`` where to write them."""
    timing: dict[str, float] = {}

    # 1. The actor.
    photo = astronaut_photo()
    t0 = time.perf_counter()
    actor = fit_actor(photo, "astronaut.jpg")[0]
    timing["fit"] = time.perf_counter() - t0
    write_bytes(paths[0], actor_bytes(actor))
    write_image(paths[1], preview_sheet(actor, photo))

    # 2. The scripted performance in her photo, with its true contours and pose.
    count = int(seconds * FPS)
    backdrop = _backdrop(SIZE)
    scene, rest = scene_mesh(actor), actor.pose
    key = key_frame(actor, scene)
    frames, truth, truth_poses = [], [], []
    t0 = time.perf_counter()
    for i in range(count):
        units, angles = performance(i / FPS)
        pose = replace(rest, **{k: getattr(rest, k) + a for k, a in angles.items()})
        vertices = actor.model.deform(units)
        frames.append(synthesize(actor, vertices, pose, SIZE, scene=scene, key=key))
        pts = project(vertices, pose)[0]
        truth.append({n: pts[actor.model.groups[n]] for n in CONTOUR_NAMES})
        truth_poses.append(pose)
    timing["render performance"] = time.perf_counter() - t0

    # 3. Track it back.
    t0 = time.perf_counter()
    analysis, motions = None, []
    for _, current, m in analysed(track(frames, count, "tracking"), "the performance", fps=FPS):
        analysis = current
        motions.append(m)
    assert analysis is not None  # the performance has frames
    timing["analyse (fit, track, pose)"] = time.perf_counter() - t0
    nme = {}
    for group, names in GROUPS.items():
        per_frame = []
        for m, ref, pose in zip(motions[1:], truth[1:], truth_poses[1:]):
            corners = project(
                actor.model.vertices[[actor.model.groups["eye_right"][0], actor.model.groups["eye_left"][4]]], pose
            )[0]
            per_frame.append(group_nme(m.contours, ref, names, float(np.linalg.norm(corners[1] - corners[0]))))
        nme[group] = summarize(np.array(per_frame))
    first = analysis.actor.pose
    pose_error = {
        k: float(
            np.mean(
                [
                    abs((getattr(m.pose, k) - getattr(first, k)) - (getattr(p, k) - getattr(rest, k)))
                    for m, p in zip(motions, truth_poses)
                ]
            )
        )
        for k in ("yaw", "pitch", "roll")
    }

    # 4. Re-synthesise on the astronaut and on the second face.
    sizes, iod = analysis.deformer.feature_sizes(), model_iod(analysis.actor.model)
    # the astronaut in her own photo, moved as the tracked face moves from its first pose
    puppets = [Puppet(actor, sizes, iod, analysis.actor.pose), Puppet(generic_actor(SIZE), sizes, iod)]
    stills, shown = [], {int(count * f) for f in (0.2, 0.43, 0.6, 0.87)}
    t0 = time.perf_counter()
    synth_seconds = 0.0
    with VideoWriter(paths[2], FPS) as perf_video, VideoWriter(paths[3], FPS) as video:
        for i, (frame, m) in enumerate(zip(frames, motions)):
            perf_video.write(frame)
            s0 = time.perf_counter()
            panels = [p.render(m.pose, m.offsets, SIZE, out=backdrop.copy(), look=m.look) for p in puppets]
            synth_seconds += time.perf_counter() - s0
            row = np.hstack([draw_contours(frame, m.contours, m.lost)] + panels)
            video.write(row)
            if i in shown:
                stills.append(row)
    timing["re-synthesise (2 faces)"] = synth_seconds
    timing["encode videos"] = time.perf_counter() - t0 - synth_seconds
    write_json(
        paths[4],
        track_document(
            {"width": SIZE[0], "height": SIZE[1], "fps": FPS, "frames": count},
            [
                {
                    "index": i,
                    "contours": m.contours,
                    "confidence": m.confidence,
                    "lost": m.lost,
                    "redetected": m.redetected,
                    "face": m.face,
                    "pose": m.pose.as_dict(),
                    "offsets": m.offsets,
                    "look": m.look.as_dict(),
                }
                for i, m in enumerate(motions)
            ],
            model=analysis.model_block,
        ),
    )
    write_image(paths[5], _still_sheet(stills))
    write_text(paths[6], _report(nme, pose_error, timing, count, sorted(shown)))
    return DemoResult(files, count, {g: s["mean"] for g, s in nme.items()}, pose_error, timing)


def _report(
    nme: dict[str, dict[str, float]],
    pose_error: dict[str, float],
    timing: dict[str, float],
    frames: int,
    shown: list[int],
) -> str:
    rows = "".join(
        f"<tr><td>{html.escape(g.replace('_', ' '))}</td><td>{s['mean']:.4f}</td><td>{s['p90']:.4f}</td>"
        f"<td>{100 * s['failure_rate']:.1f}%</td></tr>"
        for g, s in nme.items()
    )
    pose_rows = "".join(f"<tr><td>{k}</td><td>{v:.1f}°</td></tr>" for k, v in pose_error.items())
    time_rows = (
        "".join(
            f"<tr><td>{html.escape(k)}</td><td>{v:.2f} s</td><td>{frames / max(v, 1e-9):.0f} frames/s</td></tr>"
            for k, v in timing.items()
            if k != "fit"
        )
        + f"<tr><td>fit</td><td>{timing['fit']:.2f} s</td><td></td></tr>"
    )
    return f"""<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>facemime demo</title>
<style>body{{font:15px/1.45 system-ui,sans-serif;max-width:1560px;margin:2em auto;padding:0 1em;color:#222}}
table{{border-collapse:collapse;margin:.5em 0 1.5em}}td,th{{border:1px solid #ccc;padding:.25em .7em;text-align:right}}
td:first-child,th:first-child{{text-align:left}}video,img{{max-width:100%}}</style></head><body>
<h1>facemime demo</h1>
<p>The generic head was fitted to the astronaut photo (<a href="astronaut.png">fit preview</a>,
<a href="astronaut.actor">actor file</a>) and animated by a scripted performance of {frames} frames:
<a href="performance.mp4">performance.mp4</a>. That video was tracked back from an automatic start, and the
tracked motion was re-synthesised on the astronaut and on a second face.</p>
<h2>Re-synthesis</h2>
<p>Left: the performance with the tracked contours. Middle: the motion re-synthesised on the astronaut,
in her photo. Right: the same motion on the generic head.</p>
<video src="resynthesis.mp4" controls loop muted autoplay></video>
<h2>Stills (frames {", ".join(map(str, shown))})</h2>
<img src="stills.png" alt="stills of the re-synthesis">
<h2>Tracking error against the known truth</h2>
<p>NME: mean distance between tracked and true contours over the inter-ocular distance (first frame excluded);
failure: NME above 0.10.</p>
<table><tr><th>feature group</th><th>mean NME</th><th>p90</th><th>failure</th></tr>{rows}</table>
<table><tr><th>head pose</th><th>mean absolute error</th></tr>{pose_rows}</table>
<h2>Timings (one CPU core)</h2>
<table><tr><th>stage</th><th>time</th><th>rate</th></tr>{time_rows}</table>
<p>Motion data: <a href="track.json">track.json</a> (facemime.track/1 with pose and knot offsets per frame).</p>
</body></html>
"""
