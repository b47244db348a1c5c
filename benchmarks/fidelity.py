"""Eyes (issue 55) on the ten shared videos: how well they are measured, and what they add to the
synthesised face, and at what rate.

Eyes, against the reference Face Mesh points (frames 1.., where the reference has a face), each
error divided by that frame's IOD and averaged over frames and both eyes:

- **iris**: the measured iris centre against the reference's (points 468 and 473);
- **opening**: the measured lid opening (upper-lid middle to lower-lid middle, px) against the
  reference's (points 159-145, 386-374);
- **frozen**: the same for the key frame's eyes carried by the head (what the synthesis showed
  before: the key frame's iris place in today's eye frame, the key frame's opening);
- **blinks**: runs of frames with both eyes shut, in the reference (opening below
  :data:`SHUT` IOD) and in the measurement (closure above :data:`CLOSED`), and how many of the
  reference's the measurement overlaps.

Synthesis, face region (the hull of the reference points) and eye region (the hull of each eye's
reference ring grown by 0.1 IOD), luma PSNR (dB, BT.601 Y) and SSIM against the real frame, for
the actor in its scene driven **with the look** (the measured eyes) and with **none** (the
eyes of the key frame, as before this issue).

Rate: the clip's stream (``encode_clip``, default settings) with and without the look, motion
kbit/s after the actor.

    python benchmarks/fidelity.py [--data ../shared/data] [--videos lp_d0,vr_1] [--stills DIR]

Prints a table per video, the means, and one JSON line with every figure.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import json
import sys
from dataclasses import replace
from pathlib import Path

import cv2
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from facemime.animate.analysis import Analysis
from facemime.animate.synth import Puppet
from facemime.codec.clip import Clip, encode_clip
from facemime.codec.stream import Settings
from facemime.io.video import VideoReader
from facemime.types.head import model_iod
from facemime.types.look import Look
from synthesis import ssim_map

VIDEOS = ("lp_d0", "lp_d3", "lp_d6", "lp_d12", "mt_sun", "mt_yongen", "st_aoc", "st_kh", "vr_1", "vr_2")
ROOT = Path(__file__).resolve().parents[1]
IRIS = (468, 473)
LIDS = ((159, 145), (386, 374))
RINGS = (
    (33, 246, 161, 160, 159, 158, 157, 173, 133, 155, 154, 153, 145, 144, 163, 7),
    (362, 398, 384, 385, 386, 387, 388, 466, 263, 249, 390, 373, 374, 380, 381, 382),
)
#: A reference eye is shut below this opening (IOD); a measured one above this closure.
SHUT = 0.03
CLOSED = 0.6
VARIANTS = ("look", "none")


def luma(image: np.ndarray) -> np.ndarray:
    return image.astype(np.float64) @ np.array([0.299, 0.587, 0.114])


def regions(points: np.ndarray, iod: float, shape: tuple[int, int]) -> dict[str, np.ndarray]:
    """The face (hull of the reference points) and both eyes (hulls of their rings grown by
    0.1 IOD) of a frame of ``shape``."""
    face = np.zeros(shape, np.uint8)
    cv2.fillConvexPoly(face, cv2.convexHull(np.round(points[:, :2]).astype(np.int32)), 1)
    eyes = np.zeros(shape, np.uint8)
    for ring in RINGS:
        cv2.fillConvexPoly(eyes, cv2.convexHull(np.round(points[list(ring), :2]).astype(np.int32)), 1)
    grow = max(1, int(round(0.1 * iod)))
    eyes = cv2.dilate(eyes, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * grow + 1, 2 * grow + 1)))
    return {"face": face.astype(bool), "eyes": (eyes & face).astype(bool)}


def scores(synth: np.ndarray, real: np.ndarray, masks: dict[str, np.ndarray]) -> dict[str, tuple[float, float]]:
    ys, yr = luma(synth), luma(real)
    s = ssim_map(ys, yr)
    return {
        n: (10 * np.log10(255.0**2 / max(((ys - yr)[m] ** 2).mean(), 1e-9)), float(s[m].mean()))
        for n, m in masks.items()
    }


def runs(flags: np.ndarray) -> list[tuple[int, int]]:
    """[first, last] of each run of True."""
    out, start = [], None
    for i, f in enumerate(list(flags) + [False]):
        if f and start is None:
            start = i
        elif not f and start is not None:
            out.append((start, i - 1))
            start = None
    return out


def one_video(path: Path, ref: dict, still: Path | None) -> dict:
    landmarks, valid, iod = ref["landmarks"], ref["valid"], ref["iod"]
    out = {v: {r: [] for r in ("face", "eyes")} for v in VARIANTS}
    eye_err, motions, shut_ref, shut_ours = [], [], [], []
    analysis = None
    still_at = int(0.6 * len(valid))
    for i, frame in enumerate(VideoReader(path)):
        if analysis is None:
            analysis = Analysis(frame, path.name)
            actor, size = analysis.actor, (frame.shape[1], frame.shape[0])
            puppet = Puppet(actor, analysis.deformer.feature_sizes(), model_iod(actor.model), actor.pose)
            motions.append(analysis.last)
            shut_ref.append(False)
            shut_ours.append(False)
            continue
        m = analysis.update(frame)
        motions.append(m)
        shut_ours.append(bool(m.face and (m.look.closure > CLOSED).all()))
        if not valid[i]:
            shut_ref.append(False)
            continue
        p = landmarks[i]
        opening_ref = np.array([np.linalg.norm(p[a, :2] - p[b, :2]) for a, b in LIDS])
        shut_ref.append(bool((opening_ref / iod[i] < SHUT).all()))
        s, key = analysis.eye_state, analysis.eyes.key
        frozen_iris = np.array([f.to_image(k) for f, k in zip(s.frames, key.iris)])
        frozen_opening = key.opening * np.array([f.width for f in s.frames])
        iris_ref = p[list(IRIS), :2]
        eye_err.append(
            [
                np.linalg.norm(s.iris_xy() - iris_ref, axis=1).mean() / iod[i],
                np.abs(s.opening_px() - opening_ref).mean() / iod[i],
                np.linalg.norm(frozen_iris - iris_ref, axis=1).mean() / iod[i],
                np.abs(frozen_opening - opening_ref).mean() / iod[i],
            ]
        )
        looks = {"look": m.look, "none": Look()}
        renders = {v: puppet.render(m.pose, m.offsets, size, look=looks[v]).copy() for v in VARIANTS}
        masks = regions(p, float(iod[i]), frame.shape[:2])
        for v, img in renders.items():
            for r, value in scores(img, frame, masks).items():
                out[v][r].append(value)
        if still is not None and i == still_at:
            cv2.imwrite(
                str(still / f"{path.stem}.png"),
                cv2.cvtColor(np.hstack([frame, renders["look"], renders["none"]]), cv2.COLOR_RGB2BGR),
            )
    clip = Clip(analysis.actor, 30.0, size, motions, [], 0.0)
    rates = {}
    for name, ms in (("look", motions), ("none", [replace(x, look=Look()) for x in motions])):
        _, _, packets = encode_clip(replace(clip, motion=ms), Settings(), carry_actor=False)
        rates[name] = sum(map(len, packets)) * 8 / 1000 / (len(ms) / VideoReader(path).fps)
    e = np.array(eye_err).mean(axis=0)
    blinks_ref, blinks_ours = runs(np.array(shut_ref)), runs(np.array(shut_ours))
    caught = sum(any(a <= d and c <= b for c, d in blinks_ours) for a, b in blinks_ref)
    return {
        "iris": e[0],
        "opening": e[1],
        "frozen_iris": e[2],
        "frozen_opening": e[3],
        "blinks_reference": len(blinks_ref),
        "blinks_measured": len(blinks_ours),
        "blinks_caught": caught,
        "kbit_s": rates,
        **{f"{v} {r}": list(np.mean(out[v][r], axis=0)) for v in VARIANTS for r in ("face", "eyes")},
    }


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--videos", default=",".join(VIDEOS))
    ap.add_argument("--stills", type=Path)
    args = ap.parse_args()
    if args.stills:
        args.stills.mkdir(parents=True, exist_ok=True)
    rows = {}
    for name in args.videos.split(","):
        ref = dict(np.load(args.data / "video" / f"{name}.landmarks.npz"))
        r = rows[name] = one_video(args.data / "video" / f"{name}.mp4", ref, args.stills)
        print(
            f"{name:10s} iris {r['iris']:.3f} (frozen {r['frozen_iris']:.3f})  opening {r['opening']:.3f} "
            f"(frozen {r['frozen_opening']:.3f})  blinks {r['blinks_caught']}/{r['blinks_reference']} "
            f"(measured {r['blinks_measured']})  face Y "
            + " / ".join(f"{v} {r[v + ' face'][0]:.2f} {r[v + ' face'][1]:.3f}" for v in VARIANTS)
            + "  eyes Y "
            + " / ".join(f"{r[v + ' eyes'][0]:.2f}" for v in VARIANTS)
            + f"  kbit/s {r['kbit_s']['look']:.2f} (none {r['kbit_s']['none']:.2f})",
            flush=True,
        )
    mean = {
        k: float(np.mean([r[k] for r in rows.values()])) for k in ("iris", "opening", "frozen_iris", "frozen_opening")
    }
    for v in VARIANTS:
        for reg in ("face", "eyes"):
            mean[f"{v} {reg}"] = list(np.mean([r[f"{v} {reg}"] for r in rows.values()], axis=0))
    mean["added kbit/s"] = float(np.mean([r["kbit_s"]["look"] - r["kbit_s"]["none"] for r in rows.values()]))
    print("mean", json.dumps(mean, default=float))
    print(json.dumps({"videos": rows, "mean": mean}, default=float))


if __name__ == "__main__":
    main()
