"""Head pose on synthetic truth that owes nothing to the landmark model (issue 63): an actor
fitted on each shared photo with a face, rendered in its own scene at known poses, its mouth and
brows moving, and analysed as ``facemime run`` analyses a video
(:class:`facemime.animate.analysis.Analysis`, 25 frames/s).

The clip: yaw swept 0 → +30 → −30 → 0 degrees, then pitch 0 → +20 → −20 → 0, then roll the
same, then all three at once (yaw 20 sin, pitch 12 sin, roll 10 sin at unrelated rates), at most
2 degrees a frame; the mouth opens and closes and the brows rise and fall throughout. Truth and
estimate are taken relative to the first frame, as yaw, pitch and roll (degrees,
:func:`facemime.types.pose.rotation_matrix`'s convention).

Per photo and axis: the mean absolute error (degrees) and the slope of the estimate on the
truth (least squares through the origin; 1 = fully measured); and the 3 x 3 matrix of each
estimated axis regressed on the three true axes, whose diagonal must carry the motion (an axis
swapped or mirrored shows as a large or negative entry off it or on it).

    python benchmarks/pose_synthetic.py [--data ../shared/data] [--photos lp_s1,lp_s2]

Prints a table, the means, and one JSON line with every figure.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import json
from dataclasses import replace
from pathlib import Path

import cv2
import numpy as np

from facemime.animate.analysis import Analysis
from facemime.animate.deform import Deformer
from facemime.animate.synth import key_frame, scene_mesh, synthesize
from facemime.fit.actor import fit_actor
from facemime.io.photo import read_photo
from facemime.types.contours import CONTOUR_NAMES

ROOT = Path(__file__).resolve().parents[1]
AXES = ("yaw", "pitch", "roll")
FPS = 25.0
STEP = 2.0  # degrees a frame at most


def sweep(limit: float) -> np.ndarray:
    """0 → +limit → −limit → 0 in steps of at most :data:`STEP` degrees."""
    n = int(np.ceil(limit / STEP))
    up = np.linspace(0, limit, n + 1)
    return np.concatenate([up, np.linspace(limit, -limit, 2 * n + 1)[1:], np.linspace(-limit, 0, n + 1)[1:]])


def truth_angles() -> np.ndarray:
    """(T, 3) yaw, pitch, roll of the clip, degrees relative to the actor's fitted pose."""
    parts = []
    for axis, limit in enumerate((30.0, 20.0, 20.0)):
        s = sweep(limit)
        part = np.zeros((len(s), 3))
        part[:, axis] = s
        parts.append(part)
    t = np.arange(150) / FPS
    parts.append(np.column_stack([20 * np.sin(1.1 * t), 12 * np.sin(1.7 * t + 0.5), 10 * np.sin(0.8 * t + 1.0)]))
    return np.concatenate(parts)


def expression(deformer: Deformer, frames: int) -> list[np.ndarray]:
    """Each frame's knot offsets (model units): the mouth opening to 0.18 of the model's
    inter-ocular distance and closing, the brows rising 0.06 and falling, at unrelated rates."""
    g = deformer.model.groups
    iod = float(np.ptp(deformer.model.vertices[np.concatenate([g["eye_left"], g["eye_right"]]), 0]))
    slot = {int(v): k for k, v in enumerate(deformer.knots)}
    lower = [slot[int(v)] for n in ("mouth_outer_lower", "mouth_inner_lower") for v in g[n][1:-1]]
    brows = [slot[int(v)] for n in CONTOUR_NAMES if n.startswith("brow") for v in g[n]]
    out = []
    for i in range(frames):
        o = np.zeros((len(deformer.knots), 2))
        o[lower, 1] -= 0.18 * iod * 0.5 * (1 - np.cos(2 * np.pi * i / 37))
        o[brows, 1] += 0.06 * iod * 0.5 * (1 - np.cos(2 * np.pi * i / 53))
        out.append(o)
    return out


def measure(photo_path: Path) -> dict:
    photo = read_photo(photo_path)
    actor = fit_actor(photo, photo_path.name)[0]
    scene = scene_mesh(actor)
    key = key_frame(actor, scene)
    size = scene.size
    rest = actor.pose
    truth = truth_angles()
    deformer = Deformer(actor.model)
    offsets = expression(deformer, len(truth))
    frames = [
        synthesize(
            actor,
            deformer.vertices(o),
            replace(rest, yaw=rest.yaw + y, pitch=rest.pitch + p, roll=rest.roll + r),
            size,
            scene=scene,
            key=key,
        )
        for (y, p, r), o in zip(truth, offsets)
    ]
    analysis = Analysis(frames[0], photo_path.name, fps=FPS)
    poses = [analysis.last.pose] + [analysis.update(f).pose for f in frames[1:]]
    est = np.array([[p.yaw, p.pitch, p.roll] for p in poses])
    est -= est[0]
    true = truth - truth[0]
    mae = np.abs(est - true).mean(axis=0)
    slope = (est * true).sum(axis=0) / (true**2).sum(axis=0)
    cross = np.linalg.lstsq(true, est, rcond=None)[0].T  # row: estimated axis, column: true axis
    return {
        "frames": len(frames),
        **{f"{a}_mae": float(m) for a, m in zip(AXES, mae)},
        **{f"{a}_slope": float(s) for a, s in zip(AXES, slope)},
        "cross": np.round(cross, 3).tolist(),
        "faceless_frames": int(analysis.frames_without_face),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    parser.add_argument("--photos", default=None, help="comma-separated names (default: every photo with a face)")
    args = parser.parse_args()
    cv2.setNumThreads(1)
    folder = args.data / "photos"
    faces = sorted(p.name.removesuffix(".landmarks.npz") for p in folder.glob("*.landmarks.npz"))
    names = args.photos.split(",") if args.photos else faces
    print(f"{'photo':8s} {'yaw':>6s} {'pitch':>6s} {'roll':>6s} | {'slopes':>17s} | worst off-diagonal  (degrees MAE)")
    results = {}
    for name in names:
        r = measure(folder / f"{name}.jpg")
        results[name] = r
        cross = np.array(r["cross"])
        off = np.abs(cross - np.diag(np.diag(cross))).max()
        print(
            f"{name:8s} {r['yaw_mae']:6.2f} {r['pitch_mae']:6.2f} {r['roll_mae']:6.2f} | "
            f"{r['yaw_slope']:5.2f} {r['pitch_slope']:5.2f} {r['roll_slope']:5.2f} | {off:5.2f}"
        )
    keys = [f"{a}_{k}" for k in ("mae", "slope") for a in AXES]
    means = {k: float(np.mean([r[k] for r in results.values()])) for k in keys}
    print(
        f"{'mean':8s} {means['yaw_mae']:6.2f} {means['pitch_mae']:6.2f} {means['roll_mae']:6.2f} | "
        f"{means['yaw_slope']:5.2f} {means['pitch_slope']:5.2f} {means['roll_slope']:5.2f} |"
    )
    print(json.dumps({"photos": results, "mean": means}))


if __name__ == "__main__":
    main()
