"""Build facemime's generic head model (python/facemime/model/data/generic_head.json).

The model is *measured*, not copied from any model file: the frontal first frames of the six
shared videos (../shared/data/video/*.landmarks.npz, MediaPipe Face Mesh points with depth) are
aligned by generalised Procrustes, averaged, made left/right symmetric, scaled to millimetres
(outer eye corners 90 mm apart) and thinned to the vertices listed below. Triangles come from a
constrained Delaunay triangulation of the frontal view that keeps every feature contour as a
chain of edges; the mouth opening is left out (the inner lip curves close it at rest).

Run from the repository root (needs numpy, scipy and the `triangle` package, dev-time only):

    python tools/build_generic_head.py ../shared/data/video
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import triangle
from scipy.spatial import cKDTree

IOD_MM = 90.0  # outer-eye-corner distance of the model, millimetres

# Model groups: name -> MediaPipe Face Mesh indices, in model order.
CONTOURS = {  # ordered image-left -> image-right, as the snake contours (shared/data/README.md)
    "mouth_outer_upper": [61, 185, 40, 39, 37, 0, 267, 269, 270, 409, 291],
    "mouth_outer_lower": [61, 146, 91, 181, 84, 17, 314, 405, 321, 375, 291],
    "mouth_inner_upper": [78, 191, 80, 81, 82, 13, 312, 311, 310, 415, 308],
    "mouth_inner_lower": [78, 95, 88, 178, 87, 14, 317, 402, 318, 324, 308],
    "brow_left_upper": [336, 296, 334, 293, 300],
    "brow_left_lower": [285, 295, 282, 283, 276],
    "brow_right_upper": [70, 63, 105, 66, 107],
    "brow_right_lower": [46, 53, 52, 65, 55],
}
EYES = {  # closed rings, image-left corner first, along the upper lid then back along the lower
    "eye_right": [33, 160, 159, 158, 133, 153, 145, 144],
    "eye_left": [362, 385, 386, 387, 263, 373, 374, 380],
}
NOSE = [168, 6, 197, 195, 5, 4, 1, 2, 98, 327, 64, 294, 48, 278, 129, 358]
# Face outline, every other point of Face Mesh's silhouette ring, clockwise from the forehead top.
OUTLINE = [10, 297, 284, 389, 454, 361, 397, 379, 400, 152, 176, 150, 172, 132, 234, 162, 54, 67]
INTERIOR = [9, 151, 108, 337, 50, 280, 205, 425, 199, 18]


def load_frontal_shapes(video_dir: Path) -> list[np.ndarray]:
    """First valid frame of every video as (478, 3) model-like coordinates (x right, y up, z out)."""
    shapes = []
    for f in sorted(video_dir.glob("*.landmarks.npz")):
        d = np.load(f)
        i = int(np.flatnonzero(d["valid"])[0])
        p = d["landmarks"][i].astype(np.float64)
        shapes.append(np.column_stack([p[:, 0], -p[:, 1], -p[:, 2]]))
    return shapes


def similarity_align(src: np.ndarray, dst: np.ndarray) -> np.ndarray:
    """src moved onto dst by the least-squares rotation, uniform scale and translation."""
    ms, md = src.mean(0), dst.mean(0)
    a, b = src - ms, dst - md
    u, s, vt = np.linalg.svd(a.T @ b)
    d = np.sign(np.linalg.det(u @ vt))
    corr = np.diag([1, 1, d])
    r = u @ corr @ vt
    scale = (s * np.diag(corr)).sum() / (a**2).sum()
    return scale * a @ r + md


def canonical_frame(p: np.ndarray) -> np.ndarray:
    """Origin between the outer eye corners, x from the subject's right eye to the left one,
    y up through the forehead, z out of the face; scaled to IOD_MM."""
    right, left = p[33], p[263]
    x = (left - right) / np.linalg.norm(left - right)
    up = p[10] - p[152]
    y = up - (up @ x) * x
    y /= np.linalg.norm(y)
    z = np.cross(x, y)
    r = np.stack([x, y, z])
    return (p - (left + right) / 2) @ r.T * (IOD_MM / np.linalg.norm(left - right))


def mean_shape(shapes: list[np.ndarray]) -> np.ndarray:
    mean = canonical_frame(shapes[0])
    for _ in range(5):
        aligned = [similarity_align(s, mean) for s in shapes]
        mean = canonical_frame(np.mean(aligned, axis=0))
    return mean


def symmetrise(p: np.ndarray) -> np.ndarray:
    """Average each point with the mirror image of its mirror partner (nearest reflected point)."""
    mirrored = p * [-1, 1, 1]
    partner = cKDTree(p).query(mirrored)[1]
    sym = (p + mirrored[partner]) / 2
    on_axis = partner == np.arange(len(p))
    sym[on_axis, 0] = 0.0
    return sym


def triangulate(xy: np.ndarray, segments: list[tuple[int, int]], holes: list[np.ndarray]) -> np.ndarray:
    tri = triangle.triangulate(
        {"vertices": xy, "segments": np.array(segments), "holes": np.array(holes)}, "p"
    )
    if len(tri["vertices"]) != len(xy):
        raise SystemExit("triangulation added Steiner points: a constraint crosses another")
    t = tri["triangles"]
    a, b, c = xy[t[:, 0]], xy[t[:, 1]], xy[t[:, 2]]
    area = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    t[area < 0] = t[area < 0][:, [0, 2, 1]]  # counter-clockwise seen from +z: outward
    return t


def smoothstep(a: float, b: float, x: np.ndarray) -> np.ndarray:
    t = np.clip((x - a) / (b - a), 0.0, 1.0)
    return t * t * (3 - 2 * t)


def deformation_units(v: np.ndarray, g: dict[str, list[int]]) -> dict[str, dict]:
    """Displacements (mm) at activation 1 of each deformation unit."""
    n = len(v)
    x, y = v[:, 0], v[:, 1]
    corner_r, corner_l = g["mouth_outer_upper"][0], g["mouth_outer_upper"][-1]
    mouth_y = (v[corner_r, 1] + v[corner_l, 1]) / 2
    half_w = (v[corner_l, 0] - v[corner_r, 0]) / 2
    chin_y = v[g["face_outline"], 1].min()
    lower_lip = set(g["mouth_outer_lower"][1:-1] + g["mouth_inner_lower"][1:-1])
    upper_lip = set(g["mouth_outer_upper"][1:-1] + g["mouth_inner_upper"][1:-1])
    corners = {corner_r, corner_l, g["mouth_inner_upper"][0], g["mouth_inner_upper"][-1]}
    lips = lower_lip | upper_lip | corners
    units: dict[str, tuple[str, np.ndarray]] = {}

    d = np.zeros((n, 3))
    below = smoothstep(mouth_y, mouth_y - 0.35 * (mouth_y - chin_y), y) * np.exp(-((x / (2.2 * half_w)) ** 2))
    for i in range(n):
        w = 1.0 if i in lower_lip else 0.45 if i in corners else below[i]
        d[i] = w * np.array([0.0, -12.0, -3.0])
    units["jaw_drop"] = ("the jaw opens: lower lip and chin move down (12 mm) and back", d)

    d = np.zeros((n, 3))
    for i in lips:
        d[i, 0] = 6.0 * np.clip(x[i] / half_w, -1, 1)
    units["lip_stretch"] = ("the mouth corners pull outwards (6 mm each), the lips follow", d)

    d = np.zeros((n, 3))
    for i in lips:
        d[i, 1] = 4.0 * np.clip(abs(x[i]) / half_w, 0, 1) ** 2
    d[:, 1] += 2.0 * np.exp(-(((x - np.sign(x) * half_w * 1.3) / 10) ** 2 + ((y - mouth_y) / 10) ** 2)) * (np.abs(x) > 0)
    units["lip_corner_raise"] = ("the mouth corners move up 4 mm (a smile); negative values pull them down", d)

    d = np.zeros((n, 3))
    for i in upper_lip:
        d[i, 1] = 3.5 * (1 - 0.6 * np.clip(abs(x[i]) / half_w, 0, 1))
    units["upper_lip_raise"] = ("the upper lip lifts (3.5 mm at the centre)", d)

    d = np.zeros((n, 3))
    brows = {i for k in g if k.startswith("brow_") for i in g[k]}
    brow_y = v[sorted(brows), 1].mean()
    for i in range(n):
        if i in brows:
            d[i, 1] = 7.0
        elif y[i] > brow_y:
            d[i, 1] = 3.0 * np.exp(-((y[i] - brow_y) / 25) ** 2)
        elif y[i] > brow_y - 18 and i not in set(g["eye_left"] + g["eye_right"]):
            d[i, 1] = 2.0 * smoothstep(brow_y - 18, brow_y, y[i])
    units["brow_raise"] = ("both brows lift 7 mm, the forehead follows; negative values lower them", d)

    d = np.zeros((n, 3))
    for eye in ("eye_right", "eye_left"):
        ring = g[eye]
        upper, lower = ring[1:4], ring[7:4:-1]  # lids, each ordered from the image-left corner
        for u, lo in zip(upper, lower):
            d[u] = v[lo] - v[u]
            d[u, 2] = 0.0
    units["eyes_closed"] = ("the upper lids come down onto the lower lids", d)

    return {
        name: {
            "description": text,
            "displacements": [[i, *np.round(disp[i], 3).tolist()] for i in range(n) if np.abs(disp[i]).max() > 1e-3],
        }
        for name, (text, disp) in units.items()
    }


def build(video_dir: Path) -> dict:
    p = symmetrise(mean_shape(load_frontal_shapes(video_dir)))
    chosen: list[int] = []
    groups_mp: dict[str, list[int]] = {}
    for name, idx in {**CONTOURS, **EYES, "nose": NOSE, "face_outline": OUTLINE, "interior": INTERIOR}.items():
        groups_mp[name] = idx
        chosen += [i for i in idx if i not in chosen]
    index = {mp: k for k, mp in enumerate(chosen)}
    groups = {name: [index[i] for i in idx] for name, idx in groups_mp.items() if name != "interior"}
    v = p[chosen].copy()

    # Constraints: every feature contour, the eye rings and the outline ring.
    segs: set[tuple[int, int]] = set()
    for name in list(CONTOURS) + ["face_outline", "eye_right", "eye_left"]:
        ring = groups[name]
        closed = name not in CONTOURS
        for a, b in zip(ring, ring[1:] + (ring[:1] if closed else [])):
            segs.add((min(a, b), max(a, b)))
    # The mouth opening is a hole; make it open by a millimetre so the triangulator sees it.
    xy = v[:, :2].copy()
    xy[groups["mouth_inner_upper"][1:-1], 1] += 0.6
    xy[groups["mouth_inner_lower"][1:-1], 1] -= 0.6
    mouth_centre = xy[groups["mouth_inner_upper"][5]] / 2 + xy[groups["mouth_inner_lower"][5]] / 2
    tris = triangulate(xy, sorted(segs), [mouth_centre])

    # Rest shape: lips closed along the mean of the two inner curves.
    iu, il = groups["mouth_inner_upper"], groups["mouth_inner_lower"]
    mid = (v[iu] + v[il]) / 2
    v[iu], v[il] = mid, mid
    v[il[1:-1], 1] -= 0.05  # closed, but not zero-width: the lower curve sits just below
    lo, hi = v[:, :2].min(0), v[:, :2].max(0)
    margin = 0.04 * (hi - lo)
    uv = np.column_stack([(v[:, 0] - lo[0] + margin[0]) / (hi[0] - lo[0] + 2 * margin[0]),
                          (hi[1] + margin[1] - v[:, 1]) / (hi[1] - lo[1] + 2 * margin[1])])
    return {
        "format": "facemime.head/1",
        "name": "facemime generic head",
        "unit": "mm",
        "axes": "right-handed: x to the subject's left, y up, z towards the camera; origin between the outer eye corners",
        "source": "mean of the first frames of six face videos (MediaPipe Face Mesh points with depth), "
                  "Procrustes-aligned, symmetrised, thinned; built by tools/build_generic_head.py",
        "vertices": np.round(v, 3).tolist(),
        "triangles": tris.tolist(),
        "uv": np.round(uv, 5).tolist(),
        "groups": groups,
        "deformation_units": deformation_units(v, groups),
    }


def main() -> None:
    video_dir = Path(sys.argv[1] if len(sys.argv) > 1 else "../shared/data/video")
    model = build(video_dir)
    out = Path(__file__).resolve().parents[1] / "python/facemime/model/data/generic_head.json"
    text = json.dumps(model, indent=None, separators=(",", ":"))
    # One vertex / triangle / entry per line keeps the file readable and its diffs small.
    text = text.replace("],[", "],\n[").replace('},"', '},\n"')
    out.write_text(text + "\n")
    print(f"{out}: {len(model['vertices'])} vertices, {len(model['triangles'])} triangles, "
          f"{len(model['deformation_units'])} deformation units")


if __name__ == "__main__":
    main()
