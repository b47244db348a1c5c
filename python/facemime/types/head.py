"""The head model's type: vertices, triangles, named vertex groups and deformation units, and
the measures every layer takes of it.

Coordinates are model space: right-handed, x to the subject's left, y up, z towards the camera.
The generic head (:func:`facemime.head.generic_head`) is in millimetres with its origin between
the outer eye corners, which are 90 mm apart. Triangles wind counter-clockwise seen from outside
(normals point out of the face).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from facemime.errors import InvalidInputError
from facemime.shared_constants import CONTOUR_GROUPS

#: Groups every facemime head file must have.
REQUIRED_GROUPS = CONTOUR_GROUPS + ("eye_left", "eye_right", "nose", "face_outline")


#: The fewest vertices each required group needs: an eye ring is corner, three upper-lid vertices,
#: corner, three lower-lid ones; the outline's tenth vertex is the chin, the nose's seventh its tip;
#: a contour is a curve.
MIN_GROUP_SIZES = {**dict.fromkeys(CONTOUR_GROUPS, 2), "eye_left": 8, "eye_right": 8, "nose": 7, "face_outline": 10}


#: Default input limits, each overridden by its environment variable (see the module docstring).
#: Largest vertex coordinate, model units (a face is some hundreds of millimetres; a farther vertex
#: is a broken file, and would overflow the pixel arithmetic of previews).
MAX_COORDINATE = 1e6


@dataclass(frozen=True, eq=False)
class HeadModel:
    """A wire-frame head.

    Attributes
    ----------
    vertices : (N, 3) float64 array
        Rest positions in model space (see the module docstring), in ``unit``.
    triangles : (F, 3) int64 array
        Vertex indices, outward (counter-clockwise from outside) winding.
    uv : (N, 2) float64 array or None
        Texture coordinates in [0, 1] from the texture's top-left corner.
    groups : dict of str -> (K,) int64 array
        Named, ordered vertex groups.
    units : dict of str -> (N, 3) float64 array
        Deformation (animation) units: displacement of every vertex at activation 1.
    shape_units : dict of str -> (N, 3) float64 array
        Shape units (per-person shape, CANDIDE), same layout.
    descriptions : dict of str -> str
        What each unit does.
    name : str
        The model's name, for messages.
    unit : str
        The model unit of ``vertices`` and of the units' displacements (``"mm"`` for the generic
        head).
    """

    vertices: np.ndarray
    triangles: np.ndarray
    uv: np.ndarray | None = None
    groups: dict[str, np.ndarray] = field(default_factory=dict)
    units: dict[str, np.ndarray] = field(default_factory=dict)
    shape_units: dict[str, np.ndarray] = field(default_factory=dict)
    descriptions: dict[str, str] = field(default_factory=dict)
    name: str = "head"
    unit: str = "mm"

    def __post_init__(self) -> None:
        problem = first_problem(self.vertices, self.triangles, self.uv, self.groups, (self.units, self.shape_units))
        if problem:
            raise InvalidInputError(f"head model {self.name!r}: {problem}")

    def deform(
        self, weights: Mapping[str, float] | None = None, shape: Mapping[str, float] | None = None
    ) -> np.ndarray:
        """Vertices with deformation units (and shape units) applied.

        Parameters
        ----------
        weights
            Deformation unit name -> activation (1: the unit's full displacement); None: none.
        shape
            Shape unit name -> activation; None: none.

        Returns
        -------
        (N, 3) float64 array
            The rest vertices plus each unit's displacement times its activation, model units.

        Examples
        --------
        >>> from facemime.head import generic_head
        >>> head = generic_head()
        >>> moved = head.deform({"jawOpen": 0.5})
        >>> bool(moved[head.groups["mouth_outer_lower"][5], 1] < head.vertices[head.groups["mouth_outer_lower"][5], 1])
        True
        """
        v = self.vertices.copy()
        for table, given, kind in ((self.units, weights, "deformation unit"), (self.shape_units, shape, "shape unit")):
            for name, w in (given or {}).items():
                if name not in table:
                    raise InvalidInputError(f"unknown {kind} {name!r}; this model has: {', '.join(table) or 'none'}")
                v += float(w) * table[name]
        return v


def first_problem(
    v: np.ndarray,
    t: np.ndarray,
    uv: np.ndarray | None,
    groups: Mapping[str, np.ndarray],
    tables: tuple[Mapping[str, np.ndarray], ...],
) -> str | None:
    """The first thing wrong with a model's arrays, as text.

    Parameters
    ----------
    v
        Vertices, expected (N, 3) float, N >= 3, finite, model units, no coordinate beyond
        :data:`MAX_COORDINATE`.
    t
        Triangles, expected (F, 3) int vertex indices, F >= 1, none of zero area.
    uv
        Texture coordinates, expected (N, 2) within -1..2 (nominally 0..1), or None.
    groups
        Group name -> vertex indices, expected 1-D, non-empty, within 0..N - 1.
    tables
        Unit tables (deformation, shape), each name -> expected (N, 3) finite displacements.

    Returns
    -------
    str or None
        One line describing the problem; None when the arrays are sound.
    """
    if not (isinstance(v, np.ndarray) and v.ndim == 2 and v.shape[1] == 3 and len(v) >= 3):
        return f"vertices must have shape (N, 3) with N >= 3, got {getattr(v, 'shape', type(v).__name__)}"
    n = len(v)
    if not np.isfinite(v).all():
        return "vertices hold NaN or inf"
    if np.abs(v).max() > MAX_COORDINATE:
        return f"a vertex lies {np.abs(v).max():.3g} from the origin, beyond the {MAX_COORDINATE:g} model units allowed"
    if not (isinstance(t, np.ndarray) and t.ndim == 2 and t.shape[1] == 3 and len(t) >= 1):
        return f"triangles must have shape (F, 3) with F >= 1, got {getattr(t, 'shape', type(t).__name__)}"
    if t.min() < 0 or t.max() >= n:
        bad = int(t.min() if t.min() < 0 else t.max())
        return f"triangle {int(np.argwhere((t < 0) | (t >= n))[0, 0])} uses vertex {bad}, but there are {n} vertices"
    area = np.linalg.norm(np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]]), axis=1)
    scale = max(float(np.ptp(v, axis=0).max()), 1e-12)
    if (area <= 1e-9 * scale**2).any():
        return f"triangle {int(np.argmax(area <= 1e-9 * scale**2))} is degenerate (zero area)"
    if uv is not None and (uv.shape != (n, 2) or not np.isfinite(uv).all()):
        return f"uv must have shape ({n}, 2) and be finite, got {uv.shape}"
    if uv is not None and (uv.min() < -1 or uv.max() > 2):
        return "texture coordinates (uv) must lie near 0..1 (within -1..2)"
    for name, g in groups.items():
        if g.ndim != 1 or len(g) == 0 or g.min() < 0 or g.max() >= n:
            return f"group {name!r} must list vertex indices in 0..{n - 1}"
    for table in tables:
        for name, d in table.items():
            if d.shape != (n, 3) or not np.isfinite(d).all():
                return f"unit {name!r} must have shape ({n}, 3) and be finite"
    return None


def model_iod(model: HeadModel) -> float:
    """Distance between the model's outer eye corners in the frontal (x, y) plane.

    Parameters
    ----------
    model
        A head with the ``eye_right`` and ``eye_left`` groups.

    Returns
    -------
    float
        Model units, z ignored (90 for the generic head).
    """
    g = model.groups
    return float(np.linalg.norm(model.vertices[g["eye_right"][0], :2] - model.vertices[g["eye_left"][4], :2]))


def model_eye_centres(model: HeadModel) -> np.ndarray:
    """Midpoints of each eye's corners.

    Parameters
    ----------
    model
        A head with the ``eye_right`` and ``eye_left`` groups.

    Returns
    -------
    (2, 3) float64 array
        Model coordinates, model units; the image-left eye (the subject's right) first.
    """
    return np.array([model.vertices[model.groups[e][[0, 4]]].mean(axis=0) for e in ("eye_right", "eye_left")])


def mouth_width(model: HeadModel, vertices: np.ndarray) -> float:
    """Distance between the mouth's corners (the outer lips' ends) in the model's (x, y) plane.

    Parameters
    ----------
    model
        The head model whose ``mouth_outer_upper`` group names the corners.
    vertices
        (N, 3) float array: a shape of ``model``'s (its own vertices or deformed ones), model units.

    Returns
    -------
    float
        The corner-to-corner distance, model units.
    """
    first, last = model.groups["mouth_outer_upper"][[0, -1]]
    return float(np.hypot(*(vertices[last, :2] - vertices[first, :2])))


def mouth_up(model: HeadModel, vertices: np.ndarray) -> np.ndarray | None:
    """The unit vector across the mouth's corner line, towards the nose, in the model's (x, y)
    plane: the direction the lips' gap is measured along.

    Parameters
    ----------
    model
        The head model whose ``mouth_outer_upper`` group names the corners.
    vertices
        (N, 3) float array: a shape of ``model``'s (its own vertices or deformed ones), model units.

    Returns
    -------
    (2,) float64 array or None
        Model (x, y), y up; None where the corners coincide.
    """
    first, last = model.groups["mouth_outer_upper"][[0, -1]]
    along = vertices[last, :2] - vertices[first, :2]
    width = mouth_width(model, vertices)
    return None if width <= 0.0 else np.array([-along[1], along[0]]) / width


def lip_strip(model: HeadModel) -> np.ndarray:
    """The strip between the inner lips, knot to knot: two triangles a pair of knots, none where
    the lips share a vertex (the corners).

    Parameters
    ----------
    model
        The head, with the inner lips' groups.

    Returns
    -------
    (M, 3) int64 array
        Vertex indices, winding as the lips run (upper i, upper i + 1, lower i + 1; upper i, lower
        i + 1, lower i); (0, 3) where the inner lips' knot counts differ.
    """
    upper, lower = model.groups["mouth_inner_upper"], model.groups["mouth_inner_lower"]
    if len(upper) != len(lower):
        return np.zeros((0, 3), np.int64)
    quads = [(upper[i], upper[i + 1], lower[i + 1], lower[i]) for i in range(len(upper) - 1)]
    triangles = [t for a, b, c, d in quads for t in ((a, b, c), (a, c, d)) if len({*t}) == 3]
    return np.array(triangles, np.int64).reshape(-1, 3)


def mouth_capped(model: HeadModel) -> bool:
    """Whether a model's mouth is capped: its triangles close the opening between the inner lips
    (:func:`facemime.fit.actor.mouth_cap`, on a photo whose mouth was open), so that its texture
    shows that opening.

    Parameters
    ----------
    model
        The head, with the inner lips' groups.

    Returns
    -------
    bool
        True when any of its triangles is one of :func:`lip_strip`'s, in either winding.
    """
    strip = {frozenset(t) for t in lip_strip(model).tolist()}
    return any(frozenset(t) in strip for t in np.asarray(model.triangles).tolist())
