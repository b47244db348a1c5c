"""The eyes, measured frame by frame: how open each is and where its iris is.

Each eye is looked at in its own frame: the head pose places the actor's eye ring (its model
group ``eye_right`` or ``eye_left``: outer or inner corner, three upper-lid vertices, the other
corner, three lower-lid vertices), and the picture is sampled on a grid in (u, v), units of the
eye's width from the middle of its corners, u along the line from the image-left corner to the
image-right one, v across it (down on the screen for an upright face).

- The iris is the darkest disc of the iris's radius with bright sclera beside it
  (:func:`find_iris`).
- The lids: the key frame's eye (its lids where the actor was fitted, on the Face Mesh's lid
  middles) is closed in trials, by shares of its opening, and the trial that looks most like the
  eye now, on a few columns across it, gives the opening (:class:`LidModel`). The opening is
  never looked for above the key frame's: an eye opened wider shows as the key frame's.

Measured on all ten shared videos against their Face Mesh references:
``benchmarks/fidelity.py``.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import cv2
import numpy as np

from facemime.render.bilinear import sample_affine
from facemime.shared_constants import DENSITY, EYES, IRIS_RADIUS, IRIS_U, IRIS_V, SPAN_U, SPAN_V
from facemime.types.head import HeadModel
from facemime.types.pose import Pose, head_plane, project

#: How far above the key frame's upper lid, and below its lower lid, the trials are compared.
REACH_UP = 0.15
REACH_DOWN = 0.15


@dataclass(frozen=True)
class EyeFrame:
    """One eye's frame in the picture: ``origin`` the middle of its corners (x, y) px, ``axes``
    (2, 2) rows the u and v directions scaled to one eye width (px)."""

    origin: np.ndarray
    axes: np.ndarray

    @classmethod
    def of(cls, ring: np.ndarray) -> EyeFrame:
        """The frame of a projected eye ring.

        Parameters
        ----------
        ring
            (8, 2) float array: the ring's projections (corner, 3 upper-lid, corner, 3 lower-lid
            vertices), (x, y) pixels.

        Returns
        -------
        EyeFrame
            Origin at the middle of the two corners, u from the image-left corner to the
            image-right one, v that turned 90° (down on the screen for an upright face).
        """
        a, b = (ring[0], ring[4]) if ring[0, 0] <= ring[4, 0] else (ring[4], ring[0])
        ex = b - a
        return cls((a + b) / 2.0, np.array([ex, [-ex[1], ex[0]]]))

    @property
    def width(self) -> float:
        """The eye's width, px."""
        return float(np.hypot(*self.axes[0]))

    def to_image(self, uv: np.ndarray) -> np.ndarray:
        """Image positions of eye coordinates.

        Parameters
        ----------
        uv
            (..., 2) float array: (u, v) eye coordinates, eye widths.

        Returns
        -------
        (..., 2) float64 array
            (x, y) pixels.
        """
        return self.origin + np.asarray(uv) @ self.axes

    def to_eye(self, xy: np.ndarray) -> np.ndarray:
        """Eye coordinates of image points.

        Parameters
        ----------
        xy
            (..., 2) float array: (x, y) pixels.

        Returns
        -------
        (..., 2) float64 array
            (u, v) eye coordinates, eye widths.
        """
        return (np.asarray(xy) - self.origin) @ np.linalg.inv(self.axes)

    def patch(self, frame: np.ndarray) -> np.ndarray:
        """The eye's gray patch of ``frame``.

        Sampled every 1 / :data:`DENSITY` eye widths over :data:`SPAN_U` x :data:`SPAN_V`
        (:func:`~facemime.render.bilinear.sample_affine`, then OpenCV's RGB-to-gray).

        Parameters
        ----------
        frame
            (H, W, 3) uint8 RGB array.

        Returns
        -------
        (R, C) float32 array
            0-255 gray levels; row i at v = SPAN_V[0] + i / DENSITY, column j at
            u = SPAN_U[0] + j / DENSITY (23 x 29 with the shared constants).
        """
        rows, cols = _patch_shape()
        step = self.axes / DENSITY
        start = self.to_image(np.array([SPAN_U[0], SPAN_V[0]]))
        m = np.column_stack([step[0], step[1], start])  # patch (col, row) -> image (x, y)
        rgb = sample_affine(frame, m, (cols, rows))
        return cv2.cvtColor(rgb, cv2.COLOR_RGB2GRAY).astype(np.float32)


