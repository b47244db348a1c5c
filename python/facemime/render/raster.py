"""Texture-mapped triangle meshes, drawn by the Rust core (docs/method.md §3, the paper's eq. 18).

Each destination triangle A'B'C' is filled scan line by scan line; every destination pixel P'
takes the texture at ``P = A + M (P' - A')`` with M solved once per triangle, so no deformation
leaves holes. Triangles that share an edge cover every pixel exactly once.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from facemime import _core, validate
from facemime.errors import InvalidInputError

FILTERS = ("nearest", "bilinear")
DEPTH_TESTS = ("painter", "zbuffer")


@dataclass(frozen=True)
class RenderStats:
    """What one render did: triangles drawn, culled as back-facing, skipped as zero-area, and
    pixel writes (a pixel drawn twice counts twice)."""

    drawn: int
    culled: int
    degenerate: int
    pixels: int


def render_mesh_into(
    out: np.ndarray,
    texture: np.ndarray,
    tex_coords: np.ndarray,
    points: np.ndarray,
    depth: np.ndarray,
    triangles: np.ndarray,
    *,
    filter: str = "bilinear",
    depth_test: str = "painter",
    cull: bool = True,
) -> RenderStats:
    """Draw a textured mesh into ``out`` in place; pixels outside the mesh are left as they are.

    Parameters
    ----------
    out
        (H, W) or (H, W, C) uint8 array, C-contiguous and writeable: the image drawn into, with
        the same number of channels as ``texture``.
    texture
        (Ht, Wt) or (Ht, Wt, C) uint8 array, the picture mapped onto the mesh.
    tex_coords
        (N, 2) float array: texture coordinates (u, v) of each vertex, in [0, 1] of the texture's
        width and height from its top-left corner (not pixel centre); lookups outside clamp to
        the texture's edge.
    points
        (N, 2) float array: image position of each vertex, (x, y) pixels, y down, origin at the
        centre of the top-left pixel.
    depth
        (N,) float array: depth of each vertex, any unit, larger = nearer the camera.
    triangles
        (F, 3) int array of vertex indices. A triangle faces the camera when its vertices run
        counter-clockwise as seen on the image (a model's outward winding, counter-clockwise seen
        from outside).
    filter
        Texture lookup, 'nearest' or 'bilinear'.
    depth_test
        'painter' draws whole triangles far to near by mean vertex depth (the paper); 'zbuffer'
        tests every pixel.
    cull
        Skip back-facing triangles (else both sides are drawn).

    Returns
    -------
    RenderStats
        Triangles drawn, culled and skipped as zero-area, and pixel writes.

    Examples
    --------
    >>> tex = np.full((4, 4, 3), 200, np.uint8)
    >>> out = np.zeros((8, 8, 3), np.uint8)
    >>> pts = np.array([[-0.5, -0.5], [7.5, -0.5], [7.5, 7.5], [-0.5, 7.5]])  # pixel edges
    >>> uv = np.array([[0.0, 0.0], [1, 0], [1, 1], [0, 1]])
    >>> render_mesh_into(out, tex, uv, pts, np.zeros(4), [[0, 3, 2], [0, 2, 1]]).pixels
    64
    """
    if not (isinstance(out, np.ndarray) and out.flags.c_contiguous and out.flags.writeable):
        raise InvalidInputError("out must be a writeable, C-contiguous uint8 numpy array")
    out_img = _image_3d("out", out)
    tex = _image_3d("texture", texture)
    if tex.shape[2] != out_img.shape[2]:
        raise InvalidInputError(f"texture has {tex.shape[2]} channels but out has {out_img.shape[2]}")
    validate.image_size("out size", (out_img.shape[1], out_img.shape[0]))
    validate.image_size("texture size", (tex.shape[1], tex.shape[0]))
    pts = validate.float_array("points", points, (None, 2))
    n = len(pts)
    uv = validate.float_array("tex_coords", tex_coords, (n, 2))
    z = validate.float_array("depth", depth, (n,))
    tris = validate.index_array("triangles", triangles, 3, n)
    validate.choice("filter", filter, FILTERS)
    validate.choice("depth_test", depth_test, DEPTH_TESTS)
    texel = np.empty_like(uv)  # [0, 1] from the corner -> texel pixels, centres on integers
    texel[:, 0] = uv[:, 0] * tex.shape[1] - 0.5
    texel[:, 1] = uv[:, 1] * tex.shape[0] - 0.5
    stats = _core.render_mesh_into(out_img, tex, texel, pts, z, tris, filter, depth_test, bool(cull))
    return RenderStats(*stats)


def render_mesh(
    texture: np.ndarray,
    tex_coords: np.ndarray,
    points: np.ndarray,
    depth: np.ndarray,
    triangles: np.ndarray,
    size: tuple[int, int],
    *,
    background: np.ndarray | tuple[int, ...] | int | None = None,
    filter: str = "bilinear",
    depth_test: str = "painter",
    cull: bool = True,
) -> np.ndarray:
    """Draw a textured mesh into a new image of ``size`` = (width, height).

    Parameters
    ----------
    texture
        (Ht, Wt) or (Ht, Wt, C) uint8 array, as in :func:`render_mesh_into`.
    tex_coords
        (N, 2) float array, texture coordinates (u, v) in [0, 1], as in :func:`render_mesh_into`.
    points
        (N, 2) float array, image position of each vertex, (x, y) pixels, y down.
    depth
        (N,) float array, depth of each vertex, larger = nearer the camera.
    triangles
        (F, 3) int array of vertex indices, counter-clockwise on the image facing the camera.
    size
        (width, height) of the new image, pixels.
    background
        An image of that size and the texture's channels ((H, W) or (H, W, C) uint8, copied), a
        colour (one 0-255 value per channel, or one for all), or None for black.
    filter
        'nearest' or 'bilinear', as in :func:`render_mesh_into`.
    depth_test
        'painter' or 'zbuffer', as in :func:`render_mesh_into`.
    cull
        Skip back-facing triangles.

    Returns
    -------
    uint8 array
        The image, shaped like the texture: (H, W) for gray, (H, W, C) otherwise.

    Examples
    --------
    >>> img = render_mesh(np.full((2, 2), 9, np.uint8), [[0, 0], [1, 0], [0, 1]],
    ...                   [[1.0, 1], [5, 1], [1, 5]], np.zeros(3), [[0, 2, 1]], (6, 6), background=3)
    >>> img.shape, int(img[2, 2]), int(img[5, 5])
    ((6, 6), 9, 3)
    """
    w, h = validate.image_size("size", size)
    tex = validate.image("texture", texture)
    shape = (h, w) + tex.shape[2:]
    if background is None or np.isscalar(background) or isinstance(background, (tuple, list)):
        colour = np.asarray(0 if background is None else background)
        if colour.ndim > 1 or (colour.ndim == 1 and (tex.ndim == 2 or len(colour) != tex.shape[2])):
            raise InvalidInputError(f"background colour must have one value per texture channel, got {background!r}")
        if not np.issubdtype(colour.dtype, np.number) or colour.min() < 0 or colour.max() > 255:
            raise InvalidInputError(f"background colour values must be in 0..255, got {background!r}")
        out = fill(np.empty(shape, np.uint8), colour)
    else:
        bg = validate.image("background", background)
        if bg.shape != shape:
            raise InvalidInputError(f"background image must have shape {shape}, got {bg.shape}")
        out = bg.copy()
    render_mesh_into(out, tex, tex_coords, points, depth, triangles, filter=filter, depth_test=depth_test, cull=cull)
    return out


def fill(img: np.ndarray, colour: object) -> np.ndarray:
    """Fill ``img`` with ``colour`` in place.

    One row is filled and then copied to the others: numpy's per-pixel broadcast of a C-vector
    takes about 40 times as long.

    Parameters
    ----------
    img
        (H, W) or (H, W, C) uint8 array, filled in place.
    colour
        One 0-255 value, or one per channel.

    Returns
    -------
    (H, W) or (H, W, C) uint8 array
        ``img`` itself.
    """
    row = np.empty(img.shape[1:], np.uint8)
    row[...] = colour
    img[...] = row
    return img


def coverage(points: np.ndarray, triangles: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """How many triangles cover each pixel, both windings counted.

    0 inside a face marks a hole, more than 1 an overlap (a fold of the mesh).

    Parameters
    ----------
    points
        (N, 2) float array: vertex positions, (x, y) pixels, y down, origin at the centre of the
        top-left pixel.
    triangles
        (F, 3) int array of vertex indices.
    size
        (width, height) of the image counted over, pixels.

    Returns
    -------
    (H, W) uint32 array
        The number of triangles covering each pixel.

    Examples
    --------
    >>> coverage([[0.0, 0], [3, 0], [0, 3]], [[0, 1, 2]], (4, 4)).sum()
    np.uint64(6)
    """
    w, h = validate.image_size("size", size)
    pts = validate.float_array("points", points, (None, 2))
    tris = validate.index_array("triangles", triangles, 3, len(pts))
    return _core.coverage(pts, tris, w, h)


def _image_3d(name: str, a: np.ndarray) -> np.ndarray:
    """A validated uint8 image viewed as (H, W, C) (a view, so writes reach the caller)."""
    img = validate.image(name, a)
    return img if img.ndim == 3 else img[:, :, None]
