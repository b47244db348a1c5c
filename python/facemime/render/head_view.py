"""Pictures of a head model: textured and flat-shaded (both by the Rust rasteriser) and
wireframe views.

Poses and coordinates as in :mod:`facemime.types.pose`.
"""

from __future__ import annotations

import cv2
import numpy as np

from facemime.errors import InvalidInputError
from facemime.render.raster import render_mesh
from facemime.types.head import HeadModel
from facemime.types.pose import Pose, project, rotation_matrix

LIGHT = np.array([0.3, 0.4, 1.0]) / np.linalg.norm([0.3, 0.4, 1.0])  # model-space, towards the light


def render_head(
    model: HeadModel,
    texture: np.ndarray,
    pose: Pose,
    size: tuple[int, int],
    *,
    vertices: np.ndarray | None = None,
    background: np.ndarray | tuple[int, ...] | int | None = None,
    filter: str = "bilinear",
    depth_test: str = "painter",
) -> np.ndarray:
    """The textured model seen in ``pose``, drawn into a new image by the Rust rasteriser.

    Parameters
    ----------
    model
        The head; its triangles and texture coordinates (``uv``, required) are used.
    texture
        (Ht, Wt, 3) uint8 RGB array (or (Ht, Wt) gray) that ``model.uv`` maps onto the mesh.
    pose
        The head pose that places the model in the image.
    size
        (width, height) of the new image, pixels.
    vertices
        (N, 3) float array: a deformed copy of ``model.vertices`` to draw instead, model units;
        None draws the rest shape.
    background
        An image of ``size``, a 0-255 colour (one value per channel, or one for all), or None for
        black; see :func:`~facemime.render.raster.render_mesh`.
    filter
        Texture lookup, 'nearest' or 'bilinear'.
    depth_test
        'painter' (whole triangles far to near) or 'zbuffer' (per pixel).

    Returns
    -------
    (H, W, 3) uint8 array
        The picture, RGB ((H, W) for a gray texture).
    """
    points, depth = project(model.vertices if vertices is None else vertices, pose)
    if model.uv is None:
        raise InvalidInputError(f"head model {model.name!r} has no texture coordinates (uv)")
    return render_mesh(
        texture,
        model.uv,
        points,
        depth,
        model.triangles,
        size,
        background=background,
        filter=filter,
        depth_test=depth_test,
    )


def render_shaded(
    model: HeadModel,
    pose: Pose,
    size: tuple[int, int],
    *,
    vertices: np.ndarray | None = None,
    colour: tuple[int, int, int] = (205, 180, 160),
    background: int = 255,
) -> np.ndarray:
    """Flat Lambert shading of the front faces, far to near, drawn by the Rust rasteriser.

    Each face gets its own three corners, all on the texel of its colour in a one-row palette
    texture, so the nearest-texel fill paints the face in one flat colour. Edges are not
    anti-aliased (a wireframe drawn on top covers them). A face's shade is ``colour`` times
    0.25 + 0.75 max(0, cos) of the angle between its pose-rotated normal and :data:`LIGHT`.

    Parameters
    ----------
    model
        The head; its triangles are used, and its vertices unless ``vertices`` is given.
    pose
        The head pose that places the model in the image.
    size
        (width, height) of the preview image, pixels.
    vertices
        (N, 3) float array: a deformed copy of ``model.vertices`` to draw instead, model units;
        None draws the rest shape.
    colour
        (R, G, B) 0-255 colour of a face lit head-on.
    background
        0-255 level of all three channels where no face is drawn.

    Returns
    -------
    (H, W, 3) uint8 array
        The RGB preview image.
    """
    v = model.vertices if vertices is None else vertices
    points, depth = project(v, pose)
    t = model.triangles
    a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
    normals = np.cross(b - a, c - a)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    view_normals = normals @ rotation_matrix(pose.yaw, pose.pitch, pose.roll).T
    light = 0.25 + 0.75 * np.clip(view_normals @ LIGHT, 0, 1)
    shades = np.clip(np.round(light[:, None] * np.asarray(colour, np.float64)), 0, 255).astype(np.int64)
    palette_keys, face_texel = np.unique(shades @ [1 << 16, 1 << 8, 1], return_inverse=True)  # RGB as one int
    palette = ((palette_keys[:, None] >> [16, 8, 0]) & 255).astype(np.uint8)[None]
    uv = np.empty((len(t), 2))
    uv[:, 0] = (face_texel + 0.5) / len(palette_keys)
    uv[:, 1] = 0.5
    corners = t.ravel()
    return render_mesh(
        palette,
        np.repeat(uv, 3, axis=0),
        points[corners],
        depth[corners],
        np.arange(len(corners)).reshape(-1, 3),
        size,
        background=background,
        filter="nearest",
    )