def _patch_shape() -> tuple[int, int]:
    """(rows, columns) of an eye's patch."""
    return int(round((SPAN_V[1] - SPAN_V[0]) * DENSITY)) + 1, int(round((SPAN_U[1] - SPAN_U[0]) * DENSITY)) + 1


def _u(col: float) -> float:
    return SPAN_U[0] + col / DENSITY


def _v(row: float) -> float:
    return SPAN_V[0] + row / DENSITY


def _col(u: float) -> int:
    return int(round((u - SPAN_U[0]) * DENSITY))


def _row(v: float) -> int:
    return int(round((v - SPAN_V[0]) * DENSITY))


def _peak(values: np.ndarray, i: int) -> float:
    """``i`` moved to the vertex of the parabola through ``values[i - 1 : i + 2]``."""
    if 0 < i < len(values) - 1:
        a, b, c = values[i - 1], values[i], values[i + 1]
        d = a - 2 * b + c
        if d != 0:
            return i + float(np.clip(0.5 * (a - c) / d, -0.5, 0.5))
    return float(i)


@functools.cache
def _disc(radius: float) -> np.ndarray:
    """A normalised disc kernel of ``radius`` px (read only)."""
    r = int(np.ceil(radius))
    y, x = np.mgrid[-r : r + 1, -r : r + 1]
    k = (x * x + y * y <= radius * radius).astype(np.float32)
    k /= k.sum()
    k.flags.writeable = False
    return k


def find_iris(patch: np.ndarray, radius: float = IRIS_RADIUS) -> tuple[np.ndarray, float]:
    """The iris centre in an eye's :meth:`EyeFrame.patch`.

    It is where a disc of ``radius`` is darkest against the picture beside it: the disc's mean
    less half the mean beside it is least, searched within ± :data:`IRIS_U` along the eye and
    :data:`IRIS_V` across it, refined between samples by parabolas. Beside it is the mean of two
    boxes, 0.6 of the radius wide and 1.2 radii tall, just outside the disc on either side
    (taking the brighter box instead pulled the centre towards the side with more sclera, 0.031
    against 0.029 IOD on the shared videos). (Taking the disc's darkness inside the eye's opening
    only, to keep the lashes out, doubled the error on the shared videos: 0.031 to 0.050 IOD.)

    Parameters
    ----------
    patch
        (R, C) float32 array: an eye's gray patch from :meth:`EyeFrame.patch`, 0-255 levels.
    radius
        The iris's radius, eye widths.

    Returns
    -------
    centre : (2,) float64 array
        The iris centre (u, v), eye widths.
    contrast : float
        How much brighter the sides are than the disc there, gray levels; low when no iris
        shows.
    """
    r = radius * DENSITY
    inside = cv2.filter2D(patch, -1, _disc(r), borderType=cv2.BORDER_REPLICATE)
    side = int(round(0.6 * r))
    box = cv2.blur(patch, (side, int(round(1.2 * r))), borderType=cv2.BORDER_REPLICATE)
    shift = int(round(r + side / 2.0))
    beside = np.empty_like(box)
    beside[:, shift:-shift] = 0.5 * (box[:, : -2 * shift] + box[:, 2 * shift :])
    beside[:, :shift] = beside[:, shift : shift + 1]
    beside[:, -shift:] = beside[:, -shift - 1 : -shift]
    score = inside - 0.5 * beside
    r0, c0 = _row(IRIS_V[0]), _col(-IRIS_U)
    window = score[r0 : _row(IRIS_V[1]) + 1, c0 : _col(IRIS_U) + 1]
    row, col = np.unravel_index(int(np.argmin(window)), window.shape)
    centre = np.array([_u(c0 + _peak(window[row], int(col))), _v(r0 + _peak(window[:, col], int(row)))])
    return centre, float(beside[r0 + row, c0 + col] - inside[r0 + row, c0 + col])


