"""Classic codecs at their lowest rates: H.264 (libx264) and AV1 (SVT-AV1) through PyAV, for comparison
with facemime's own rate. Each clip is one key frame followed only by inter frames, 4:2:0, in an
in-memory MP4 whose whole size (container included) is the byte count; the frames are decoded back
to RGB for scoring.

    python benchmarks/classic_codecs.py --video ../shared/data/video/lp_d3.mp4 [--frames N]

Quantisers are strings, ``"crf=51"`` or ``"qp=51"`` (an int is a CRF). The floor is the fewest
bytes among each codec's coarsest settings (:data:`FLOOR`):

- x264: CRF 51 (the top of its CRF scale) and QP 51 (the top of H.264's scale). x264 also takes
  QPs up to 69, emulated within the stream's QP 51, but they ruin the picture before they save
  much: on 120 frames of lp_d3, QP 69 gave 14.0 kB at 17.3 dB whole-frame luma PSNR (the key
  frame 14.7 dB), against 15.8 kB at 28.0 dB for CRF 51 and 18.1 kB at 29.1 dB for QP 51; so
  they are left out. Preset ``veryslow``, the slowest before ``placebo``.
- SVT-AV1 (v4.1.0 in this build): CRF 63 and QP 63 (QP turns adaptive quantisation off, and is
  the smaller of the two: 9.4 kB against 11.8 kB on 100 frames of lp_d3). Preset 0, the slowest:
  on this 2-core machine (shared with other work, load 3-5), 512x512 lp_d3 took 0.37, 0.16, 0.085,
  0.052 and 0.032 s a frame at presets 0-4 (CRF 63, 40 frames), 0.27, 0.12 and 0.064 s at presets
  0-2 (QP 63, 100 frames); a 300-frame encode at preset 0, QP 63, took 72 s, under the 2 minutes
  allowed (all 354 frames: 87 s). Presets 0-4 gave about the same bytes at QP 63 (9.4-9.5 kB on
  100 frames).

One key frame only: x264 takes ``keyint=100000:min-keyint=100000:scenecut=0``; SVT-AV1 takes
``keyint=-1:scd=0`` (its log then says gop size 0, against 161 by default). SVT-AV1 only logs an
option it does not know and encodes on, so :func:`encode` checks on decoding that the first frame
is the only key frame.
"""

from __future__ import annotations

import argparse
import io
import os
import time
from collections.abc import Callable
from fractions import Fraction

import av
import numpy as np

from facemime.io.video import VideoReader

#: Options that leave the first frame the only key frame.
ONE_KEY_FRAME = {
    "libx264": {"x264-params": "keyint=100000:min-keyint=100000:scenecut=0"},
    "libsvtav1": {"svtav1-params": "keyint=-1:scd=0"},
}
#: The slowest preset used, per codec (see the module docstring for why SVT-AV1's is 0).
PRESET = {"libx264": "veryslow", "libsvtav1": "0"}
#: The coarsest quantisers, per codec; the floor is whichever gives the fewest bytes.
FLOOR = {"libx264": ("crf=51", "qp=51"), "libsvtav1": ("crf=63", "qp=63")}


def encode(
    frames: list[np.ndarray], fps: float, codec: str, crf_or_qp: int | str, preset: str | int
) -> tuple[int, list[np.ndarray]]:
    """Encode RGB uint8 (H, W, 3) frames at ``fps`` frames/s with ``codec`` ("libx264" or "libsvtav1")
    into an MP4 in memory; return its size in bytes and its frames decoded to RGB uint8 at the input
    size (odd sizes are padded by the edge pixels for 4:2:0 and cropped back)."""
    size, decoded, _ = _encode(frames, fps, codec, crf_or_qp, preset)
    return size, decoded


def floor(frames: list[np.ndarray], fps: float, codec: str) -> dict:
    """``codec``'s lowest rate: the fewest bytes among its :data:`FLOOR` quantisers at its
    :data:`PRESET`. Returns {"codec", "preset", "quantiser", "bytes", "kbit_s" (kbit per second of
    clip), "seconds" (encoding wall time, decoding excluded), "frames" (decoded RGB),
    "tried" (bytes per quantiser tried)}."""
    results = [_encode(frames, fps, codec, q, PRESET[codec]) for q in FLOOR[codec]]
    best = min(range(len(results)), key=lambda i: results[i][0])
    size, decoded, seconds = results[best]
    return {
        **_entry(codec, PRESET[codec], FLOOR[codec][best], size, seconds, len(frames), fps),
        "frames": decoded,
        "tried": {q: r[0] for q, r in zip(FLOOR[codec], results)},
    }


