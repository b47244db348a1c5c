"""The facemime bitstream on the ten shared videos: rate, quality, speed, loss, and the classic
codecs beside it in the same run.

Per video, the clip is analysed once (actor fitted on frame 0, every frame tracked), then:

- **Rate-quality curve**: the motion (packets: pose, coefficients, flags, framing) in kbit/s at
  qualities 0, 1, 2, 3, 5 (the default), 7, 10 and with ``--rate 1``, and the decoded face's luma
  PSNR and SSIM (11×11 Gaussian window; the eyes as decoded too) inside the face (the convex
  hull of the reference Face Mesh points of each frame), next to the unquantised synthesis (the
  analysis's own pose, offsets and look). The one-time bytes beside it: header (with the clip's basis) and actor
  (WebP texture).
- **Representations** at the default steps: the 60 knots' 120 coordinates directly; a basis
  learned from the *other* nine videos (what a basis shipped with the package would do on an
  unseen face); the clip's own basis (the format's choice) with 8, 16 and 24 vectors.
- **Lossy channel**: 5% of the packets dropped at random (ten channels, seeds 0-9): frames
  concealed and the face PSNR over the clip, means.

Then, on ``--classic`` videos (default lp_d0, lp_d3, vr_1), x264 and SVT-AV1 at their floors
(``classic_codecs.py``: slowest presets, one key frame, whole MP4 bytes), scored the same way;
the texture's size and fidelity as JPEG, WebP and AVIF; decoding speed (bitstream to parameters
in the Rust core, one core; to pictures against ``run``'s synthesis), encoding's share of
tracking; and a fuzz run of the decoder on mutated streams.

    python benchmarks/codec.py [--data ../shared/data] [--videos lp_d0,vr_1] [--classic lp_d3] [--every 3]

Prints tables and, last, one JSON line with every figure.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("SVT_LOG", "1")

import argparse
import json
import random
import sys
import time
from dataclasses import replace
from pathlib import Path

import cv2
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import classic_codecs
from facemime import _core
from facemime.animate.deform import Deformer
from facemime.animate.synth import Puppet
from facemime.codec.clip import MAX_COEFFICIENTS, Clip, analyse, encode_clip
from facemime.codec.decoder import MotionDecoder
from facemime.codec.params import Basis
from facemime.codec.stream import MotionEncoder, Settings
from facemime.io.video import VideoReader
from facemime.shared_constants import BASIS_ONE
from facemime.types.head import model_iod
from synthesis import ssim_map

VIDEOS = ("lp_d0", "lp_d3", "lp_d6", "lp_d12", "vr_1", "vr_2", "mt_sun", "mt_yongen", "st_aoc", "st_kh")
QUALITIES = (0, 1, 2, 3, 5, 7, 10)
ROOT = Path(__file__).resolve().parents[1]


def face_masks(
    landmarks: np.ndarray, valid: np.ndarray, shape: tuple[int, int], frames: list[int]
) -> dict[int, np.ndarray]:
    """Frame -> boolean mask of the hull of its reference Face Mesh points (valid frames only)."""
    out = {}
    for i in frames:
        if valid[i]:
            m = np.zeros(shape, np.uint8)
            cv2.fillConvexPoly(m, cv2.convexHull(np.round(landmarks[i][:, :2]).astype(np.int32)), 1)
            out[i] = m.astype(bool)
    return out


def luma(img: np.ndarray) -> np.ndarray:
    return cv2.cvtColor(img, cv2.COLOR_RGB2GRAY).astype(np.float64)


def score(
    images: dict[int, np.ndarray], real: dict[int, np.ndarray], masks: dict[int, np.ndarray]
) -> tuple[float, float]:
    """Mean luma PSNR (dB) and SSIM inside the face over the scored frames."""
    psnr, ssim = [], []
    for i, m in masks.items():
        a, b = luma(images[i]), real[i]
        psnr.append(10 * np.log10(255.0**2 / max(((a - b) ** 2)[m].mean(), 1e-9)))
        ssim.append(float(ssim_map(a, b)[m].mean()))
    return float(np.mean(psnr)), float(np.mean(ssim))


class Scene:
    """One video: its analysis, the frames scored (every ``every``-th with valid landmarks), their
    luma and masks, and the synthesis of any sequence of (pose, offsets)."""

    def __init__(self, data: Path, name: str, every: int):
        self.name, self.path = name, data / "video" / f"{name}.mp4"
        z = np.load(data / "video" / f"{name}.landmarks.npz")
        t0 = time.perf_counter()
        self.clip: Clip = analyse(self.path)
        self.analysis_seconds = time.perf_counter() - t0
        n = len(self.clip.motion)
        w, h = self.clip.size
        self.masks = face_masks(z["landmarks"], z["valid"], (h, w), list(range(1, n, every)))
        self.real = {i: luma(f) for i, f in enumerate(VideoReader(self.path)) if i in self.masks}
        a = self.clip.actor
        self.puppet = Puppet(a, Deformer(a.model).feature_sizes(), model_iod(a.model))
        self.duration = n / self.clip.fps
        faces = [m.offsets for m in self.clip.motion if m.face]
        self.offsets = np.array(faces)
        self.basis = Basis.learn(self.offsets, MAX_COEFFICIENTS)

    def quality(self, frames) -> tuple[float, float]:
        """Face luma PSNR and SSIM of the synthesis of ``frames`` (decoded or analysed: their
        pose, offsets and look)."""
        images = {
            i: self.puppet.render(frames[i].pose, frames[i].offsets, self.clip.size, look=frames[i].look)
            for i in self.masks
        }
        return score(images, self.real, self.masks)

    def coded(self, settings: Settings, basis: Basis | None = None) -> dict:
        """Encode with ``settings`` (and ``basis``, default the clip's), decode, score."""
        header, actor, packets = encode_clip(self.clip, settings, True, basis or self.basis)
        dec = MotionDecoder()
        frames = dec.push(header + actor + b"".join(packets)) + dec.finish()
        psnr, ssim = self.quality(frames)
        return {
            "kbit_s": sum(map(len, packets)) * 8 / 1000 / self.duration,
            "header_bytes": len(header),
            "actor_bytes": len(actor),
            "psnr": psnr,
            "ssim": ssim,
        }


def identity_basis(knots: int) -> Basis:
    return Basis(np.eye(2 * knots, dtype=np.int16) * BASIS_ONE)


def lossy(scene: Scene, drop: float, seeds: int = 10) -> dict:
    """Each packet dropped with probability ``drop``, over ``seeds`` channels: packets dropped,
    frames concealed and the face's PSNR and SSIM, means over the channels."""
    header, actor, packets = encode_clip(scene.clip, Settings(), True, scene.basis)
    runs = []
    for seed in range(seeds):
        rng = random.Random(seed)
        kept = [p for p in packets if rng.random() >= drop]
        dec = MotionDecoder()
        frames = dec.push(header + actor + b"".join(kept)) + dec.finish()
        missing = len(scene.clip.motion) - len(frames)  # the last packets lost: their frames hold the last one
        frames += [frames[-1]] * missing
        psnr, ssim = scene.quality(frames)
        runs.append((len(packets) - len(kept), dec.stats["concealed"] + missing, psnr, ssim))
    dropped, concealed, psnr, ssim = np.mean(runs, axis=0)
    return {
        "packets": len(packets),
        "dropped": dropped,
        "concealed": concealed,
        "frames": len(scene.clip.motion),
        "psnr": psnr,
        "ssim": ssim,
        "seeds": seeds,
    }


def classic(scene: Scene) -> dict:
    frames = list(VideoReader(scene.path))
    out = {}
    for codec in ("libx264", "libsvtav1"):
        f = classic_codecs.floor(frames, scene.clip.fps, codec)
        psnr, ssim = score(dict(enumerate(f["frames"])), scene.real, scene.masks)
        out[codec] = {
            "kbit_s": f["kbit_s"],
            "bytes": f["bytes"],
            "quantiser": f["quantiser"],
            "preset": f["preset"],
            "seconds": f["seconds"],
            "psnr": psnr,
            "ssim": ssim,
        }
    return out


def texture_sizes(scene: Scene) -> dict:
    tex = scene.clip.actor.texture
    bgr = cv2.cvtColor(tex, cv2.COLOR_RGB2BGR)
    out = {"png": len(cv2.imencode(".png", bgr)[1])}
    flags = {"jpg": cv2.IMWRITE_JPEG_QUALITY, "webp": cv2.IMWRITE_WEBP_QUALITY, "avif": cv2.IMWRITE_AVIF_QUALITY}
    for fmt, flag in flags.items():
        for q in (50, 70, 80, 90):
            data = cv2.imencode("." + fmt, bgr, [flag, q])[1]
            back = cv2.cvtColor(cv2.imdecode(data, cv2.IMREAD_COLOR), cv2.COLOR_BGR2RGB)
            mse = ((luma(back) - luma(tex)) ** 2).mean()
            out[f"{fmt}{q}"] = {"bytes": len(data), "psnr": 10 * np.log10(255.0**2 / max(mse, 1e-9))}
    return out


def speed(scene: Scene) -> dict:
    """Decoding to parameters (Rust core, one core), through the Python decoder, and to pictures;
    encoding's time against the analysis's."""
    header, _actor, packets = encode_clip(scene.clip, Settings(), False, scene.basis)
    stream = header + b"".join(packets)
    n = len(scene.clip.motion)
    t0, reps = time.perf_counter(), 0
    while time.perf_counter() - t0 < 2.0:
        dec = _core.StreamDecoder(True)
        dec.push(stream)
        dec.finish()
        reps += 1
    core_fps = reps * n / (time.perf_counter() - t0)
    t0 = time.perf_counter()
    dec = MotionDecoder(scene.clip.actor)
    frames = dec.push(stream) + dec.finish()
    python_fps = n / (time.perf_counter() - t0)
    size = scene.clip.size
    out = np.empty((size[1], size[0], 3), np.uint8)
    fps = {"decoded": 0.0, "analysed": 0.0}
    for _ in range(3):  # alternated, best of three: the first pass warms the caches
        for label, seq in (("decoded", frames), ("analysed", scene.clip.motion)):
            t0 = time.perf_counter()
            for f in seq:
                scene.puppet.render(f.pose, f.offsets, size, out=out, look=f.look, samples=f.samples)
            fps[label] = max(fps[label], n / (time.perf_counter() - t0))
    picture_fps, synth_fps = fps["decoded"], fps["analysed"]
    t0 = time.perf_counter()
    enc = MotionEncoder(scene.clip.actor, scene.clip.fps, size, Basis(scene.basis.raw[:16]), Settings(), False)
    for m in scene.clip.motion:
        enc.push(m.face, m.lost, m.pose, m.offsets)
    enc.finish()
    encode_seconds = time.perf_counter() - t0
    return {
        "decode_core_fps": core_fps,
        "decode_python_fps": python_fps,
        "decode_pictures_fps": picture_fps,
        "run_synthesis_fps": synth_fps,
        "encode_share_of_analysis": encode_seconds / scene.analysis_seconds,
    }


def fuzz(stream: bytes, count: int, seed: int = 1) -> dict:
    """Mutated copies of ``stream`` (bit flips, cut, dropped and inserted bytes, shuffled
    chunks of bytes) and random bytes through the native decoder: how many were tried and
    decoded without an error escaping."""
    rng = random.Random(seed)
    tried = 0
    for k in range(count):
        data = bytearray(stream) if k % 10 else bytearray(rng.randbytes(rng.randrange(1, 5000)))
        for _ in range(rng.randrange(1, 12)):
            if not data:
                break
            i, how = rng.randrange(len(data)), rng.randrange(5)
            if how == 0:
                data[i] ^= 1 << rng.randrange(8)
            elif how == 1:
                del data[i : i + rng.randrange(1, 200)]
            elif how == 2:
                data[i:i] = rng.randbytes(rng.randrange(1, 50))
            elif how == 3:
                j = rng.randrange(len(data))
                data[i : i + 50], data[j : j + 50] = data[j : j + 50], data[i : i + 50]
            else:
                del data[i:]
        dec = _core.StreamDecoder(bool(k % 2))
        for a in range(0, len(data), 997):
            dec.push(bytes(data[a : a + 997]))
        dec.finish()
        tried += 1
    return {"streams": tried, "crashed": 0}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--videos", default=",".join(VIDEOS))
    ap.add_argument("--classic", default="lp_d0,lp_d3,vr_1", help="videos to run x264 and SVT-AV1 on ('' for none)")
    ap.add_argument("--every", type=int, default=3, help="score every N-th frame")
    ap.add_argument("--fuzz", type=int, default=20000, help="mutated streams fed to the decoder")
    args = ap.parse_args()
    cv2.setNumThreads(1)
    names = args.videos.split(",")
    scenes = {}
    report: dict = {"videos": {}}
    for name in names:
        t0 = time.perf_counter()
        scenes[name] = s = Scene(args.data, name, args.every)
        base = s.quality(s.clip.motion)
        curve = {q: s.coded(Settings(quality=q)) for q in QUALITIES}
        header, _, packets = encode_clip(s.clip, Settings(), True, s.basis)
        at_rate = None
        for q in reversed(range(11)):
            header, _, packets = encode_clip(s.clip, Settings(quality=q), True, s.basis)
            if sum(map(len, packets)) * 8 / 1000 / s.duration <= 1.0:
                at_rate = {"quality": q, **s.coded(Settings(quality=q))}
                break
        report["videos"][name] = {
            "frames": len(s.clip.motion),
            "fps": s.clip.fps,
            "size": s.clip.size,
            "unquantised": {"psnr": base[0], "ssim": base[1]},
            "curve": curve,
            "rate_1": at_rate,
            "lossy_5pct": lossy(s, 0.05),
        }
        print(
            f"{name}: {len(s.clip.motion)} frames, {len(s.masks)} scored, {time.perf_counter() - t0:.0f} s", flush=True
        )
    print(
        f"\n{'video':10s} {'unquant. dB':>11s} "
        + " ".join(f"{'q' + str(q):>17s}" for q in QUALITIES)
        + f" {'--rate 1':>19s}   (motion kbit/s, ΔPSNR dB / ΔSSIM against the unquantised synthesis)"
    )
    for name, v in report["videos"].items():
        u = v["unquantised"]
        delta = lambda c, u=u: f"{c['psnr'] - u['psnr']:+.2f}/{c['ssim'] - u['ssim']:+.4f}"  # noqa: E731
        cells = [f"{c['kbit_s']:5.2f} {delta(c)}" for c in v["curve"].values()]
        r = v["rate_1"]
        cells.append(f"q{r['quality']} {r['kbit_s']:4.2f} {delta(r)}" if r else "-")
        print(f"{name:10s} {u['psnr']:6.2f}/{u['ssim']:.3f} " + " ".join(f"{c:>17s}" for c in cells))
    default = [v["curve"][5] for v in report["videos"].values()]
    print(
        f"\ndefault (quality 5): motion max {max(d['kbit_s'] for d in default):.2f} kbit/s; one-time bytes: header "
        f"{min(d['header_bytes'] for d in default)}-{max(d['header_bytes'] for d in default)}, actor "
        f"{min(d['actor_bytes'] for d in default)}-{max(d['actor_bytes'] for d in default)}"
    )
    print(
        "lossy channel, 5% of packets dropped: "
        + "  ".join(
            f"{n}: {v['lossy_5pct']['concealed']:.0f}/{v['lossy_5pct']['frames']} concealed, "
            f"{v['lossy_5pct']['psnr'] - v['curve'][5]['psnr']:+.2f} dB"
            for n, v in report["videos"].items()
        )
    )

    # representations, at the default quality's steps
    reps = {}
    for name, s in scenes.items():
        others = np.concatenate([o.offsets for n, o in scenes.items() if n != name]) if len(scenes) > 1 else s.offsets
        knots = s.offsets.shape[1]
        variants = {
            "knots directly": (replace(Settings(), coefficients=2 * knots), identity_basis(knots)),
            "other videos' basis 16": (Settings(), Basis.learn(others, 16)),
            "other videos' basis 24": (replace(Settings(), coefficients=24), Basis.learn(others, 24)),
            "own basis 8": (replace(Settings(), coefficients=8), s.basis),
            "own basis 16": (Settings(), s.basis),
            "own basis 24": (replace(Settings(), coefficients=24), s.basis),
        }
        reps[name] = {k: s.coded(st, b) for k, (st, b) in variants.items()}
    report["representations"] = reps
    print(
        f"\n{'representation':24s} {'max kbit/s':>10s} {'mean kbit/s':>11s} {'mean ΔPSNR':>10s} {'mean ΔSSIM':>10s} "
        f"{'worst ΔSSIM':>11s}"
    )
    for k in next(iter(reps.values())):
        rows = [(reps[n][k], report["videos"][n]["unquantised"]) for n in reps]
        print(
            f"{k:24s} {max(r['kbit_s'] for r, _ in rows):10.2f} {np.mean([r['kbit_s'] for r, _ in rows]):11.2f} "
            f"{np.mean([r['psnr'] - u['psnr'] for r, u in rows]):+10.3f} "
            f"{np.mean([r['ssim'] - u['ssim'] for r, u in rows]):+10.4f} "
            f"{min(r['ssim'] - u['ssim'] for r, u in rows):+11.4f}"
        )

    report["classic"] = {}
    for name in filter(None, args.classic.split(",")):
        s = scenes.get(name) or Scene(args.data, name, args.every)
        c = classic(s)
        ours = report["videos"][name]["curve"][5] if name in report["videos"] else s.coded(Settings())
        report["classic"][name] = {**c, "facemime": ours}
        print(
            f"\n{name}: facemime {ours['kbit_s']:.2f} kbit/s {ours['psnr']:.2f} dB SSIM {ours['ssim']:.3f} | "
            + " | ".join(
                f"{k} ({v['quantiser']}, preset {v['preset']}) {v['kbit_s']:.1f} kbit/s {v['psnr']:.2f} dB "
                f"SSIM {v['ssim']:.3f}: {v['kbit_s'] / ours['kbit_s']:.0f}x facemime's rate"
                for k, v in c.items()
            ),
            flush=True,
        )

    first = scenes[names[0]]
    report["texture"] = texture_sizes(first)
    print(
        f"\ntexture of {names[0]}'s actor ({first.clip.actor.texture.shape[1]}x{first.clip.actor.texture.shape[0]}): "
        + ", ".join(
            f"{k} {v['bytes']} B {v['psnr']:.1f} dB" if isinstance(v, dict) else f"{k} {v} B"
            for k, v in report["texture"].items()
        )
    )
    cpus = os.sched_getaffinity(0)
    os.sched_setaffinity(0, {min(cpus)})
    try:
        longest = max(scenes.values(), key=lambda s: len(s.clip.motion))
        report["speed"] = {"video": longest.name, **speed(longest)}
    finally:
        os.sched_setaffinity(0, cpus)
    sp = report["speed"]
    print(
        f"\nspeed on one core ({sp['video']}): decoding to parameters {sp['decode_core_fps']:.0f} frames/s "
        f"(Rust core), {sp['decode_python_fps']:.0f} through MotionDecoder; to pictures "
        f"{sp['decode_pictures_fps']:.0f} frames/s against run's synthesis {sp['run_synthesis_fps']:.0f}; "
        f"encoding {100 * sp['encode_share_of_analysis']:.2f}% of the analysis"
    )
    header, _actor, packets = encode_clip(first.clip, Settings(), True, first.basis)
    report["fuzz"] = fuzz(header + b"".join(packets), args.fuzz)
    print(f"fuzz: {report['fuzz']['streams']} mutated or random streams decoded, none crashed")
    print(json.dumps(report, default=float))


if __name__ == "__main__":
    main()
