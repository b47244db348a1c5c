"""The 52 ARKit values (:mod:`facemime.animate.arkit`) against the Face Mesh references of the
shared videos: blinks told apart from looking down, and the eyes' look directions.

Per video every frame is analysed (as ``facemime live`` does) and its ARKit values solved. Per eye,
the reference's lid opening (the distance between the lids' middles over the eye's width,
relative to frame 0's) marks frames **shut** (under 0.35) and **open and looking down** (over
0.6, the reference's iris 0.04 eye widths or more below its frame-0 place). Figures per video:

- **blinks**: how many shut eye-frames have ``eyeBlink`` > 0.5 and how many looking-down ones
  < 0.2 (issue 66's target on lp_d3), and the median ``eyeBlink`` of each; the counts over all
  the videos last; and on how many eye-frames the eye model looked (``eye_model``);
- **jaw**: the largest ``jawOpen`` and its correlation with the reference's chin drop
  (:func:`facemime.animate.arkit.chin_drop`) and with the gap between its inner lips' middles;
- **look**: the correlation of ``eyeLookIn - eyeLookOut`` (per eye, signed towards image-right)
  and ``eyeLookDown - eyeLookUp`` with the reference iris's shift;
- **speed**: ms a frame of the ARKit solve alone, one core.

    python benchmarks/arkit.py [--data ../shared/data] [--videos lp_d3,lp_d6]

Prints a line per video and, last, one JSON line with every figure.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # one core (set before numpy loads)

import argparse
import json
import time
from pathlib import Path

import numpy as np

from facemime.animate.analysis import analysed
from facemime.animate.arkit import NAMES, ArkitSolver, chin_drop
from facemime.io.video import VideoReader
from facemime.metrics import reference_eyes

VIDEOS = ("lp_d0", "lp_d3", "lp_d6", "lp_d12", "mt_sun", "mt_yongen", "st_aoc", "st_kh", "vr_1", "vr_2")
ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--videos", default=",".join(VIDEOS))
    args = ap.parse_args()
    at = {n: k for k, n in enumerate(NAMES)}
    results = {}
    for name in args.videos.split(","):
        values, seconds, looked = [], 0.0, 0
        with VideoReader(args.data / "video" / f"{name}.mp4") as reader:
            solver = None
            for _, analysis, motion in analysed(reader, name, fps=reader.fps, eye_model=True):
                solver = solver or ArkitSolver(analysis.actor.model)
                looked += 0 if motion.lid_closure is None else int(np.isfinite(motion.lid_closure).sum())
                t0 = time.perf_counter()
                values.append(
                    solver.step(
                        motion.offsets, motion.look, motion.landmark_closure, motion.landmark_jaw, motion.lid_closure
                    )
                )
                seconds += time.perf_counter() - t0
        w = np.array(values)
        ref = np.load(args.data / "video" / f"{name}.landmarks.npz")
        opening, iris = reference_eyes(ref["landmarks"])
        n = min(len(w), len(opening))
        w, opening, u, v = w[:n], opening[:n], iris[:n, :, 0], iris[:n, :, 1]
        row: dict = {"ms_per_frame": round(1000 * seconds / n, 3), "eye_model": f"{looked}/{2 * len(values)}"}
        shut_ok = shut_n = down_ok = down_n = 0
        shut_values, down_values, look_u, look_v = [], [], [], []
        for eye, side in ((0, "Right"), (1, "Left")):
            blink = w[:, at[f"eyeBlink{side}"]]
            shut = opening[:, eye] < 0.35
            down = (opening[:, eye] > 0.6) & (v[:, eye] > 0.04)
            shut_ok += int((blink[shut] > 0.5).sum())
            down_ok += int((blink[down] < 0.2).sum())
            shut_n, down_n = shut_n + int(shut.sum()), down_n + int(down.sum())
            shut_values.append(blink[shut])
            down_values.append(blink[down])
            sign = 1.0 if side == "Right" else -1.0  # the right eye looks in towards image-right
            across = sign * (w[:, at[f"eyeLookIn{side}"]] - w[:, at[f"eyeLookOut{side}"]])
            updown = w[:, at[f"eyeLookDown{side}"]] - w[:, at[f"eyeLookUp{side}"]]
            look_u.append(np.corrcoef(across, u[:, eye])[0, 1] if across.std() > 0 else float("nan"))
            look_v.append(np.corrcoef(updown, v[:, eye])[0, 1] if updown.std() > 0 else float("nan"))
        # the jaw: against the reference's chin drop and the opening between its inner lips
        lm = ref["landmarks"][:n].astype(np.float64)
        chin = np.array([chin_drop(f, lm[0]) for f in lm])
        gap = np.linalg.norm(lm[:, 13, :2] - lm[:, 14, :2], axis=1) / np.linalg.norm(
            lm[:, 33, :2] - lm[:, 263, :2], axis=1
        )
        jaw = w[:, at["jawOpen"]]
        corr = lambda a, b: round(float(np.corrcoef(a, b)[0, 1]), 3) if a.std() > 0 and b.std() > 0 else None  # noqa: E731
        row.update(jaw_max=round(float(jaw.max()), 3), jaw_chin_corr=corr(jaw, chin), jaw_gap_corr=corr(jaw, gap))
        med = lambda parts: round(float(np.median(np.concatenate(parts))), 3) if sum(map(len, parts)) else None  # noqa: E731
        row.update(
            shut=f"{shut_ok}/{shut_n}",
            shut_median=med(shut_values),
            down=f"{down_ok}/{down_n}",
            down_median=med(down_values),
            look_u_corr=[round(float(c), 3) for c in look_u],
            look_v_corr=[round(float(c), 3) for c in look_v],
        )
        results[name] = row
        print(name, row, flush=True)
    counts = np.array([[int(x) for x in r[k].split("/")] for r in results.values() for k in ("shut", "down")])
    shut, down = counts[0::2].sum(axis=0), counts[1::2].sum(axis=0)
    results["all"] = {"shut": f"{shut[0]}/{shut[1]}", "down": f"{down[0]}/{down[1]}"}
    print("all", results["all"])
    print(json.dumps(results))


if __name__ == "__main__":
    main()