def curve(
    frames: list[np.ndarray],
    fps: float,
    codec: str,
    settings: list[int | str],
    score: Callable[[list[np.ndarray]], object] | None = None,
    preset: str | int | None = None,
) -> list[dict]:
    """One point per quantiser in ``settings``, at ``preset`` (default :data:`PRESET`): {"codec", "preset",
    "quantiser", "bytes", "kbit_s", "seconds"} as in :func:`floor`, with "score": ``score(decoded
    frames)`` when a score function is given (the frames are then not kept), else "frames"."""
    preset = PRESET[codec] if preset is None else preset
    points = []
    for q in settings:
        size, decoded, seconds = _encode(frames, fps, codec, q, preset)
        point = _entry(codec, preset, q, size, seconds, len(frames), fps)
        point.update({"score": score(decoded)} if score is not None else {"frames": decoded})
        points.append(point)
    return points


def luma_psnr(a: np.ndarray, b: np.ndarray) -> float:
    """PSNR in dB of the BT.601 luma of two RGB uint8 frames, over the whole frame."""
    weights = np.array([0.299, 0.587, 0.114])
    mse = float(np.mean((a @ weights - b @ weights) ** 2))
    return 10 * np.log10(255**2 / mse) if mse > 0 else float("inf")


def _encode(
    frames: list[np.ndarray], fps: float, codec: str, crf_or_qp: int | str, preset: str | int
) -> tuple[int, list[np.ndarray], float]:
    """:func:`encode`, and the encoding's wall time in seconds (decoding excluded)."""
    mode, value = _quantiser(crf_or_qp).split("=")
    h, w = frames[0].shape[:2]
    pad = ((0, h % 2), (0, w % 2), (0, 0))
    buffer = io.BytesIO()
    with av.open(buffer, "w", format="mp4") as container:
        stream = container.add_stream(
            codec,
            rate=Fraction(fps).limit_denominator(1001),
            options={mode: str(value), "preset": str(preset), **ONE_KEY_FRAME[codec]},
        )
        stream.width, stream.height, stream.pix_fmt = w + w % 2, h + h % 2, "yuv420p"
        start = time.perf_counter()
        for frame in frames:
            rgb = np.pad(frame, pad, mode="edge") if h % 2 or w % 2 else np.ascontiguousarray(frame)
            container.mux(stream.encode(av.VideoFrame.from_ndarray(rgb, format="rgb24")))
        container.mux(stream.encode())
        seconds = time.perf_counter() - start
    data = buffer.getvalue()
    with av.open(io.BytesIO(data), "r") as container:
        decoded, keys = [], []
        for frame in container.decode(video=0):
            decoded.append(frame.to_ndarray(format="rgb24")[:h, :w])
            keys.append(frame.key_frame)
    if len(decoded) != len(frames) or not keys[0] or any(keys[1:]):
        raise RuntimeError(
            f"{codec} {crf_or_qp}: {len(decoded)} frames decoded of {len(frames)}, "
            f"key frames at {[i for i, k in enumerate(keys) if k]} (only 0 expected)"
        )
    return len(data), decoded, seconds


def _entry(codec: str, preset: str | int, quantiser: int | str, size: int, seconds: float, n: int, fps: float) -> dict:
    return {
        "codec": codec,
        "preset": str(preset),
        "quantiser": _quantiser(quantiser),
        "bytes": size,
        "kbit_s": size * 8 / 1000 / (n / fps),
        "seconds": seconds,
    }


def _quantiser(crf_or_qp: int | str) -> str:
    """ "crf=N" for an int, else the string as given."""
    return f"crf={crf_or_qp}" if isinstance(crf_or_qp, int) else crf_or_qp


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--video", required=True)
    ap.add_argument("--frames", type=int, default=0, help="first N frames only (0: all)")
    args = ap.parse_args()
    os.environ.setdefault("SVT_LOG", "1")  # SVT-AV1's own log: errors only, not its settings on every encode
    with VideoReader(args.video) as reader:
        fps, frames = reader.fps, []
        for frame in reader:
            frames.append(frame)
            if len(frames) == args.frames:
                break
    h, w = frames[0].shape[:2]
    print(f"{args.video}: {len(frames)} frames, {w}x{h}, {fps:.3f} frames/s, {len(frames) / fps:.2f} s")
    for codec in PRESET:
        f = floor(frames, fps, codec)
        psnr = np.mean([luma_psnr(a, b) for a, b in zip(frames, f["frames"])])
        tried = ", ".join(f"{q} {b} B" for q, b in f["tried"].items())
        print(
            f"{codec:10s} preset {f['preset']:8s} {f['quantiser']:7s} {f['bytes']:7d} B {f['kbit_s']:6.2f} kbit/s "
            f"encode {f['seconds']:6.1f} s  luma PSNR (whole frame) {psnr:5.2f} dB   [{tried}]",
            flush=True,
        )


if __name__ == "__main__":
    main()