#: Columns (u, eye widths) the lids are looked at, each the mean of a band of COLUMN_HALF either
#: side: the shut eye's lid line runs across them all.
COLUMNS = (-0.3, -0.15, 0.0, 0.15, 0.3)
COLUMN_HALF = 0.05


def profiles(patch: np.ndarray) -> np.ndarray:
    """The mean of an eye's patch over each of :data:`COLUMNS`' bands, per row.

    Parameters
    ----------
    patch
        (R, C) float32 array: an eye's gray patch from :meth:`EyeFrame.patch`, 0-255 levels.

    Returns
    -------
    (len(COLUMNS), R) float32 array
        Per column band (± :data:`COLUMN_HALF` eye widths), the mean gray level of each row.
    """
    half = max(1, int(round(COLUMN_HALF * DENSITY)))
    return np.array([patch[:, _col(u) - half : _col(u) + half + 1].mean(axis=1) for u in COLUMNS])


#: Openings (shares of the key frame's) and lower-lid shifts (eye widths) tried by
#: :class:`LidModel`; an eye opened wider than on the key frame is not looked for (trials up to
#: 1.5 times mistook a gaze moving down for one).
OPENINGS = np.linspace(0.0, 1.1, 12)
LOWER_SHIFTS = np.linspace(-0.05, 0.05, 3)
#: The lids' rims beyond the fitted lid lines, eye widths: a shut eye hides them too.
LID_MARGIN = 0.03
#: Shifts of the whole eye tried (the pose errs by some pixels), eye widths.
SHIFTS = np.linspace(-0.15, 0.15, 5)
#: Weight of the pull towards the key frame's eye (opening 1, no shifts): the mean openness error
#: on the ten shared videos (IOD, both eyes) fell from 0.0205 at 0.2 to 0.019 at 0.4 and 0.018
#: at this weight (the key frame's opening kept throughout: 0.022).
PRIOR = 0.8


def _normalised(a: np.ndarray) -> np.ndarray:
    return (a - a.mean(axis=-1, keepdims=True)) / np.maximum(a.std(axis=-1, keepdims=True), 1e-6)


