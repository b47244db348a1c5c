"""Rendering speed: the textured generic head through facemime's renderer against the common
OpenCV approach (per triangle: boundingRect, getAffineTransform, warpAffine, mask composite, as
in the face-morphing tutorials), and a leaner OpenCV variant (uint8 mask, copyto), all measured
in the same run, on one core.

    python benchmarks/render.py [--seconds 2]

Each frame: projection of the posed head (the pose changes every frame), background fill and
the textured render. The background is a grey colour filled in place, as ``render_mesh`` does;
copying a background image instead also pulls a second frame-sized buffer through the cache,
which on a 2 MB L2 evicts much of the texture (about a quarter slower for facemime at 640x480).
The face fills most of the frame. The last line of output is one JSON object for comparisons
over time.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import time

import cv2
import numpy as np

from facemime.head import generic_head, painted_texture
from facemime.render import fill, render_mesh_into
from facemime.types.pose import Pose, project

SIZES = ((128, 128), (640, 480))
BACKGROUND = 30  # grey level


def visible_far_to_near(points: np.ndarray, depth: np.ndarray, triangles: np.ndarray) -> np.ndarray:
    """Front-facing triangles (counter-clockwise as seen), far to near: what facemime draws."""
    a, b, c = points[triangles[:, 0]], points[triangles[:, 1]], points[triangles[:, 2]]
    area2 = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    visible = np.flatnonzero(area2 < 0)
    return visible[np.argsort(depth[triangles[visible]].mean(axis=1))]


def opencv_common(
    out: np.ndarray,
    texture: np.ndarray,
    uv: np.ndarray,
    points: np.ndarray,
    depth: np.ndarray,
    triangles: np.ndarray,
    interpolation: int,
) -> None:
    """The common per-triangle warp: float32 mask from fillConvexPoly, warpAffine of the source
    rectangle, composite ``dst * (1 - mask) + warped * mask`` (``out`` is float32)."""
    th, tw = texture.shape[:2]
    src_all = (uv * [tw, th] - 0.5).astype(np.float32)
    h, w = out.shape[:2]
    for f in visible_far_to_near(points, depth, triangles):
        t1, t2 = src_all[triangles[f]], points[triangles[f]].astype(np.float32)
        r1, r2 = cv2.boundingRect(t1), cv2.boundingRect(t2)
        x, y, rw, rh = r2
        if x < 0 or y < 0 or x + rw > w or y + rh > h or rw == 0 or rh == 0:
            continue  # the tutorials' version needs the rectangle inside the image
        t1r = (t1 - r1[:2]).astype(np.float32)
        t2r = (t2 - r2[:2]).astype(np.float32)
        mask = np.zeros((rh, rw, 3), np.float32)
        cv2.fillConvexPoly(mask, np.int32(t2r), (1.0, 1.0, 1.0), 16, 0)
        crop = texture[r1[1] : r1[1] + r1[3], r1[0] : r1[0] + r1[2]]
        warped = cv2.warpAffine(
            crop, cv2.getAffineTransform(t1r, t2r), (rw, rh), flags=interpolation, borderMode=cv2.BORDER_REFLECT_101
        )
        out[y : y + rh, x : x + rw] = out[y : y + rh, x : x + rw] * (1.0 - mask) + warped * mask


def opencv_lean(
    out: np.ndarray,
    texture: np.ndarray,
    uv: np.ndarray,
    points: np.ndarray,
    depth: np.ndarray,
    triangles: np.ndarray,
    interpolation: int,
) -> None:
    """The same warp with a uint8 mask and ``np.copyto`` into a uint8 image: a stronger peer."""
    th, tw = texture.shape[:2]
    src_all = (uv * [tw, th] - 0.5).astype(np.float32)
    h, w = out.shape[:2]
    for f in visible_far_to_near(points, depth, triangles):
        src = src_all[triangles[f]]
        dst = points[triangles[f]].astype(np.float32)
        x, y, rw, rh = cv2.boundingRect(dst)
        x0, y0, x1, y1 = max(x, 0), max(y, 0), min(x + rw, w), min(y + rh, h)
        if x1 <= x0 or y1 <= y0:
            continue
        sx, sy, sw, sh = cv2.boundingRect(src)
        sx, sy = max(sx, 0), max(sy, 0)
        crop = texture[sy : sy + sh, sx : sx + sw]
        m = cv2.getAffineTransform((src - [sx, sy]).astype(np.float32), (dst - [x0, y0]).astype(np.float32))
        warped = cv2.warpAffine(crop, m, (x1 - x0, y1 - y0), flags=interpolation, borderMode=cv2.BORDER_REFLECT_101)
        mask = np.zeros((y1 - y0, x1 - x0), np.uint8)
        cv2.fillConvexPoly(mask, np.round((dst - [x0, y0]) * 16).astype(np.int32), 1, cv2.LINE_8, 4)
        np.copyto(out[y0:y1, x0:x1], warped, where=mask[..., None].astype(bool))


def frames_per_second(draw, seconds: float) -> float:
    draw(0)  # warm-up
    n, start = 0, time.perf_counter()
    while (elapsed := time.perf_counter() - start) < seconds or n < 5:
        draw(n)
        n += 1
    return n / elapsed


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seconds", type=float, default=2.0, help="time per measurement")
    args = parser.parse_args()
    cv2.setNumThreads(1)  # one core for both
    head = generic_head()
    texture = painted_texture(head, 512)
    results: dict[str, float] = {}
    print(
        f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} cores visible; "
        f"one core used; {len(head.vertices)} vertices, {len(head.triangles)} triangles, 512x512 texture"
    )
    for w, h in SIZES:
        base = Pose.framing(head.vertices, (w, h), 0.95)
        out = np.empty((h, w, 3), np.uint8)
        poses = [
            Pose(
                yaw=8 * np.sin(i / 7),
                pitch=4 * np.sin(i / 5),
                roll=3 * np.sin(i / 9),
                scale=base.scale,
                tx=base.tx,
                ty=base.ty,
            )
            for i in range(64)
        ]
        out_f = np.empty((h, w, 3), np.float32)
        for filt, interp in (("nearest", cv2.INTER_NEAREST), ("bilinear", cv2.INTER_LINEAR)):

            def ours(i: int, poses: list = poses, out: np.ndarray = out, filt: str = filt) -> None:
                pts, z = project(head.vertices, poses[i % 64])
                fill(out, BACKGROUND)
                render_mesh_into(out, texture, head.uv, pts, z, head.triangles, filter=filt)

            def common(i: int, poses: list = poses, out_f: np.ndarray = out_f, interp: int = interp) -> None:
                pts, z = project(head.vertices, poses[i % 64])
                out_f.fill(BACKGROUND)
                opencv_common(out_f, texture, head.uv, pts, z, head.triangles, interp)

            def lean(i: int, poses: list = poses, out: np.ndarray = out, interp: int = interp) -> None:
                pts, z = project(head.vertices, poses[i % 64])
                fill(out, BACKGROUND)
                opencv_lean(out, texture, head.uv, pts, z, head.triangles, interp)

            fps = frames_per_second(ours, args.seconds)
            fps_cv, fps_lean = frames_per_second(common, args.seconds), frames_per_second(lean, args.seconds)
            key = f"{w}x{h}_{filt}"
            results[f"fps_{key}"] = round(fps, 1)
            results[f"fps_opencv_{key}"] = round(fps_cv, 1)
            results[f"fps_opencv_lean_{key}"] = round(fps_lean, 1)
            results[f"ratio_{key}"] = round(fps / fps_cv, 2)
            results[f"ratio_lean_{key}"] = round(fps / fps_lean, 2)
            print(
                f"{w}x{h} {filt:8s}  facemime {fps:8.1f} frames/s | opencv {fps_cv:7.1f} ({fps / fps_cv:5.1f}x) "
                f"| opencv lean {fps_lean:7.1f} ({fps / fps_lean:5.1f}x)"
            )
    results["ratio_vs_opencv"] = results["ratio_640x480_bilinear"]
    print(json.dumps(results))


if __name__ == "__main__":
    main()
