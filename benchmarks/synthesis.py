"""Analysis by synthesis on the ten shared videos, and the speed of ``facemime run``.

Quality: an actor is fitted on frame 0 of each video (automatic points), every later frame is
analysed (tracked contours, head pose, knot offsets) and re-synthesised; PSNR (dB, on RGB) and
SSIM (luma, 11×11 Gaussian window σ = 1.5) against the real frame over the **whole frame**,
inside the **face** region (the convex hull of the reference Face Mesh points) and inside the
**mouth** region (the hull of the reference outer lips, grown by 0.15 IOD). Methods, side by side:

- **scene**: :class:`Puppet` in its scene (the key frame warped by :class:`SceneMesh`), driven
  from the actor's own key-frame pose, as ``run`` shows it;
- **mask only**: ``Puppet(mask_only=True)``, the face alone on the dark ``BACKGROUND``;
- **frozen picture**: the key frame (frame 0) held still;
- **scene, inpainted**: the same face, but the background the head uncovers is filled from a
  clean plate (``cv2.inpaint`` of the key frame with the head masked: the scene triangles inside
  the first ring, all three vertices with follow == 1, dilated by :data:`PLATE_GROW` of the
  picture's shorter side) instead of by stretching the surround: per frame the plate, then only
  those triangles warped as :meth:`SceneMesh.points` gives, then the face. The hole is those
  triangles, not the hull of their vertices: where the picture's edge cut the first ring (a chin
  near the bottom) the hull also takes in a patch no head triangle covers, which then showed
  inpainted even at rest. The outer rings stay where they were here (the plate does not move),
  so the surround beyond the first ring is the key frame as it is. A benchmark variant only, to
  weigh stretching against inpainting.

Targets (issue 49), checked per video and per measure (PSNR, SSIM): the face region no worse
with the scene than mask only, and the scene better than the frozen picture on the whole frame
and on the face. Also per video: the share of frames that depart from the scene
(:mod:`facemime.animate.departure`, what ``run`` marks in the track file). ``--stills DIR``
saves, per video, the frame 60% into the clip as real | scene | mask only | inpainted (PNG).

Speed: ``run``'s per-frame work (:class:`SideBySide`, encoding left out) on a 512×512 video on one
core (the process pinned to one CPU, the video decoder's threads included), in the scene and
mask only, alternated twice, the better of the two passes each (frames/s), with the share of each
stage; then the whole ``run`` with its H.264 encoding, wall clock, for scale. OpenCV and numpy's
BLAS on one thread.

    python benchmarks/synthesis.py [--data ../shared/data] [--videos lp_d0,vr_1] [--speed lp_d3] [--stills DIR]

Prints a table per video, the means over videos and, last, one JSON line with every figure.
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
from facemime.animate.departure import DEPARTS_AT, departure
from facemime.animate.synth import Puppet, key_frame, synthesize
from facemime.app.run import SideBySide, run_video
from facemime.io.video import VideoReader
from facemime.render.raster import render_mesh_into
from facemime.types.contours import from_face_mesh
from facemime.types.head import model_iod
from facemime.types.pose import project

VIDEOS = ("lp_d0", "lp_d3", "lp_d6", "lp_d12", "mt_sun", "mt_yongen", "st_aoc", "st_kh", "vr_1", "vr_2")
ROOT = Path(__file__).resolve().parents[1]
METHODS = ("scene", "mask only", "frozen picture", "scene, inpainted")
REGIONS = ("frame", "face", "mouth")
#: The clean plate's hole: the head's hull grown by this fraction of the picture's shorter side.
PLATE_GROW = 0.01
#: Where in the clip the still is taken (fraction of its frames).
STILL_AT = 0.6


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
        out[name] = (10 * np.log10(255.0**2 / max(mse, 1e-9)), float(s[m].mean()))
    return out


def regions(landmarks: np.ndarray, iod: float, shape: tuple[int, int]) -> dict[str, np.ndarray]:
    """The whole frame, the face and the mouth region of a frame of ``shape`` (H, W) whose
    reference points are ``landmarks`` (478, 2 or 3) px and eye distance ``iod`` px."""
    face = np.zeros(shape, np.uint8)
    cv2.fillConvexPoly(face, cv2.convexHull(np.round(landmarks[:, :2]).astype(np.int32)), 1)
    c = from_face_mesh(landmarks)
    lips = np.concatenate([c["mouth_outer_upper"], c["mouth_outer_lower"]])
    mouth = np.zeros(shape, np.uint8)
    cv2.fillConvexPoly(mouth, cv2.convexHull(np.round(lips).astype(np.int32)), 1)
    grow = max(1, int(round(0.15 * iod)))
    mouth = cv2.dilate(mouth, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * grow + 1, 2 * grow + 1)))
    return {"frame": np.ones(shape, bool), "face": face.astype(bool), "mouth": (mouth & face).astype(bool)}


class Inpainted:
    """The "scene, inpainted" variant for a scene ``puppet``: the clean plate, the first ring's
    triangles warped over it, the face on top (see the module docstring)."""

    def __init__(self, puppet: Puppet):
        self.puppet, scene = puppet, puppet.scene
        w, h = scene.size
        self.key = key_frame(puppet.actor, scene)
        self.triangles = scene.triangles[(scene.follow[scene.triangles] == 1.0).all(axis=1)]
        self.uv = (scene.rest + 0.5) / [w, h]
        hole = np.zeros((h, w), np.uint8)  # the first ring's triangles, rasterised
        render_mesh_into(
            hole,
            np.full((1, 1), 255, np.uint8),
            self.uv,
            scene.rest,
            np.zeros(len(scene.rest)),
            self.triangles,
            filter="nearest",
            cull=False,
        )
        grow = max(1, int(round(PLATE_GROW * min(w, h))))
        hole = cv2.dilate(hole, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * grow + 1, 2 * grow + 1)))
        self.plate = cv2.inpaint(self.key, hole, 5, cv2.INPAINT_TELEA)

    def render(self) -> np.ndarray:
        """The variant for what the puppet drew last (:attr:`Puppet.shown`), (H, W, 3) uint8."""
        vertices, pose = self.puppet.shown
        scene = self.puppet.scene
        out = self.plate.copy()
        points = scene.points(project(vertices[scene.anchors], pose)[0])
        render_mesh_into(out, self.key, self.uv, points, np.zeros(len(points)), self.triangles, cull=False)
        return synthesize(self.puppet.actor, vertices, pose, scene.size, out=out)


def save_still(path: Path, pictures: list[np.ndarray], labels: list[str]) -> None:
    """``pictures`` (RGB, one size) side by side under a strip with their ``labels``, as a PNG."""
    _h, w = pictures[0].shape[:2]
    strip = np.full((28, w * len(pictures), 3), 255, np.uint8)
    for k, label in enumerate(labels):
        cv2.putText(strip, label, (k * w + 8, 20), cv2.FONT_HERSHEY_SIMPLEX, 0.6, (0, 0, 0), 1, cv2.LINE_AA)
    path.parent.mkdir(parents=True, exist_ok=True)
    cv2.imwrite(str(path), cv2.cvtColor(np.vstack([strip, np.hstack(pictures)]), cv2.COLOR_RGB2BGR))


def quality(
    path: Path, landmarks: np.ndarray, valid: np.ndarray, iod: np.ndarray, still: Path | None = None
) -> tuple[dict[str, dict[str, list]], list[float]]:
    """method -> region -> [(PSNR dB, SSIM) per scored frame] over frames 1.. with reference
    points, and every frame's departure from the scene (:func:`departure`, as ``run`` reports)."""
    out = {m: {r: [] for r in REGIONS} for m in METHODS}
    departures = []
    analysis = None
    still_at = int(STILL_AT * len(valid))
    for i, frame in enumerate(VideoReader(path)):
        if analysis is None:
            analysis = Analysis(frame, path.name)
            actor, sizes, size = analysis.actor, analysis.deformer.feature_sizes(), (frame.shape[1], frame.shape[0])
            scene = Puppet(actor, sizes, model_iod(actor.model), actor.pose)
            mask = Puppet(actor, sizes, model_iod(actor.model), actor.pose, mask_only=True)
            inpainted, frozen = Inpainted(scene), frame.copy()
            continue
        m = analysis.update(frame)
        if not valid[i] and not (still is not None and i == still_at):
            continue
        renders = {
            "scene": scene.render(m.pose, m.offsets, size),
            "mask only": mask.render(m.pose, m.offsets, size),
            "frozen picture": frozen,
        }
        renders["scene, inpainted"] = inpainted.render()
        vertices, pose = scene.shown
        departures.append(departure(frame, renders["scene"], project(vertices[scene.scene.anchors], pose)[0]))
        if still is not None and i == still_at:
            save_still(
                still,
                [frame, renders["scene"], renders["mask only"], renders["scene, inpainted"]],
                [f"real {path.stem} #{i}", "scene", "mask only", "scene, inpainted"],
            )
        if not valid[i]:
            continue
        masks = regions(landmarks[i], float(iod[i]), frame.shape[:2])
        for method, img in renders.items():
            for region, value in scores(img, frame, masks).items():
                out[method][region].append(value)
    return out, departures