class LidModel:
    """The key frame's eye, closed in trials, to be matched with the eye on other frames.

    Each trial moves the key frame's eye by a shift (the head's pose errs by some pixels) and
    closes it: the upper lid comes down to a share of the opening, the skin above sliding with it
    (less and less up to :data:`REACH_UP` above) and the eye between the lids squeezed; the
    lower lid moves by a shift of its own. This is done on each column's :func:`profiles` of the
    key frame, once.

    Parameters
    ----------
    key
        (len(COLUMNS), R) float array: the key frame's eye :func:`profiles`, 0-255 levels.
    upper
        (len(COLUMNS),) float array: the key frame's upper lid at each of :data:`COLUMNS`, v in
        eye widths.
    lower
        (len(COLUMNS),) float array: its lower lid there, v in eye widths.
    """

    def __init__(self, key: np.ndarray, upper: np.ndarray, lower: np.ndarray):
        rows = key.shape[1]
        # the squeezed part reaches LID_MARGIN past each lid line: the lids' dark rims
        vu = ((upper - LID_MARGIN - SPAN_V[0]) * DENSITY)[:, None]
        vl = ((lower + LID_MARGIN - SPAN_V[0]) * DENSITY)[:, None]
        top = max(0.0, float(vu.min()) - REACH_UP * DENSITY)
        bottom = min(rows - 1.0, float(vl.max()) + REACH_DOWN * DENSITY)
        self._rows = slice(int(np.ceil(top)), int(bottom) + 1)
        v = np.arange(rows, dtype=np.float64)[self._rows]
        o = OPENINGS[:, None, None, None, None]
        lower_shift = LOWER_SHIFTS[None, :, None, None, None]
        w = v - SHIFTS[None, None, :, None, None] * DENSITY  # where the row was, the whole eye moved back
        opening = vl - vu
        new_l = vl + lower_shift * DENSITY
        new_u = new_l - o * opening
        slide = (new_u - vu) * np.clip((w - top) / np.maximum(vu - top, 1e-9), 0.0, 1.0)
        between = vu + (w - new_u) / np.maximum(new_l - new_u, 1e-9) * opening
        source = np.clip(np.where(w < new_u, w - slide, np.where(w <= new_l, between, w - (new_l - vl))), 0, rows - 1)
        i0 = np.floor(source).astype(int)
        f = source - i0
        i1 = np.minimum(i0 + 1, rows - 1)
        c = np.arange(len(key))[:, None]
        self._trials = _normalised(key[c, i0] * (1 - f) + key[c, i1] * f)  # (O, L, M, C, R')
        prior = (
            (OPENINGS[:, None, None] - 1.0) ** 2
            + (LOWER_SHIFTS[None, :, None] / LOWER_SHIFTS[-1]) ** 2
            + (SHIFTS[None, None, :] / SHIFTS[-1]) ** 2
        )
        self._prior = PRIOR * prior

    def share(self, now: np.ndarray) -> float:
        """The share of the key frame's opening that an eye shows now.

        The best trial's (normalised squared difference, summed with the pull :data:`PRIOR`),
        refined between trials by a parabola.

        Parameters
        ----------
        now
            (len(COLUMNS), R) float array: the eye's :func:`profiles` now, 0-255 levels.

        Returns
        -------
        float
            The opening as a share of the key frame's, within the range of :data:`OPENINGS`
            (0 to 1.1).
        """
        seen = _normalised(now[:, self._rows])
        cost = ((self._trials - seen) ** 2).mean(axis=(-1, -2)) + self._prior
        i, j, k = np.unravel_index(int(np.argmin(cost)), cost.shape)
        return float(np.interp(_peak(cost[:, j, k], int(i)), np.arange(len(OPENINGS)), OPENINGS))


@dataclass(frozen=True)
class EyeState:
    """Both eyes measured on one frame: ``opening`` (2,) upper to lower lid, eye widths;
    ``iris`` (2, 2) iris centres (u, v); ``frames`` the two :class:`EyeFrame`; ``seen`` (2,)
    whether each iris shows (:data:`IRIS_SEEN`); ``rest`` (2, 2) where the key frame's irises
    are in this pose (u, v). The subject's right (image-left) eye first."""

    opening: np.ndarray
    iris: np.ndarray
    frames: tuple[EyeFrame, EyeFrame]
    seen: np.ndarray
    rest: np.ndarray

    def iris_xy(self) -> np.ndarray:
        """The iris centres in the image.

        Returns
        -------
        (2, 2) float64 array
            Per eye (the subject's right first), the iris centre (x, y), pixels.
        """
        return np.array([f.to_image(i) for f, i in zip(self.frames, self.iris)])

    def opening_px(self) -> np.ndarray:
        """The lid openings in the image.

        Returns
        -------
        (2,) float64 array
            Per eye (the subject's right first), upper to lower lid, pixels.
        """
        return self.opening * np.array([f.width for f in self.frames])


#: Iris shifts are shrunk by this much (eye widths) towards none, so that an iris that does not
#: move is drawn as on the key frame (repainting it for the measure's noise cost the eyes of
#: still faces up to 2 dB: mt_sun 26.1 dB against 24.0).
IRIS_STILL = 0.03
#: An iris counts as seen when its contrast is at least this share of the key frame's.
IRIS_SEEN = 0.4
#: An eye closed more than this (share of its key-frame opening) shows too little iris to find:
#: its iris keeps its last place.
IRIS_HIDDEN = 0.6


