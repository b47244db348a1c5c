"""Expression weights (:mod:`facemime.animate.expressions`) on the ten shared videos: coverage,
re-synthesis and speed.

Per video, the actor is fitted on frame 0 and every frame analysed (as ``facemime run``); the
weights are solved from the tracked knot offsets (and lid closures), and the offsets rebuilt
from them. Figures:

- **coverage**: mean over frames and knots of the distance between the rebuilt and the
  tracked knot offsets, in IOD (the actor model's outer-eye-corner distance); beside it the same
  for all-zero weights (the motion's own size), for scale. Target (issue 51): <= 0.01 IOD.
- **mouth PSNR** (dB, RGB) of the re-synthesis in the actor's scene against the real frame
  inside the mouth region (as ``benchmarks/synthesis.py``: the reference outer lips' hull grown
  by 0.15 IOD), from knots and from weights, over the frames with reference points. Target:
  from weights within 0.5 dB of from knots.
- **speed**: seconds to solve the weights of the video's frames (one core), and per 1,000 frames.

``--calibrate`` prints, instead, the 99th percentile of the amplitude along each pattern alone
(the tracked offsets in each face's feature sizes projected on each unit pattern, negatives 0):
how :data:`facemime.animate.expressions.MAGNITUDES` were set.

    python benchmarks/expressions.py [--data ../shared/data] [--videos lp_d0,vr_1] [--no-psnr] [--calibrate]

Prints a line per video and, last, one JSON line with every figure.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # one core (set before numpy loads)

import argparse
import json
import sys
import time
from pathlib import Path

import cv2
import numpy as np

from facemime.animate.analysis import Analysis
from facemime.animate.expressions import BLINKS, MAGNITUDES, NAMES, Expressions, unit_patterns
from facemime.animate.synth import Puppet
from facemime.io.video import VideoReader
from facemime.types.head import model_iod

sys.path.insert(0, str(Path(__file__).resolve().parent))
from synthesis import regions

VIDEOS = ("lp_d0", "lp_d3", "lp_d6", "lp_d12", "mt_sun", "mt_yongen", "st_aoc", "st_kh", "vr_1", "vr_2")
ROOT = Path(__file__).resolve().parents[1]


def analyse(path: Path) -> tuple[Analysis, list[np.ndarray], list]:
    """The analysis of every frame of ``path``: (the analysis, the frames, their motion)."""
    analysis, frames, motion = None, [], []
    for frame in VideoReader(path):
        if analysis is None:
            analysis = Analysis(frame, path.name)
            motion.append(analysis.last)
        else:
            motion.append(analysis.update(frame))
        frames.append(frame)
    return analysis, frames, motion


def mouth_psnr(puppet: Puppet, frames, motion, offsets, z) -> float:
    """Mean mouth-region PSNR (dB) of the scene re-synthesis driven by ``offsets`` (T, K, 2)."""
    values = []
    for i, (frame, m) in enumerate(zip(frames, motion)):
        if i == 0 or not z["valid"][i]:
            continue
        img = puppet.render(m.pose, offsets[i], (frame.shape[1], frame.shape[0]), look=m.look)
        mask = regions(z["landmarks"][i], float(z["iod"][i]), frame.shape[:2])["mouth"]
        mse = ((img.astype(np.float64) - frame)[mask] ** 2).mean()
        values.append(10 * np.log10(255.0**2 / max(mse, 1e-9)))
    return float(np.mean(values))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--videos", default=",".join(VIDEOS))
    ap.add_argument("--no-psnr", action="store_true", help="coverage and speed only")
    ap.add_argument("--calibrate", action="store_true", help="print the patterns' 99th-percentile amplitudes")
    args = ap.parse_args()
    cv2.setNumThreads(1)
    rows, amplitudes = {}, []
    for name in args.videos.split(","):
        path = args.data / "video" / f"{name}.mp4"
        analysis, frames, motion = analyse(path)
        model = analysis.actor.model
        offsets = np.array([m.offsets for m in motion])
        closure = np.array([m.look.closure for m in motion])
        expressions = Expressions.of(model)
        if args.calibrate:
            knots = np.array([n not in BLINKS for n in NAMES])
            unit = (unit_patterns(model) / np.array([MAGNITUDES[n] for n in NAMES])[:, None, None])[knots]
            unit = (unit * expressions.deformer.feature_sizes()[None, :, None]).reshape(knots.sum(), -1)
            amplitudes.append(np.maximum(offsets.reshape(len(offsets), -1) @ unit.T / (unit**2).sum(1), 0.0))
            print(f"{name}: {len(frames)} frames", flush=True)
            continue
        t0 = time.perf_counter()
        weights = expressions.solve(offsets, closure)
        seconds = time.perf_counter() - t0
        rebuilt = expressions.offsets(weights)
        iod = model_iod(model)
        row = {
            "frames": len(frames),
            "coverage_iod": float(np.linalg.norm(rebuilt - offsets, axis=2).mean() / iod),
            "zero_weights_iod": float(np.linalg.norm(offsets, axis=2).mean() / iod),
            "solve_s": seconds,
            "solve_s_per_1000": 1000 * seconds / len(frames),
            "saturated": float((weights[:, :-2] >= 1.0).mean()),
        }
        if not args.no_psnr:
            z = np.load(args.data / "video" / f"{name}.landmarks.npz")
            puppet = Puppet(analysis.actor, expressions.deformer.feature_sizes(), iod, analysis.actor.pose)
            row["mouth_psnr_knots"] = mouth_psnr(puppet, frames, motion, offsets, z)
            row["mouth_psnr_weights"] = mouth_psnr(puppet, frames, motion, rebuilt, z)
            row["psnr_loss_db"] = row["mouth_psnr_knots"] - row["mouth_psnr_weights"]
        rows[name] = row
        print(f"{name:10s} " + " ".join(f"{k} {v:.4g}" for k, v in row.items()), flush=True)
    if args.calibrate:
        q = np.percentile(np.concatenate(amplitudes), 99, axis=0)
        for n, x in zip([n for n in NAMES if n not in BLINKS], q):
            print(f"{n}: {x:.3f} (now {MAGNITUDES[n]:.2f})")
        return
    missed = [v for v, r in rows.items() if r["coverage_iod"] > 0.01]
    print(f"coverage <= 0.01 IOD: {'met on every video' if not missed else 'NOT met on ' + ', '.join(missed)}")
    if not args.no_psnr:
        missed = [v for v, r in rows.items() if r["psnr_loss_db"] > 0.5]
        verdict = "met on every video" if not missed else "NOT met on " + ", ".join(missed)
        print(f"mouth PSNR from weights within 0.5 dB: {verdict}")
    slow = max(r["solve_s_per_1000"] for r in rows.values())
    print(f"solve, slowest per 1,000 frames: {slow:.2f} s (target < 1 s)")
    print(json.dumps(rows))


if __name__ == "__main__":
    main()
