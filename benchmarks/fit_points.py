"""Accuracy of the automatic reference points on the first frames of the ten shared videos and on
the seven shared face photos, against the points facemime found before its face models
(OpenCV's Haar cascades, eye placement and colour search, snakes settling: ``haar_points.py``
beside this file), measured in the same run.

NME per point group (shared data README): eye corners = mean distance of the four eye corners
(Face Mesh 33, 133, 362, 263) over the IOD; brows = the four brow curves and mouth = the four
mouth curves, each the README's symmetric curve distance over the IOD, averaged per group.
Seconds are each method's, on the machine's threads as configured (``taskset`` for one core).

    python benchmarks/fit_points.py [--data ../shared/data] [--frame 0]

Prints a table and, last, one JSON line with every figure.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import cv2
import numpy as np

from facemime.errors import NoFaceError
from facemime.fit import auto_points
from facemime.io.photo import read_photo
from facemime.metrics import curve_error
from facemime.networks.mesh import POINT_INDICES, reference_points
from facemime.types.points import GROUPS
from haar_points import haar_points

VIDEOS = ("lp_d0", "lp_d3", "lp_d6", "lp_d12", "vr_1", "vr_2", "st_aoc", "st_kh", "mt_sun", "mt_yongen")
PHOTOS = ("lp_s1", "lp_s2", "lp_s7", "lp_s9", "lp_s11", "lp_s12", "lp_s42")
ROOT = Path(__file__).resolve().parents[1]


def group_errors(points: dict[str, np.ndarray], landmarks: np.ndarray, iod: float) -> dict[str, float]:
    """NME of each point group of ``points`` against one frame's Face Mesh ``landmarks``."""
    ref = reference_points(landmarks)
    out = {}
    for group, names in GROUPS.items():
        errs = [
            float(np.linalg.norm(points[n][0] - ref[n][0])) if n in POINT_INDICES else curve_error(points[n], ref[n])
            for n in names
        ]
        out[group] = float(np.mean(errs)) / iod
    return out


def timed(method, image: np.ndarray) -> tuple[dict[str, np.ndarray] | None, float]:
    """A method's points on ``image`` (None where it found no face) and its seconds."""
    t0 = time.perf_counter()
    try:
        points = method(image)
    except NoFaceError:
        points = None
    return points, time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--frame", type=int, default=0, help="frame of each video")
    args = ap.parse_args()
    # OpenCV 5 left the Haar cascades to its contrib modules: without them the baseline is inf
    cascades = hasattr(cv2, "CascadeClassifier")
    if not cascades:
        print("no Haar cascades in this OpenCV (5 keeps them in contrib): the baseline's column is inf")
    baseline = (lambda im: haar_points(im)[0]) if cascades else (lambda im: None)
    methods = {"facemime": lambda im: auto_points(im).points, "cascades": baseline}
    rows = {}
    items = [(v, args.data / "video" / f"{v}.mp4", args.frame) for v in VIDEOS]
    items += [(p, args.data / "photos" / f"{p}.jpg", 0) for p in PHOTOS]
    for name, path, frame in items:
        ref = np.load(path.with_name(f"{name}.landmarks.npz"))
        image = read_photo(path, frame)
        lm, iod = ref["landmarks"][frame, :, :2].astype(np.float64), float(ref["iod"][frame])
        rows[name] = {}
        for method, find in methods.items():
            points, seconds = timed(find, image)
            errors = group_errors(points, lm, iod) if points is not None else {g: float("inf") for g in GROUPS}
            rows[name][method] = errors | {"seconds": seconds}
    print(f"{'image':10} " + " ".join(f"{g + ' facemime/cascades':>30}" for g in GROUPS) + "   seconds")
    for name, r in rows.items():
        print(
            f"{name:10} "
            + " ".join(f"{r['facemime'][g]:>15.4f}/{r['cascades'][g]:<14.4f}" for g in GROUPS)
            + f"   {r['facemime']['seconds']:.3f}/{r['cascades']['seconds']:.3f}"
        )
    summary = {
        m: {
            g: {
                "mean": float(np.mean([r[m][g] for r in rows.values()])),
                "max": float(np.max([r[m][g] for r in rows.values()])),
            }
            for g in GROUPS
        }
        for m in methods
    }
    for stat in ("mean", "max"):
        print(
            f"{stat:10} "
            + " ".join(f"{summary['facemime'][g][stat]:>15.4f}/{summary['cascades'][g][stat]:<14.4f}" for g in GROUPS)
        )
    worst = max(summary["facemime"][g]["max"] for g in GROUPS)
    print(f"every group of every image within 0.03 (facemime): {'yes' if worst <= 0.03 else 'no'} (worst {worst:.4f})")
    print(json.dumps({"images": rows, "summary": summary}))


if __name__ == "__main__":
    main()