def one_pass(path: Path, mask_only: bool) -> dict[str, float]:
    """One run of ``run``'s per-frame work on ``path`` (:class:`SideBySide`, no encoding):
    frames/s and the share of each stage."""
    with VideoReader(path) as reader:
        work = SideBySide(reader, path.name, mask_only=mask_only, fps=reader.fps)
        for _ in work:
            pass
    result = work.result([])
    return {
        "fps": result.fps,
        "frames": result.frames,
        "fit_seconds": result.seconds["fit"],
        **{f"share_{k}": v for k, v in result.shares.items()},
    }


def speed(path: Path) -> dict[str, dict[str, float] | float]:
    """``run``'s per-frame work (decode, track, pose, synthesis, compose; :class:`SideBySide`)
    on one core with the encoding left out, mask only and in the scene alternately, twice each,
    the faster pass of each kept: the process is pinned to one CPU, so the decoder's threads
    count too and no encoder threads compete. Then, for scale, the whole ``run`` (scene) with
    its encoding, unpinned (wall-clock frames/s)."""
    cpus = os.sched_getaffinity(0)
    os.sched_setaffinity(0, {min(cpus)})
    best: dict[str, dict[str, float]] = {}
    try:
        for mode in ("mask only", "scene", "mask only", "scene"):
            p = one_pass(path, mode == "mask only")
            print(f"  speed pass, {mode}: {p['fps']:.0f} frames/s", flush=True)
            if mode not in best or p["fps"] > best[mode]["fps"]:
                best[mode] = p
    finally:
        os.sched_setaffinity(0, cpus)
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        whole = run_video(path, Path(tmp) / "out.mp4", force=True)
        wall = time.perf_counter() - t0
    return {
        **best,
        "scene_over_mask": best["scene"]["fps"] / best["mask only"]["fps"],
        "fps_run_with_encoding_wall": whole.frames / wall,
        "encode_seconds": whole.seconds["encode"],
    }