class EyeTracker:
    """Measures the eyes of an actor's model on frames given with the head's pose.

    ``key`` (attribute) is the :class:`EyeState` measured on the key frame.

    Parameters
    ----------
    model
        The actor's fitted model, its eye rings (:data:`EYES` groups) on the lids.
    key
        (H, W, 3) uint8 RGB array: the key frame, the one the actor was fitted on.
    key_pose
        The head's pose in ``key``.
    """

    def __init__(self, model: HeadModel, key: np.ndarray, key_pose: Pose):
        self._rings = [model.vertices[model.groups[e]] for e in EYES]
        frames = self._frames(key_pose)
        self._models, self._opening, self._contrast = [], np.zeros(2), np.zeros(2)
        # the key frame's irises on the head: at the depth of the lids, they turn with it (an
        # eye's surface bulges in front of its corners, so a turned head moves the iris across
        # the eye by itself; the synthesis's mesh does the same)
        self._irises = np.zeros((2, 3))
        for k, (f, r) in enumerate(zip(frames, self._rings)):
            # the lids as fitted, in the eye's frame: upper and lower, corner to corner
            uv = f.to_eye(project(r, key_pose)[0])
            upper, lower = (c[np.argsort(c[:, 0])] for c in (uv[[0, 1, 2, 3, 4]], uv[[0, 7, 6, 5, 4]]))
            at = lambda u, c: np.interp(u, c[:, 0], c[:, 1])  # noqa: E731
            patch = f.patch(key)
            self._models.append(LidModel(profiles(patch), at(np.array(COLUMNS), upper), at(np.array(COLUMNS), lower)))
            self._opening[k] = at(0.0, lower) - at(0.0, upper)
            iris, self._contrast[k] = find_iris(patch)
            depth = r[[1, 2, 3, 5, 6, 7], 2].mean()
            self._irises[k] = [*head_plane(f.to_image(iris)[None], np.array([depth]), key_pose)[0], depth]
        self.key = self.update(key, key_pose)
        self._shift = np.zeros((2, 2))

    def _frames(self, pose: Pose) -> tuple[EyeFrame, EyeFrame]:
        return tuple(EyeFrame.of(project(r, pose)[0]) for r in self._rings)  # type: ignore[return-value]

    def update(self, frame: np.ndarray, pose: Pose) -> EyeState:
        """Measure the eyes of ``frame`` with the head in ``pose``.

        Parameters
        ----------
        frame
            (H, W, 3) uint8 RGB array.
        pose
            The head's pose in ``frame``.

        Returns
        -------
        EyeState
            Both eyes' openings, irises and frames on ``frame``.
        """
        frames = self._frames(pose)
        iris, opening, seen = np.zeros((2, 2)), np.zeros(2), np.zeros(2, bool)
        for k, f in enumerate(frames):
            p = f.patch(frame)
            share = self._models[k].share(profiles(p))
            opening[k] = share * self._opening[k]
            iris[k], contrast = find_iris(p)
            seen[k] = contrast >= IRIS_SEEN * self._contrast[k]
        rest = np.array([f.to_eye(xy) for f, xy in zip(frames, project(self._irises, pose)[0])])
        return EyeState(opening, iris, frames, seen, rest)

    def look(self, state: EyeState) -> tuple[np.ndarray, np.ndarray]:
        """The closure and iris shift of :class:`facemime.types.look.Look` for a measured state.

        Both are relative to the key frame (the iris to where the head's turn carries the key
        frame's); every iris shift is shrunk by :data:`IRIS_STILL` towards none, and an iris not
        seen or hidden by its lids (:data:`IRIS_HIDDEN`) is held where it was last seen (the
        tracker keeps it from call to call).

        Parameters
        ----------
        state
            The eyes measured on a frame, by :meth:`update`.

        Returns
        -------
        closure : (2,) float64 array
            Per eye (the subject's right first), the share of the key frame's opening closed: 0
            as on the key frame, 1 shut, negative opened wider.
        iris : (2, 2) float64 array
            Per eye, the iris centre's shift (u, v) from its key-frame place, eye widths.
        """
        closure = 1.0 - state.opening / np.maximum(self.key.opening, 1e-6)
        shift = state.iris - state.rest
        shift = np.sign(shift) * np.maximum(np.abs(shift) - IRIS_STILL, 0.0)  # the measure's noise: still
        seen = state.seen & (closure <= IRIS_HIDDEN)
        self._shift[seen] = shift[seen]
        return closure, self._shift.copy()
