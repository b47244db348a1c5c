"""What a receiver's synthesis costs with the actor's own mouth and eyes (issue 64), against the
same stream without them, measured in the same run on one thread.

Per video: the stream encoded with ``encode``'s defaults (samples and their choices) and with
``--no-samples``; each decoded, then every frame drawn as ``facemime decode`` draws it
(:meth:`facemime.animate.synth.Puppet.render`, writing the output video left out), the two
streams interleaved over ``--repeats`` rounds, the fastest round kept. Prints milliseconds a
frame, how many times faster than real time that is at the video's frame rate, and one JSON line.

    python benchmarks/decode_speed.py [--data ../shared/data] [--videos lp_d3,st_aoc] [--repeats 3]
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import json
import tempfile
import time
from pathlib import Path

import cv2
import numpy as np

from facemime.animate.deform import Deformer
from facemime.animate.synth import Puppet
from facemime.app.coding import encode_video
from facemime.codec.decoder import MotionDecoder
from facemime.types.head import model_iod

ROOT = Path(__file__).resolve().parents[1]


def draw_all(stream: bytes) -> tuple[float, float]:
    """Seconds to decode ``stream`` and draw every frame; the stream's frame rate."""
    t0 = time.perf_counter()
    decoder = MotionDecoder()
    frames = decoder.push(stream) + decoder.finish()
    actor = decoder.actor
    puppet = Puppet(actor, Deformer(actor.model).feature_sizes(), model_iod(actor.model), decoder.reference())
    w, h = decoder.info.size
    image = np.empty((h, w, 3), np.uint8)
    for f in frames:
        puppet.render(f.pose, f.offsets, (w, h), out=image, look=f.look, samples=f.samples)
    return (time.perf_counter() - t0) / len(frames), decoder.info.fps


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    parser.add_argument("--videos", default="lp_d3,st_aoc,vr_1")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    cv2.setNumThreads(1)
    results = {}
    print(f"{'video':10s} {'samples ms':>10s} {'x real time':>11s} {'without ms':>10s} {'x real time':>11s}")
    for name in args.videos.split(","):
        streams = {}
        with tempfile.TemporaryDirectory() as tmp:
            for samples in (True, False):
                path = Path(tmp) / f"{samples}.fmstream"
                encode_video(args.data / "video" / f"{name}.mp4", path, samples=samples)
                streams[samples] = path.read_bytes()
        best = {True: np.inf, False: np.inf}
        fps = 0.0
        for _ in range(args.repeats):
            for samples in (True, False):
                seconds, fps = draw_all(streams[samples])
                best[samples] = min(best[samples], seconds)
        r = {
            "samples_ms": 1000 * best[True],
            "samples_x_real_time": 1 / (best[True] * fps),
            "without_ms": 1000 * best[False],
            "without_x_real_time": 1 / (best[False] * fps),
        }
        results[name] = r
        print(
            f"{name:10s} {r['samples_ms']:10.2f} {r['samples_x_real_time']:11.1f} "
            f"{r['without_ms']:10.2f} {r['without_x_real_time']:11.1f}"
        )
    print(json.dumps(results))


if __name__ == "__main__":
    main()