def targets(v: dict) -> dict[str, bool]:
    """Issue 49's targets for one video's figures (method -> region -> {psnr, ssim}), per measure."""
    s, m, f = v["scene"], v["mask only"], v["frozen picture"]
    out = {}
    for k in ("psnr", "ssim"):
        out[f"face_scene_no_worse_than_mask_{k}"] = s["face"][k] >= m["face"][k]
        out[f"scene_beats_frozen_frame_{k}"] = s["frame"][k] > f["frame"][k]
        out[f"scene_beats_frozen_face_{k}"] = s["face"][k] > f["face"][k]
    return out


def table(rows: dict[str, dict[str, dict[str, float]]], title: str) -> None:
    """Print method -> region -> {psnr, ssim} as one line per method."""
    print(f"\n{title}\n{'method':18s}" + "".join(f" {r + ' PSNR':>11s} {r + ' SSIM':>11s}" for r in REGIONS))
    for method, v in rows.items():
        print(f"{method:18s}" + "".join(f" {v[r]['psnr']:11.2f} {v[r]['ssim']:11.4f}" for r in REGIONS))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--videos", default=",".join(VIDEOS))
    ap.add_argument("--speed", default="lp_d3", help="512x512 video for the speed measurement")
    ap.add_argument("--stills", type=Path, default=None, help="folder for one PNG still per video (default: none)")
    args = ap.parse_args()
    cv2.setNumThreads(1)
    per_video, checks, frames, departs = {}, {}, {}, {}
    for name in args.videos.split(","):
        z = np.load(args.data / "video" / f"{name}.landmarks.npz")
        t0 = time.perf_counter()
        still = None if args.stills is None else args.stills / f"{name}.png"
        q, d = quality(args.data / "video" / f"{name}.mp4", z["landmarks"], z["valid"], z["iod"], still)
        departs[name] = float(np.mean(np.array(d) > DEPARTS_AT))
        per_video[name] = {
            m: {r: dict(zip(("psnr", "ssim"), np.mean(vals, axis=0).tolist())) for r, vals in by.items()}
            for m, by in q.items()
        }
        checks[name], frames[name] = targets(per_video[name]), len(q["scene"]["face"])
        table(per_video[name], f"{name}: {frames[name]} frames scored in {time.perf_counter() - t0:.1f} s")
        print(
            f"targets not met: {', '.join(k for k, ok in checks[name].items() if not ok) or 'none'}; "
            f"frames that depart from the scene: {100 * departs[name]:.0f}%",
            flush=True,
        )
    pooled = {
        m: {
            r: {k: float(np.mean([per_video[v][m][r][k] for v in per_video])) for k in ("psnr", "ssim")}
            for r in REGIONS
        }
        for m in METHODS
    }
    table(pooled, f"mean over {len(per_video)} videos")
    print(f"\n{'face region':12s} {'PSNR scene':>11s} {'mask only':>10s} {'SSIM scene':>11s} {'mask only':>10s}")
    for v in per_video:
        s, m = per_video[v]["scene"]["face"], per_video[v]["mask only"]["face"]
        print(f"{v:12s} {s['psnr']:11.2f} {m['psnr']:10.2f} {s['ssim']:11.4f} {m['ssim']:10.4f}")
    for k in next(iter(checks.values())):
        missed = [v for v in checks if not checks[v][k]]
        print(f"target {k}: {'met on every video' if not missed else 'NOT met on ' + ', '.join(missed)}")
    sp = speed(args.data / "video" / f"{args.speed}.mp4")
    for mode in ("scene", "mask only"):
        p = sp[mode]
        print(
            f"run on {args.speed} ({p['frames']} frames), {mode}, one core, encoding excluded: "
            f"{p['fps']:.0f} frames/s; shares: "
            + ", ".join(f"{k[6:]} {100 * x:.0f}%" for k, x in p.items() if k.startswith("share_"))
        )
    print(
        f"scene / mask only: {sp['scene_over_mask']:.2f}; target >= 200 frames/s in the scene: "
        f"{'met' if sp['scene']['fps'] >= 200 else 'NOT MET'}"
    )
    print(f"the whole run with H.264 encoding, all cores: {sp['fps_run_with_encoding_wall']:.0f} frames/s wall clock")
    print(
        json.dumps(
            {
                "pooled": pooled,
                "per_video": per_video,
                "frames": frames,
                "targets": checks,
                "departs": departs,
                "speed": sp,
            }
        )
    )


if __name__ == "__main__":
    main()
