"""What a receiver sees (issues 63 and 64): each shared video encoded with ``facemime encode``'s
defaults and decoded as ``facemime decode`` draws it, scored against the real frames.

Per video: the motion's rate (kbit/s, packets only), the mouth and eye sample library's bytes in
the actor chunk, and the luma PSNR (dB, BT.601 Y) of the decoded picture against the real frame
inside the face (the hull of the reference Face Mesh points), the mouth (the hull of the outer
lips grown by 0.1 IOD) and the eyes (the hulls of both eye rings grown by 0.1 IOD), and in issue
64's regions: ``mouth64``, the hull of the outer lips grown 1.3 times about its centre, and
``eyes64``, each eye ring's hull grown 1.5 times about its centre; over every ``--every``-th frame
with a reference face; and the face's on the decoded key frame (frame 0) alone. ``--no-samples``
encodes without the library (the baseline of issue 64).

    python benchmarks/receiver.py [--data ../shared/data] [--videos lp_d0,vr_1] [--every 3]
                                  [--no-samples]

Prints a table, the means, and one JSON line with every figure.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import json
import tempfile
from pathlib import Path

import cv2
import numpy as np

from facemime.animate.deform import Deformer
from facemime.animate.synth import Puppet
from facemime.app.coding import encode_video
from facemime.codec.appearance import Appearance
from facemime.codec.decoder import MotionDecoder
from facemime.io.video import VideoReader
from facemime.shared_constants import NO_FACE_DIM
from facemime.types.head import model_iod

VIDEOS = ("lp_d0", "lp_d3", "lp_d6", "lp_d12", "mt_sun", "mt_yongen", "st_aoc", "st_kh", "vr_1", "vr_2")
ROOT = Path(__file__).resolve().parents[1]
MOUTH = (61, 185, 40, 39, 37, 0, 267, 269, 270, 409, 291, 375, 321, 405, 314, 17, 84, 181, 91, 146)
EYES = (
    (33, 246, 161, 160, 159, 158, 157, 173, 133, 155, 154, 153, 145, 144, 163, 7),
    (362, 398, 384, 385, 386, 387, 388, 466, 263, 249, 390, 373, 374, 380, 381, 382),
)
REGIONS = ("face", "mouth", "eyes", "mouth64", "eyes64")


def hull(points: np.ndarray, shape: tuple[int, int], grow: int = 0) -> np.ndarray:
    mask = np.zeros(shape, np.uint8)
    cv2.fillConvexPoly(mask, cv2.convexHull(np.round(points[:, :2]).astype(np.int32)), 1)
    if grow:
        mask = cv2.dilate(mask, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * grow + 1, 2 * grow + 1)))
    return mask.astype(bool)


def scaled(points: np.ndarray, factor: float) -> np.ndarray:
    """(x, y) of points grown ``factor`` times about their bounding box's centre."""
    xy = points[:, :2]
    centre = (xy.min(axis=0) + xy.max(axis=0)) / 2
    return centre + factor * (xy - centre)


def masks(points: np.ndarray, iod: float, shape: tuple[int, int]) -> dict[str, np.ndarray]:
    grow = max(1, int(round(0.1 * iod)))
    face = hull(points, shape)
    eyes = hull(points[list(EYES[0])], shape, grow) | hull(points[list(EYES[1])], shape, grow)
    return {
        "face": face,
        "mouth": hull(points[list(MOUTH)], shape, grow) & face,
        "eyes": eyes & face,
        "mouth64": hull(scaled(points[list(MOUTH)], 1.3), shape),
        "eyes64": hull(scaled(points[list(EYES[0])], 1.5), shape) | hull(scaled(points[list(EYES[1])], 1.5), shape),
    }


def luma(image: np.ndarray) -> np.ndarray:
    return image.astype(np.float64) @ np.array([0.299, 0.587, 0.114])


def psnr(a: np.ndarray, b: np.ndarray, mask: np.ndarray) -> float:
    return float(10 * np.log10(255.0**2 / max(((a - b)[mask] ** 2).mean(), 1e-9)))


def measure(video: Path, reference: Path, every: int, samples: bool = True) -> dict:
    ref = np.load(reference)
    with tempfile.TemporaryDirectory() as tmp:
        stream = Path(tmp) / "clip.fmstream"
        result = encode_video(video, stream, samples=samples)
        data = stream.read_bytes()
    decoder = MotionDecoder()
    frames = decoder.push(data) + decoder.finish()
    actor = decoder.actor
    puppet = Puppet(actor, Deformer(actor.model).feature_sizes(), model_iod(actor.model), decoder.reference())
    updates = Appearance(actor.texture, decoder.appearance, decoder.appearance_after)
    w, h = decoder.info.size
    image = np.empty((h, w, 3), np.uint8)
    scores: dict[str, list[float]] = {r: [] for r in REGIONS}
    key = float("nan")
    with VideoReader(video) as reader:
        for i, (real, f) in enumerate(zip(reader, frames)):
            if updates.due(f.index):
                puppet.retexture(updates.texture)
            if not ref["valid"][i] or (i % every and i):
                continue
            puppet.render(f.pose, f.offsets, (w, h), out=image, look=f.look, samples=f.samples)
            picture = image if f.face else (image * NO_FACE_DIM).astype(np.uint8)
            regions = masks(ref["landmarks"][i].astype(np.float64), float(ref["iod"][i]), (h, w))
            a, b = luma(picture), luma(real)
            if i == 0:
                key = psnr(a, b, regions["face"])
            for r in REGIONS:
                scores[r].append(psnr(a, b, regions[r]))
    return {
        "kbit_s": result.motion_kbit_s,
        "library_bytes": result.samples_bytes,
        "key_face": key,
        **{r: float(np.mean(v)) for r, v in scores.items()},
    }


def video_arguments(description: str) -> argparse.Namespace:
    """The command line of the benchmarks that score decoded frames: --data, --videos, --every."""
    parser = argparse.ArgumentParser(description=description.split("\n\n")[0])
    parser.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    parser.add_argument("--videos", default=",".join(VIDEOS))
    parser.add_argument("--every", type=int, default=3, help="score every N-th frame")
    parser.add_argument("--no-samples", action="store_true", help="encode without the mouth and eye samples")
    return parser.parse_args()


def main() -> None:
    args = video_arguments(__doc__)
    cv2.setNumThreads(1)
    results = {}
    columns = ("kbit_s", "library_bytes", "key_face", *REGIONS)
    print(f"{'video':10s} " + " ".join(f"{c:>8s}" for c in columns) + "  (dB, luma PSNR)")
    for name in args.videos.split(","):
        data = args.data / "video"
        r = measure(data / f"{name}.mp4", data / f"{name}.landmarks.npz", args.every, not args.no_samples)
        results[name] = r
        print(f"{name:10s} " + " ".join(f"{r[c]:8.2f}" for c in columns))
    means = {k: float(np.mean([r[k] for r in results.values()])) for k in columns}
    print(f"{'mean':10s} " + " ".join(f"{means[c]:8.2f}" for c in columns))
    print(json.dumps({"videos": results, "mean": means}))


if __name__ == "__main__":
    main()
