"""Build facemime's generic head model (python/facemime/head/data/generic_head.json).

The model is *measured*, not copied from any model file: the frontal first frames of the six
shared videos (../shared/data/video/*.landmarks.npz, MediaPipe Face Mesh points with depth) are
aligned by generalised Procrustes, averaged, made left/right symmetric, scaled to millimetres
(outer eye corners 90 mm apart) and thinned to the vertices listed below. Triangles come from a
constrained Delaunay triangulation of the frontal view that keeps every feature contour as a
chain of edges; the mouth opening is left out (the inner lip curves close it at rest).

Its deformation units are facemime's expression controls (facemime.animate.expressions: ARKit
names, each a knot pattern spread by the synthesis's deformation), computed from the model as
stored.

Run from the repository root (needs numpy, scipy and the `triangle` package, dev-time only, and
facemime importable):

    python tools/build_generic_head.py ../shared/data/video

or, to recompute only the deformation units of the shipped file (after the controls change):

    python tools/build_generic_head.py --units-only
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

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
    from scipy.spatial import cKDTree

    mirrored = p * [-1, 1, 1]
    partner = cKDTree(p).query(mirrored)[1]
    sym = (p + mirrored[partner]) / 2
    on_axis = partner == np.arange(len(p))
    sym[on_axis, 0] = 0.0
    return sym


def triangulate(xy: np.ndarray, segments: list[tuple[int, int]], holes: list[np.ndarray]) -> np.ndarray:
    import triangle

    tri = triangle.triangulate({"vertices": xy, "segments": np.array(segments), "holes": np.array(holes)}, "p")
    if len(tri["vertices"]) != len(xy):
        raise SystemExit("triangulation added Steiner points: a constraint crosses another")
    t = tri["triangles"]
    a, b, c = xy[t[:, 0]], xy[t[:, 1]], xy[t[:, 2]]
    area = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    t[area < 0] = t[area < 0][:, [0, 2, 1]]  # counter-clockwise seen from +z: outward
    return t


def deformation_units(v: np.ndarray, triangles: np.ndarray, g: dict[str, list[int]]) -> dict[str, dict]:
    """The model's expression controls (facemime.animate.expressions, ARKit names) as deformation
    units: each one's vertex displacements (mm) at weight 1, the synthesis's own deformation of
    its knot pattern (the blinks: the lids closed), with its description. ``v``: the vertices as
    the file stores them (rounded), so that the units are those facemime computes from the file."""
    from facemime.animate.expressions import DESCRIPTIONS, Expressions
    from facemime.types.head import HeadModel

    model = HeadModel(v, np.asarray(triangles, np.int64), None, {k: np.asarray(i, np.int64) for k, i in g.items()})
    e = Expressions.of(model)
    return {
        name: {
            "description": DESCRIPTIONS[name],
            "displacements": [[i, *np.round(d[i], 3).tolist()] for i in range(len(v)) if np.abs(d[i]).max() > 1e-3],
        }
        for name, d in zip(e.names, e.fields)
    }


def update_units(path: Path) -> None:
    """Recompute only the deformation units of the model file at ``path`` (from its vertices,
    triangles and groups), leaving the rest byte for byte: for when the controls change."""
    model = json.loads(path.read_text())
    model["deformation_units"] = deformation_units(
        np.array(model["vertices"]), np.array(model["triangles"]), model["groups"]
    )
    write(model, path)


def write(model: dict, out: Path) -> None:
    text = json.dumps(model, indent=None, separators=(",", ":"))
    # One vertex / triangle / entry per line keeps the file readable and its diffs small.
    text = text.replace("],[", "],\n[").replace('},"', '},\n"')
    out.write_text(text + "\n")
    print(
        f"{out}: {len(model['vertices'])} vertices, {len(model['triangles'])} triangles, "
        f"{len(model['deformation_units'])} deformation units"
    )


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
    uv = np.column_stack(
        [
            (v[:, 0] - lo[0] + margin[0]) / (hi[0] - lo[0] + 2 * margin[0]),
            (hi[1] + margin[1] - v[:, 1]) / (hi[1] - lo[1] + 2 * margin[1]),
        ]
    )
    return {
        "format": "facemime.head/1",
        "name": "facemime generic head",
        "unit": "mm",
        "axes": "right-handed: x to the subject's left, y up, z towards the camera; origin between the outer "
        "eye corners",
        "source": "mean of the first frames of six face videos (MediaPipe Face Mesh points with depth), "
        "Procrustes-aligned, symmetrised, thinned; built by tools/build_generic_head.py",
        "vertices": np.round(v, 3).tolist(),
        "triangles": tris.tolist(),
        "uv": np.round(uv, 5).tolist(),
        "groups": groups,
        "deformation_units": deformation_units(np.round(v, 3), tris, groups),
    }


def main() -> None:
    out = Path(__file__).resolve().parents[1] / "python/facemime/head/data/generic_head.json"
    if sys.argv[1:] == ["--units-only"]:
        update_units(out)
        return
    video_dir = Path(sys.argv[1] if len(sys.argv) > 1 else "../shared/data/video")
    write(build(video_dir), out)


if __name__ == "__main__":
    main()
