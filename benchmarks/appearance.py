"""facemime as a codec is measured (issue 55): per shared video, the synthesised face's fidelity
against its total rate, as a curve over the appearance budget, beside x264 and SVT-AV1 at their
lowest reachable rates in the same run.

Per video: the clip is analysed once (actor fitted on frame 0), its motion and look encoded at the
default quality (``encode_clip``), and for each appearance budget the appearance updates chosen
(``with_appearance``, reading the video again); the whole stream is then decoded as a receiver
would (``MotionDecoder``, ``Appearance``) and drawn in the actor's scene. Scored on every
``--every``-th frame from 1 with a reference face: luma (BT.601) PSNR and SSIM (11×11 Gaussian
window) inside the face (the hull of the reference Face Mesh points). The rate is the motion's
and the updates' (chunks, framing included) per second of clip, after the actor (sent once;
its bytes are printed beside). The classic codecs: ``classic_codecs.floor`` (slowest presets,
one key frame, the whole MP4's bytes), scored on the same frames and region.

    python benchmarks/appearance.py [--data ../shared/data] [--videos lp_d0,vr_1] [--budgets 0,2,4,8] [--every 3]

Prints a table per video and, last, one JSON line with every figure.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("SVT_LOG", "1")

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import classic_codecs
from facemime.animate.deform import Deformer
from facemime.animate.synth import Puppet
from facemime.codec.appearance import Appearance
from facemime.codec.clip import analyse, encode_clip, with_appearance
from facemime.codec.decoder import MotionDecoder
from facemime.codec.stream import Settings
from facemime.io.video import VideoReader
from facemime.types.head import model_iod
from fidelity import regions, scores

VIDEOS = ("lp_d0", "lp_d3", "lp_d6", "lp_d12", "mt_sun", "mt_yongen", "st_aoc", "st_kh", "vr_1", "vr_2")
ROOT = Path(__file__).resolve().parents[1]


def face_scores(pictures: dict[int, np.ndarray], real: dict[int, np.ndarray], masks: dict[int, dict]) -> list[float]:
    """[mean face luma PSNR, mean face SSIM] over the scored frames."""
    s = np.array([scores(pictures[i], real[i], masks[i])["face"] for i in masks])
    return [float(s[:, 0].mean()), float(s[:, 1].mean())]


def one_video(path: Path, ref: dict, budgets: list[float], every: int) -> dict:
    clip = analyse(path)
    valid, landmarks, iod = ref["valid"], ref["landmarks"], ref["iod"]
    n = len(clip.motion)
    chosen = [i for i in range(1, n, every) if valid[i]]
    real = {i: f for i, f in enumerate(VideoReader(path)) if i in set(chosen)}
    masks = {i: {"face": regions(landmarks[i], float(iod[i]), real[i].shape[:2])["face"]} for i in chosen}
    settings = Settings()
    header, actor_chunk, packets = encode_clip(clip, settings, True)
    seconds = n / clip.fps
    motion_kbit = sum(map(len, packets)) * 8 / 1000 / seconds
    curve = []
    for budget in budgets:
        chunks = with_appearance(path, clip, header, actor_chunk, packets, settings, budget)[0] if budget else packets
        decoder = MotionDecoder()
        frames = decoder.push(header + actor_chunk + b"".join(chunks)) + decoder.finish()
        held = decoder.actor
        puppet = Puppet(held, Deformer(held.model).feature_sizes(), model_iod(held.model), decoder.reference())
        updates = Appearance(held.texture, decoder.appearance, decoder.appearance_after)
        pictures = {}
        for f in frames:
            if updates.due(f.index):
                puppet.retexture(updates.texture)
            if f.index in masks:
                pictures[f.index] = puppet.render(f.pose, f.offsets, clip.size, look=f.look, samples=f.samples).copy()
        kbit = sum(map(len, chunks)) * 8 / 1000 / seconds
        curve.append(
            {
                "budget": budget,
                "kbit_s": kbit,
                "appearance_kbit_s": kbit - motion_kbit,
                "updates": updates.applied,
                "face": face_scores(pictures, real, masks),
            }
        )
    frames_rgb = list(VideoReader(path))
    classic = {}
    for codec in ("libx264", "libsvtav1"):
        floor = classic_codecs.floor(frames_rgb, clip.fps, codec)
        classic[codec] = {
            "kbit_s": floor["kbit_s"],
            "quantiser": floor["quantiser"],
            "face": face_scores({i: floor["frames"][i] for i in chosen}, real, masks),
        }
    return {"actor_bytes": len(actor_chunk), "motion_kbit_s": motion_kbit, "curve": curve, "classic": classic}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--videos", default=",".join(VIDEOS))
    ap.add_argument("--budgets", default="0,2,4,8,16", help="appearance budgets, kbit/s")
    ap.add_argument("--every", type=int, default=3)
    args = ap.parse_args()
    budgets = [float(b) for b in args.budgets.split(",")]
    rows = {}
    for name in args.videos.split(","):
        ref = dict(np.load(args.data / "video" / f"{name}.landmarks.npz"))
        r = rows[name] = one_video(args.data / "video" / f"{name}.mp4", ref, budgets, args.every)
        points = "  ".join(
            f"{p['budget']:g}: {p['kbit_s']:.2f} kbit/s {p['face'][0]:.2f} dB {p['face'][1]:.3f} "
            f"({p['updates']} updates)"
            for p in r["curve"]
        )
        classic = "  ".join(
            f"{c}: {v['kbit_s']:.1f} kbit/s {v['face'][0]:.2f} dB {v['face'][1]:.3f}" for c, v in r["classic"].items()
        )
        print(f"{name:10s} actor {r['actor_bytes']} B | {points} | {classic}", flush=True)
    print(json.dumps(rows, default=float))


if __name__ == "__main__":
    main()
