"""How much a mesh that registers on the face could add at the receiver (issue 63): each shared
video's face drawn as ``facemime decode`` draws it, beside an oracle whose head lands exactly on
the reference landmarks of every frame.

- **decode**: ``encode`` with its defaults then ``decode`` (as ``benchmarks/receiver.py``);
- **registered**: the actor fitted on frame 0 as ``run`` fits it, each of its vertices carried
  by the reference Face Mesh points around it (barycentric coordinates in the Delaunay
  triangulation of frame 0's reference points, applied to frame t's), the face and its scene
  drawn with the actor's texture and key frame as the synthesis draws them; no eyes repainted
  and no mouth interior drawn (the key frame's show).

Luma PSNR (dB, BT.601 Y) inside the face (the hull of the reference points) on every
``--every``-th frame after the first with a reference face. The gap between the two is what
registration alone can add; what remains below the real frame is the appearance (lighting, the
mouth's interior, the eyes).

    python benchmarks/registration.py [--data ../shared/data] [--videos lp_d0,vr_1] [--every 3]

Prints a table, the means, and one JSON line with every figure.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import json
import sys
from pathlib import Path

import cv2
import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from facemime.animate.synth import key_frame, scene_mesh
from facemime.fit.actor import fit_actor
from facemime.io.video import VideoReader
from facemime.render.raster import render_mesh_into
from facemime.types.pose import project
from receiver import luma, masks, psnr, video_arguments
from receiver import measure as decode_scores


def delaunay(points: np.ndarray) -> np.ndarray:
    """(T, 3) vertex indices of the Delaunay triangles of ``points`` (N, 2) px."""
    lo, hi = points.min(axis=0) - 50, points.max(axis=0) + 50
    subdiv = cv2.Subdiv2D((int(lo[0]), int(lo[1]), int(hi[0] - lo[0]) + 1, int(hi[1] - lo[1]) + 1))
    for p in points:
        subdiv.insert((float(p[0]), float(p[1])))
    corners = subdiv.getTriangleList().reshape(-1, 3, 2)
    gap = np.linalg.norm(corners[:, :, None, :] - points[None, None], axis=3)
    return gap.argmin(axis=2)[gap.min(axis=2).max(axis=1) < 1e-3]


def carry(points: np.ndarray, triangles: np.ndarray, at: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """For each of ``at`` (M, 2) px: the triangle of ``points`` holding it (or, outside them all,
    the one it is least outside of) and its barycentric weights there: (M,) ints, (M, 3)."""
    a, b, c = (points[triangles[:, k]] for k in range(3))
    area = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    p = at[:, None, :]
    wa = ((c[:, 0] - b[:, 0]) * (p[..., 1] - b[:, 1]) - (c[:, 1] - b[:, 1]) * (p[..., 0] - b[:, 0])) / area
    wb = ((a[:, 0] - c[:, 0]) * (p[..., 1] - c[:, 1]) - (a[:, 1] - c[:, 1]) * (p[..., 0] - c[:, 0])) / area
    wc = 1.0 - wa - wb
    best = np.minimum(np.minimum(wa, wb), wc).argmax(axis=1)
    rows = np.arange(len(at))
    return best, np.column_stack([wa[rows, best], wb[rows, best], wc[rows, best]])


def registered(video: Path, reference: Path, every: int) -> float:
    """The registered oracle's mean face PSNR-Y over the scored frames, dB."""
    ref = np.load(reference)
    with VideoReader(video) as reader:
        frames = list(reader)
    actor = fit_actor(frames[0], video.name)[0]
    scene = scene_mesh(actor)
    key = key_frame(actor, scene)
    first = ref["landmarks"][0][:468].astype(np.float64)
    triangles = delaunay(first[:, :2])
    holder, weights = carry(first[:, :2], triangles, project(actor.model.vertices, actor.pose)[0])
    h, w = frames[0].shape[:2]
    scores = []
    for i in range(every, len(frames), every):
        if not ref["valid"][i]:
            continue
        marks = ref["landmarks"][i][:468].astype(np.float64)
        corners = marks[triangles[holder]]  # (N, 3, 3): each vertex's triangle's points
        points = (weights[:, :, None] * corners[:, :, :2]).sum(axis=1)
        depth = -(weights * corners[:, :, 2]).sum(axis=1)  # nearer is larger
        picture = np.zeros_like(frames[i])
        scene.draw(picture, key, points[scene.anchors])
        render_mesh_into(picture, actor.texture, actor.model.uv, points, depth, actor.model.triangles, cull=False)
        face = masks(ref["landmarks"][i].astype(np.float64), float(ref["iod"][i]), (h, w))["face"]
        scores.append(psnr(luma(picture), luma(frames[i]), face))
    return float(np.mean(scores))


def main() -> None:
    args = video_arguments(__doc__)
    cv2.setNumThreads(1)
    results = {}
    print(f"{'video':10s} {'decode':>7s} {'registered':>10s}  (face, dB luma PSNR)")
    for name in args.videos.split(","):
        data = args.data / "video"
        video, reference = data / f"{name}.mp4", data / f"{name}.landmarks.npz"
        r = {
            "decode": decode_scores(video, reference, args.every)["face"],
            "registered": registered(video, reference, args.every),
        }
        results[name] = r
        print(f"{name:10s} {r['decode']:7.2f} {r['registered']:10.2f}")
    means = {k: float(np.mean([r[k] for r in results.values()])) for k in ("decode", "registered")}
    print(f"{'mean':10s} {means['decode']:7.2f} {means['registered']:10.2f}")
    print(json.dumps({"videos": results, "mean": means}))


if __name__ == "__main__":
    main()