def draw_wireframe(
    image: np.ndarray,
    points: np.ndarray,
    triangles: np.ndarray,
    colour: tuple[int, int, int] = (40, 220, 90),
    thickness: int = 1,
) -> np.ndarray:
    """Draw every triangle edge of a projected mesh onto ``image`` in place.

    Each shared edge is drawn once, anti-aliased, its ends at 1/16 px precision.

    Parameters
    ----------
    image
        (H, W, 3) uint8 array (or any image ``cv2.polylines`` takes), drawn on in place.
    points
        (N, 2) float array: projected vertices, (x, y) pixels, y down.
    triangles
        (F, 3) int array of vertex indices.
    colour
        Line colour, one 0-255 value per channel of ``image`` (R, G, B for an RGB image).
    thickness
        Line width, pixels.

    Returns
    -------
    (H, W, 3) uint8 array
        ``image`` itself.
    """
    n = len(points)
    t = np.asarray(triangles, np.int64)
    following = np.roll(t, -1, axis=1)  # edges 0-1, 1-2, 2-0 of each triangle
    keys = np.sort((np.minimum(t, following) * n + np.maximum(t, following)).ravel())
    keys = keys[np.diff(keys, prepend=-1) != 0]  # each edge once, lowest vertex pair first
    ends = np.round(np.asarray(points) * 16).astype(np.int32)  # 4 fractional bits (shift=4)
    segments = np.stack([ends[keys // n], ends[keys % n]], axis=1)
    cv2.polylines(image, list(segments), False, colour, thickness, cv2.LINE_AA, 4)
    return image


def views_sheet(
    model: HeadModel,
    texture: np.ndarray | None,
    cell: int = 320,
    yaws: tuple[float, ...] = (-60, -30, 0, 30, 60),
    vertices: np.ndarray | None = None,
) -> np.ndarray:
    """One picture of a model seen at several yaw angles.

    One column per yaw: a textured render on top (when a texture is given), below it a
    flat-shaded render with the wireframe on top. Each view frames the rest shape to 0.88 of the
    cell (:meth:`~facemime.types.pose.Pose.framing`).

    Parameters
    ----------
    model
        The head drawn.
    texture
        (Ht, Wt, 3) uint8 RGB array mapped by ``model.uv``, or None for no textured row.
    cell
        Side of each square view, pixels.
    yaws
        The yaw of each column, degrees (positive turns the nose to the image's right).
    vertices
        (N, 3) float array: a deformed copy of ``model.vertices`` to draw instead, model units;
        None draws the rest shape.

    Returns
    -------
    (rows * cell, len(yaws) * cell, 3) uint8 array
        The RGB sheet, ``rows`` 2 with a texture and 1 without.
    """
    v = model.vertices if vertices is None else vertices
    columns = []
    for yaw in yaws:
        pose = Pose.framing(model.vertices, (cell, cell), 0.88, yaw=yaw)
        shaded = render_shaded(model, pose, (cell, cell), vertices=v)
        rows = [draw_wireframe(shaded, project(v, pose)[0], model.triangles, (30, 110, 40))]
        if texture is not None:
            rows.insert(0, render_head(model, texture, pose, (cell, cell), vertices=v, background=(36, 36, 40)))
        columns.append(np.vstack(rows))
    return np.hstack(columns)
