"""Analysis by synthesis on the six shared videos, and the speed of ``facemime run``.

Quality: an actor is fitted on frame 0 of each video (automatic points), every frame is analysed
(tracked contours, head pose, knot offsets) and re-synthesised; PSNR and SSIM (luma, 11×11
Gaussian window σ = 1.5) against the real frame inside the face region (the convex hull of the
reference Face Mesh points) and inside the mouth region (the hull of the reference outer lips,
grown by 0.15 IOD). Next to it, in the same run: **pose only** (the frame-0 face moved by the
measured head pose, no local deformation) and **no motion** (the frame-0 face where it was).

Speed: ``run``'s per-frame work on a 512×512 video with the encoding left out, on one core (the
process pinned to one CPU, the video decoder's threads included), and the share of each stage;
then the whole ``run`` with its H.264 encoding, wall clock, for scale. OpenCV and numpy's BLAS on
one thread.

    python benchmarks/synthesis.py [--data ../shared/data] [--videos lp_d0,vr_1] [--speed lp_d3]

Prints a table and, last, one JSON line with every figure.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")  # one core: no BLAS threads (set before numpy loads)

import argparse
import json
import tempfile
import time
from pathlib import Path

import cv2
import numpy as np

from facemime.animate.analysis import Analysis
from facemime.animate.run import SideBySide, run_video
from facemime.animate.synth import Puppet
from facemime.fit.placement import model_iod
from facemime.io.video import VideoReader
from facemime.track.contours import from_face_mesh

VIDEOS = ("lp_d0", "lp_d3", "lp_d6", "lp_d12", "vr_1", "vr_2")
ROOT = Path(__file__).resolve().parents[1]
METHODS = ("tracked deformation", "pose only", "no motion")


def ssim_map(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Per-pixel SSIM of two gray float images (0..255)."""
    c1, c2 = (0.01 * 255) ** 2, (0.03 * 255) ** 2
    blur = lambda x: cv2.GaussianBlur(x, (11, 11), 1.5)  # noqa: E731
    ma, mb = blur(a), blur(b)
    va, vb, cov = blur(a * a) - ma * ma, blur(b * b) - mb * mb, blur(a * b) - ma * mb
    return ((2 * ma * mb + c1) * (2 * cov + c2)) / ((ma * ma + mb * mb + c1) * (va + vb + c2))


def scores(synth: np.ndarray, real: np.ndarray, masks: dict[str, np.ndarray]) -> dict[str, tuple[float, float]]:
    """region -> (PSNR dB, SSIM) of ``synth`` against ``real`` inside each mask."""
    diff = (synth.astype(np.float64) - real) ** 2
    gs = cv2.cvtColor(synth, cv2.COLOR_RGB2GRAY).astype(np.float64)
    gr = cv2.cvtColor(real, cv2.COLOR_RGB2GRAY).astype(np.float64)
    s = ssim_map(gs, gr)
    out = {}
    for name, m in masks.items():
        mse = diff[m].mean()
        out[name] = (10 * np.log10(255.0 ** 2 / max(mse, 1e-9)), float(s[m].mean()))
    return out


def regions(landmarks: np.ndarray, iod: float, shape: tuple[int, int]) -> dict[str, np.ndarray]:
    face = np.zeros(shape, np.uint8)
    cv2.fillConvexPoly(face, cv2.convexHull(np.round(landmarks[:, :2]).astype(np.int32)), 1)
    c = from_face_mesh(landmarks)
    lips = np.concatenate([c["mouth_outer_upper"], c["mouth_outer_lower"]])
    mouth = np.zeros(shape, np.uint8)
    cv2.fillConvexPoly(mouth, cv2.convexHull(np.round(lips).astype(np.int32)), 1)
    grow = max(1, int(round(0.15 * iod)))
    mouth = cv2.dilate(mouth, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * grow + 1, 2 * grow + 1)))
    return {"face": face.astype(bool), "mouth": (mouth & face).astype(bool)}


