"""Accuracy of the automatic reference points on the first frame of the six shared videos.

NME per point group (shared data README): eye corners = mean distance of the four eye corners
(Face Mesh 33, 133, 362, 263) over the IOD; brows = the four brow curves and mouth = the four
mouth curves, each the README's symmetric curve distance over the IOD, averaged per group.
Next to it, in the same run, the baseline of the generic head placed by the face box alone
(the cascade's face box and the fixed eye prior, no eye cascade, no feature search, no snakes).

    python benchmarks/fit_points.py [--data ../shared/data] [--frame 0]

Prints a table and, last, one JSON line with every figure.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from facemime.fit import auto_points, detect_face, frontal_pose
from facemime.fit.detect import EYE_PRIOR
from facemime.fit.placement import model_eye_centres
from facemime.fit.points import GROUPS, model_chain
from facemime.io.video import VideoReader
from facemime.metrics import curve_error
from facemime.model import generic_head
from facemime.render.projection import project
from facemime.track.contours import FACE_MESH_INDICES

VIDEOS = ("lp_d0", "lp_d3", "lp_d6", "lp_d12", "vr_1", "vr_2")
ROOT = Path(__file__).resolve().parents[1]
EYE_CORNERS = {"eye_right_outer": 33, "eye_right_inner": 133, "eye_left_inner": 362, "eye_left_outer": 263}


def group_errors(points: dict[str, np.ndarray], landmarks: np.ndarray, iod: float) -> dict[str, float]:
    """NME of each point group of ``points`` against one frame's Face Mesh ``landmarks``."""
    out = {}
    for group, names in GROUPS.items():
        errs = []
        for n in names:
            if n in EYE_CORNERS:
                errs.append(float(np.linalg.norm(points[n][0] - landmarks[EYE_CORNERS[n]])))
            else:
                errs.append(curve_error(points[n], landmarks[list(FACE_MESH_INDICES[n])]))
        out[group] = float(np.mean(errs)) / iod
    return out


def box_baseline(frame: np.ndarray) -> dict[str, np.ndarray]:
    """The generic head placed on the eye prior of the face box only."""
    model = generic_head()
    box = detect_face(frame).box
    p = project(model.vertices, frontal_pose(model_eye_centres(model), box[:2] + EYE_PRIOR * box[2]))[0]
    return {n: p[model_chain(model, n)] for names in GROUPS.values() for n in names}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--frame", type=int, default=0)
    args = ap.parse_args()
    rows = {}
    for name in VIDEOS:
        ref = np.load(args.data / "video" / f"{name}.landmarks.npz")
        frame = next(f for i, f in enumerate(VideoReader(args.data / "video" / f"{name}.mp4")) if i == args.frame)
        lm, iod = ref["landmarks"][args.frame, :, :2].astype(np.float64), float(ref["iod"][args.frame])
        t0 = time.perf_counter()
        auto = auto_points(frame)
        seconds = time.perf_counter() - t0
        rows[name] = {"auto": group_errors(auto.points, lm, iod), "box": group_errors(box_baseline(frame), lm, iod),
                      "seconds": seconds, "faces": auto.detection.faces, "eyes_confirmed": auto.detection.eyes_found}
    print(f"{'video':8} " + " ".join(f"{g + ' auto/box':>24}" for g in GROUPS) + "  seconds")
    for name, r in rows.items():
        print(f"{name:8} " + " ".join(f"{r['auto'][g]:>12.4f}/{r['box'][g]:<11.4f}" for g in GROUPS) + f"  {r['seconds']:.2f}")
    mean = {m: {g: float(np.mean([r[m][g] for r in rows.values()])) for g in GROUPS} for m in ("auto", "box")}
    print(f"{'mean':8} " + " ".join(f"{mean['auto'][g]:>12.4f}/{mean['box'][g]:<11.4f}" for g in GROUPS))
    print(json.dumps({"videos": rows, "mean": mean}))


if __name__ == "__main__":
    main()
