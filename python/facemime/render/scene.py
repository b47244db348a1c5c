"""The scene around the face: the key frame (the picture an actor was fitted on) as a 2-D mesh
that the head's motion warps, so that a synthesised face appears in its own picture with hair,
ears, neck, shoulders and room instead of on a blank backdrop.

The mesh's vertices are, in order: the **anchors**, the model's ``face_outline`` vertices
(their image positions each frame are the projections of the posed, deformed model, so the scene
meets the 3-D face exactly); **rings** around the face, the outline scaled about its centre by
:data:`RINGS`, each following a share of the head's motion (the least-squares similarity, turn,
uniform scale and shift, taking the anchors from the key frame to now); and the **border**,
vertices on the picture's edges that never move. Everything inside the outline is triangulated
too: it is drawn under the face and shows only where the face mesh does not cover (a turned
head's culled side), never as a hole.

Where the head moves away from what the key frame showed, the uncovered part is filled by
stretching the band between the moving ring and the still one. The alternative, inpainting the
head out of the key frame (``cv2.inpaint``) and moving the ring's inside over that clean plate,
scores the same over the ten shared videos (``benchmarks/synthesis.py``: whole-frame PSNR 22.79
against 22.85 dB, better where the head travels far: lp_d3 19.0 against 17.7, st_aoc 17.3 against
15.8), but shows the moved patch's hard polygon edge, hair cut off at it and lines of the room
jumping across it in every still looked at; stretching bends them smoothly.

Pixels: (x, y), x right, y down, (0, 0) the centre of the top-left pixel; the border lies on the
picture's outer pixel edges (-0.5 and W - 0.5).
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np

from facemime.errors import InvalidInputError
from facemime.render.raster import render_mesh_into
from facemime.shared_constants import BORDER_STEPS, EDGE_MARGIN, RINGS, SLOW
from facemime.types.similarity import apply, robust_similarity

#: Triangles whose vertices all moved less than STILL pixels show the key frame as it is (those
#: that moved less than :data:`~facemime.shared_constants.SLOW` are sampled nearest).
STILL = 0.05


@dataclass(frozen=True, eq=False)
class SceneMesh:
    """The scene's warp mesh for one picture.

    Attributes
    ----------
    size : (width, height)
        The picture, pixels.
    anchors : (A,) int array
        Model vertex indices whose projections are the first A mesh vertices.
    rest : (N, 2) float array
        Every vertex in the key frame, pixels (the texture coordinates).
    follow : (N,) float array
        Share of the head's motion each vertex follows: 1 for anchors and the first ring, 0 on
        the border.
    triangles : (F, 3) int array
        Wound counter-clockwise as seen in the image (x right, y down); together they cover the
        picture once at rest.
    """

    size: tuple[int, int]
    anchors: np.ndarray
    rest: np.ndarray
    follow: np.ndarray
    triangles: np.ndarray

    @classmethod
    def build(cls, size: tuple[int, int], anchors: np.ndarray, outline: np.ndarray) -> SceneMesh:
        """The mesh of a picture whose face outline lies at ``outline``.

        Ring vertices outside the picture or within
        :data:`~facemime.shared_constants.EDGE_MARGIN` of its shorter side from its edge are left
        out; :data:`~facemime.shared_constants.BORDER_STEPS` vertices per side make the border.

        Parameters
        ----------
        size
            (width, height) of the picture (the key frame), pixels.
        anchors
            (A,) int array: the model vertex indices of the outline (the model's
            ``face_outline`` group).
        outline
            (A, 2) float array: the projections of the ``anchors`` in the key frame, (x, y)
            pixels; at least three, finite, possibly outside the picture.

        Returns
        -------
        SceneMesh
            The mesh, at rest on the key frame.
        """
        w, h = size
        outline = np.asarray(outline, np.float64)
        if outline.ndim != 2 or outline.shape[1] != 2 or len(outline) < 3 or not np.isfinite(outline).all():
            raise InvalidInputError("the scene needs a face outline of at least three finite points")
        centre = outline.mean(axis=0)
        lo, hi = np.array([-0.5, -0.5]), np.array([w - 0.5, h - 0.5])
        margin = EDGE_MARGIN * min(w, h)
        points, follow = [outline], [np.ones(len(outline))]
        for reach, share in RINGS:
            ring = centre + reach * (outline - centre)
            inside = ((ring > lo + margin) & (ring < hi - margin)).all(axis=1)
            points.append(ring[inside])
            follow.append(np.full(inside.sum(), share))
        t = np.linspace(0.0, 1.0, BORDER_STEPS)[:-1]
        corners = np.array([lo, [hi[0], lo[1]], hi, [lo[0], hi[1]]])
        border = np.concatenate([a + t[:, None] * (b - a) for a, b in zip(corners, np.roll(corners, -1, axis=0))])
        points.append(border)
        follow.append(np.zeros(len(border)))
        rest = np.concatenate(points)
        return cls((int(w), int(h)), np.asarray(anchors, np.int64), rest, np.concatenate(follow), _delaunay(rest))

    def points(self, outline: np.ndarray) -> np.ndarray:
        """Every vertex now, for the face outline now at ``outline``.

        The anchors are put there, the rings moved by their share of the outline's least-squares
        similarity motion from the key frame, the border left where it was; all but the anchors
        are kept inside the picture (clipped to its outer pixel edges).

        Parameters
        ----------
        outline
            (A, 2) float array: the anchors' projections now, (x, y) pixels.

        Returns
        -------
        (N, 2) float64 array
            Every mesh vertex now, (x, y) pixels, in the order of :attr:`rest`.
        """
        a = len(self.anchors)
        # least squares: with no limit on the residuals no anchor is an outlier
        moved = apply(robust_similarity(self.rest[:a], outline, limit=np.inf)[0], self.rest)
        out = self.rest + self.follow[:, None] * (moved - self.rest)
        out[:a] = outline
        w, h = self.size
        np.clip(out[a:], [-0.5, -0.5], [w - 0.5, h - 0.5], out=out[a:])
        return out

    def draw(self, out: np.ndarray, key: np.ndarray, outline: np.ndarray) -> None:
        """Draw the scene for the face outline now at ``outline``, textured by the key frame.

        Every pixel is written: the key frame is copied and only the triangles that moved (a
        vertex more than :data:`STILL` px in x or y) are drawn again, those that moved less than
        :data:`~facemime.shared_constants.SLOW` pixels sampled nearest, the others bilinear, none
        culled.

        Parameters
        ----------
        out
            (H, W, 3) uint8 RGB array of :attr:`size`, C-contiguous: the picture, written in
            place.
        key
            (H, W, 3) uint8 RGB array: the key frame at :attr:`size`, the same shape as ``out``.
        outline
            (A, 2) float array: the anchors' projections now, (x, y) pixels.
        """
        if key.shape != out.shape:
            raise InvalidInputError(
                f"the key frame is {key.shape[1]}x{key.shape[0]}, the picture {out.shape[1]}x{out.shape[0]}"
            )
        w, h = self.size
        points = self.points(outline)
        moved = np.abs(points - self.rest).max(axis=1)[self.triangles].max(axis=1)
        out[...] = key
        uv = (self.rest + 0.5) / [w, h]
        depth = np.zeros(len(points))
        for tris, sampling in (
            (self.triangles[(moved > STILL) & (moved < SLOW)], "nearest"),
            (self.triangles[moved >= SLOW], "bilinear"),
        ):
            if len(tris):  # no culling: a triangle the motion folds over shows as a fold, never a hole
                render_mesh_into(out, key, uv, points, depth, tris, filter=sampling, cull=False)


def _delaunay(points: np.ndarray) -> np.ndarray:
    """The Delaunay triangles of ``points`` ((N, 2) pixels, anywhere: a face cut by the
    picture's edge has outline vertices outside it), as vertex indices wound counter-clockwise
    in the image. A vertex at the very place of an earlier one is left out of every triangle."""
    f32 = points.astype(np.float32)
    x0, y0 = np.floor(f32.min(axis=0)) - 2
    x1, y1 = np.ceil(f32.max(axis=0)) + 2
    subdiv = cv2.Subdiv2D((int(x0), int(y0), int(x1 - x0) + 1, int(y1 - y0) + 1))
    index = {}
    for i, p in enumerate(f32):
        key = (float(p[0]), float(p[1]))
        if key not in index:
            index[key] = i
            subdiv.insert(key)
    found: list[list[int]] = []
    for x0, y0, x1, y1, x2, y2 in subdiv.getTriangleList():
        try:
            found.append([index[(float(x0), float(y0))], index[(float(x1), float(y1))], index[(float(x2), float(y2))]])
        except KeyError:  # a triangle on Subdiv2D's virtual outer vertices
            continue
    tris = np.array(found, np.int64).reshape(-1, 3)
    a, b, c = (points[tris[:, k]] for k in range(3))
    cross = (b[:, 0] - a[:, 0]) * (c[:, 1] - a[:, 1]) - (b[:, 1] - a[:, 1]) * (c[:, 0] - a[:, 0])
    tris = tris[np.abs(cross) > 1e-9]
    flip = cross[np.abs(cross) > 1e-9] > 0  # y down: counter-clockwise in the image has a negative cross
    tris[flip] = tris[flip][:, [0, 2, 1]]
    return tris