def quality(path: Path, landmarks: np.ndarray, valid: np.ndarray, iod: np.ndarray) -> dict[str, dict[str, list]]:
    out = {m: {"face": [], "mouth": []} for m in METHODS}
    analysis = puppet = None
    size = None
    for i, frame in enumerate(VideoReader(path)):
        if analysis is None:
            analysis = Analysis(frame, path.name)
            puppet = Puppet(analysis.actor, analysis.deformer.feature_sizes(), model_iod(analysis.actor.model))
            size, pose0, zero = (frame.shape[1], frame.shape[0]), analysis.actor.pose, np.zeros((len(analysis.deformer.knots), 2))
            continue
        m = analysis.update(frame)
        if not valid[i]:
            continue
        masks = regions(landmarks[i], float(iod[i]), frame.shape[:2])
        renders = {"tracked deformation": puppet.render(m.pose, m.offsets, size),
                   "pose only": puppet.render(m.pose, zero, size),
                   "no motion": puppet.render(pose0, zero, size)}
        for method, img in renders.items():
            for region, value in scores(img, frame, masks).items():
                out[method][region].append(value)
    return out


def speed(path: Path) -> dict[str, float]:
    """``run``'s per-frame work (decode, track, pose, synthesis, compose; :class:`SideBySide`)
    on one core with the encoding left out: the process is pinned to one CPU, so the decoder's
    threads count too and no encoder threads compete. Then, for scale, the whole ``run`` with
    its encoding, unpinned (wall-clock frames/s)."""
    cpus = os.sched_getaffinity(0)
    os.sched_setaffinity(0, {min(cpus)})
    try:
        with VideoReader(path) as reader:
            work = SideBySide(reader, path.name)
            for _ in work:
                pass
        result = work.result([])
    finally:
        os.sched_setaffinity(0, cpus)
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        whole = run_video(path, Path(tmp) / "out.mp4", force=True)
        wall = time.perf_counter() - t0
    return {"fps": result.fps, "frames": result.frames, **{f"share_{k}": v for k, v in result.shares.items()},
            "fit_seconds": result.seconds["fit"], "fps_run_with_encoding_wall": whole.frames / wall,
            "encode_seconds": whole.seconds["encode"]}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--videos", default=",".join(VIDEOS))
    ap.add_argument("--speed", default="lp_d3", help="512x512 video for the speed measurement")
    args = ap.parse_args()
    cv2.setNumThreads(1)
    per_video = {}
    for name in args.videos.split(","):
        z = np.load(args.data / "video" / f"{name}.landmarks.npz")
        t0 = time.perf_counter()
        q = quality(args.data / "video" / f"{name}.mp4", z["landmarks"], z["valid"], z["iod"])
        per_video[name] = {m: {r: {"psnr": float(np.mean([v[0] for v in vals])), "ssim": float(np.mean([v[1] for v in vals]))}
                               for r, vals in regions_.items()} for m, regions_ in q.items()}
        print(f"{name}: {len(q['no motion']['face'])} frames in {time.perf_counter() - t0:.1f} s", flush=True)
    print(f"\n{'method':22s} {'face PSNR':>10s} {'face SSIM':>10s} {'mouth PSNR':>11s} {'mouth SSIM':>11s}   (mean over videos)")
    pooled = {}
    for m in METHODS:
        pooled[m] = {f"{r}_{k}": float(np.mean([per_video[v][m][r][k] for v in per_video])) for r in ("face", "mouth") for k in ("psnr", "ssim")}
        p = pooled[m]
        print(f"{m:22s} {p['face_psnr']:10.2f} {p['face_ssim']:10.4f} {p['mouth_psnr']:11.2f} {p['mouth_ssim']:11.4f}")
    print("\nmouth PSNR per video: " + "  ".join(
        f"{v}: {per_video[v]['tracked deformation']['mouth']['psnr']:.2f} vs {per_video[v]['pose only']['mouth']['psnr']:.2f}" for v in per_video))
    sp = speed(args.data / "video" / f"{args.speed}.mp4")
    print(f"\nrun on {args.speed} ({sp['frames']} frames), one core, encoding excluded: {sp['fps']:.0f} frames/s; shares: "
          + ", ".join(f"{k[6:]} {100 * v:.0f}%" for k, v in sp.items() if k.startswith("share_")))
    print(f"the whole run with H.264 encoding, all cores: {sp['fps_run_with_encoding_wall']:.0f} frames/s wall clock")
    print(json.dumps({"pooled": pooled, "per_video": per_video, "speed": sp}))


if __name__ == "__main__":
    main()
