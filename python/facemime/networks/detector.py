"""Face detection with MediaPipe's short-range face detector (BlazeFace, 128 x 128 input), run by
OpenCV's ``cv2.dnn``.

The network scores 896 fixed anchors and regresses, per anchor, a box and six keypoints as
offsets from the anchor's centre in input pixels. Detections are decoded here, weighted
non-maximum suppression merges the overlapping ones, and they are mapped back to the image.

Boxes are (x0, y0, x1, y1) and keypoints (x, y), in pixels of the image searched: x right, y
down, (0, 0) at the centre of the top-left pixel. The keypoints are, in order, the subject's
right eye (image left), left eye, nose tip, mouth centre, right ear tragion, left ear tragion.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cache

import cv2
import numpy as np

from facemime.networks.network import load_network
from facemime.render.bilinear import sample_affine

#: Side of the detector's square input, pixels.
INPUT = 128
#: Anchor layout of the short-range model: the feature maps' strides (input pixels) and the
#: anchors per cell (two per stride-8 cell, six per stride-16 cell: 16*16*2 + 8*8*6 = 896).
STRIDES = (8, 16)
ANCHORS_PER_CELL = (2, 6)
#: Lowest detection score (after the sigmoid) kept, and the overlap (intersection over union)
#: above which two detections are merged: MediaPipe's settings for this model.
MIN_SCORE = 0.5
MIN_OVERLAP = 0.3
#: Raw scores are clipped to this before the sigmoid (as MediaPipe does).
SCORE_CLIP = 100.0


@dataclass(frozen=True)
class Detection:
    """One face found by the detector.

    Attributes
    ----------
    box : (4,) float64 array
        (x0, y0, x1, y1), pixels.
    keypoints : (6, 2) float64 array
        (x, y) pixels: right eye, left eye, nose tip, mouth centre, right ear, left ear
        (the subject's sides).
    score : float
        Detection confidence, 0..1.
    """

    box: np.ndarray
    keypoints: np.ndarray
    score: float

    @property
    def size(self) -> float:
        """The larger side of the box, pixels."""
        return float(max(self.box[2] - self.box[0], self.box[3] - self.box[1]))


@cache
def anchors() -> np.ndarray:
    """The 896 anchor centres, in the network's output order (row by row, cell by cell, the
    anchors of a cell together).

    Returns
    -------
    (896, 2) float64 array
        (x, y) of each anchor's centre, as fractions of the input side (0..1, y down).
    """
    out = []
    for stride, per_cell in zip(STRIDES, ANCHORS_PER_CELL):
        cells = INPUT // stride
        y, x = np.mgrid[0:cells, 0:cells]
        centres = (np.column_stack([x.ravel(), y.ravel()]) + 0.5) / cells
        out.append(np.repeat(centres, per_cell, axis=0))
    return np.concatenate(out)


def decode(scores: np.ndarray, regressors: np.ndarray, min_score: float = MIN_SCORE) -> list[Detection]:
    """The detections of one network pass, in input fractions (0..1 across the input).

    Parameters
    ----------
    scores
        (896,) float array: raw (pre-sigmoid) anchor scores.
    regressors
        (896, 16) float array: per anchor, the box centre's offset (x, y) from the anchor's
        centre, the box width and height, then six keypoint offsets (x, y) from the anchor's
        centre, all in input pixels.
    min_score
        Lowest sigmoid score kept, 0..1.

    Returns
    -------
    list of Detection
        The anchors scoring ``min_score`` or more, in anchor order, unsuppressed: ``box`` and
        ``keypoints`` as fractions of the input side, ``score`` after the sigmoid.

    Examples
    --------
    >>> raw = np.zeros((896, 16)); raw[0, 2:4] = 16.0
    >>> d = decode(np.r_[5.0, np.full(895, -5.0)], raw)
    >>> len(d), d[0].box.round(4).tolist()
    (1, [-0.0312, -0.0312, 0.0938, 0.0938])
    """
    scores = 1.0 / (1.0 + np.exp(-np.clip(np.asarray(scores, np.float64), -SCORE_CLIP, SCORE_CLIP)))
    keep = np.flatnonzero(scores >= min_score)
    raw = np.asarray(regressors, np.float64)[keep] / INPUT
    centre = anchors()[keep]
    xy = raw[:, :2] + centre
    half = raw[:, 2:4] / 2
    boxes = np.concatenate([xy - half, xy + half], axis=1)
    keypoints = raw[:, 4:].reshape(-1, 6, 2) + centre[:, None]
    return [Detection(b, k, float(s)) for b, k, s in zip(boxes, keypoints, scores[keep])]


def overlap(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Intersection over union of one box with each of several.

    Parameters
    ----------
    a
        (4,) float array: the box (x0, y0, x1, y1).
    b
        (N, 4) float array: the boxes (x0, y0, x1, y1), in ``a``'s units.

    Returns
    -------
    (N,) float64 array
        The overlap of ``a`` with each of ``b``, 0..1.

    Examples
    --------
    >>> overlap(np.array([0, 0, 2, 2.0]), np.array([[1, 0, 3, 2.0], [5, 5, 6, 6]]))
    array([0.33333333, 0.        ])
    """
    w = np.clip(np.minimum(a[2], b[:, 2]) - np.maximum(a[0], b[:, 0]), 0, None)
    h = np.clip(np.minimum(a[3], b[:, 3]) - np.maximum(a[1], b[:, 1]), 0, None)
    inter = w * h
    area = lambda r: (r[..., 2] - r[..., 0]) * (r[..., 3] - r[..., 1])  # noqa: E731
    return inter / np.maximum(area(a) + area(b) - inter, 1e-12)


def suppress(detections: list[Detection], min_overlap: float = MIN_OVERLAP) -> list[Detection]:
    """Weighted non-maximum suppression: the strongest detection left takes every detection
    overlapping it by more than ``min_overlap`` (itself included), and becomes their
    score-weighted mean box and keypoints, with its own score.

    Parameters
    ----------
    detections
        The detections to merge, in any order.
    min_overlap
        Intersection over union (0..1) above which a detection joins the strongest one's group.

    Returns
    -------
    list of Detection
        The merged detections, strongest first, in the units of ``detections``.

    Examples
    --------
    >>> a = Detection(np.array([0, 0, 10, 10.0]), np.zeros((6, 2)), 0.9)
    >>> b = Detection(np.array([2, 0, 12, 10.0]), np.ones((6, 2)), 0.6)
    >>> c = Detection(np.array([50, 50, 60, 60.0]), np.zeros((6, 2)), 0.7)
    >>> [(d.box.round(6).tolist(), d.score) for d in suppress([a, b, c])]
    [([0.8, 0.0, 10.8, 10.0], 0.9), ([50.0, 50.0, 60.0, 60.0], 0.7)]
    """
    left = sorted(detections, key=lambda d: -d.score)
    out = []
    while left:
        boxes = np.array([d.box for d in left])
        group = overlap(left[0].box, boxes) > min_overlap
        group[0] = True
        w = np.array([d.score for d in left])[group]
        members = [d for d, g in zip(left, group) if g]
        box = (w[:, None] * boxes[group]).sum(axis=0) / w.sum()
        keypoints = (w[:, None, None] * np.array([d.keypoints for d in members])).sum(axis=0) / w.sum()
        out.append(Detection(box, keypoints, left[0].score))
        left = [d for d, g in zip(left, group) if not g]
    return out


def _window_map(window: tuple[int, int, int]) -> np.ndarray:
    """The affine (2, 3) from the detector's input pixels to the pixels of a square ``window``
    (x, y, side) of an image."""
    x, y, side = window
    scale = side / INPUT
    # input pixel centre u maps to image coordinate x + (u + 0.5) * scale - 0.5
    return np.array([[scale, 0, x + 0.5 * scale - 0.5], [0, scale, y + 0.5 * scale - 0.5]])


def _turn_map(quarters: int, width: int, height: int) -> np.ndarray:
    """The affine (2, 3) from the pixels of a ``width`` x ``height`` image turned by
    ``quarters`` quarter turns counter-clockwise (``np.rot90``) back to the image's pixels.

    >>> image = np.arange(6).reshape(2, 3)
    >>> m = _turn_map(1, 3, 2); x, y = m @ [0, 2, 1]  # pixel (0, 2) of the turned image
    >>> int(np.rot90(image)[2, 0]) == int(image[int(y), int(x)])
    True
    """
    w, h = width - 1, height - 1
    return {
        0: np.array([[1.0, 0, 0], [0, 1, 0]]),
        1: np.array([[0.0, -1, w], [1, 0, 0]]),
        2: np.array([[-1.0, 0, w], [0, -1, h]]),
        3: np.array([[0.0, 1, 0], [-1, 0, h]]),
    }[quarters % 4]


def _compose(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The affine ``a`` after ``b``, both (2, 3)."""
    return np.column_stack([a[:, :2] @ b[:, :2], a[:, :2] @ b[:, 2] + a[:, 2]])


def windows(width: int, height: int) -> list[tuple[int, int, int]]:
    """The square windows (x, y, side) searched in a ``width`` x ``height`` image: the whole
    image letterboxed (centred), then, for faces too small for it (a person standing in a tall
    frame), squares of the shorter side along the longer one and squares of half the shorter
    side, each overlapping its neighbours by half.

    Parameters
    ----------
    width
        The image's width, pixels.
    height
        The image's height, pixels.

    Returns
    -------
    list of (x, y, side)
        Each window as int pixels: (x, y) of its top-left pixel (negative where the letterboxed
        whole image reaches beyond the image) and its side.

    Examples
    --------
    >>> windows(400, 200)
    [(0, -100, 400), (0, 0, 200), (100, 0, 200), (200, 0, 200)]
    """
    long, short = max(width, height), min(width, height)
    out = [((width - long) // 2, (height - long) // 2, long)]
    sides = ([short] if long > short else []) + ([short // 2] if short // 2 >= INPUT else [])
    for side in sides:
        spots = [
            np.linspace(0, extent - side, int(np.ceil(2 * (extent - side) / side)) + 1).round().astype(int)
            for extent in (width, height)
        ]
        out += [(int(x), int(y), side) for y in spots[1] for x in spots[0]]
    return out


def _search(rgb: np.ndarray, back: np.ndarray) -> list[Detection]:
    """One detector pass on the input sampled from ``rgb`` through ``back`` (the affine from
    input pixels to image pixels; zero beyond the image), detections of :data:`MIN_SCORE` or
    more in image pixels."""
    net = load_network("face_detection_short_range.tflite")
    crop = sample_affine(rgb, back, (INPUT, INPUT), border="zero")
    # MediaPipe feeds this model pixels scaled to [-1, 1].
    net.setInput(cv2.dnn.blobFromImage(crop, 2.0 / 255.0, mean=(127.5, 127.5, 127.5)))
    scores, regressors = net.forward(["classificators", "regressors"])
    found = []
    for d in decode(scores.reshape(-1), regressors.reshape(-1, 16)):
        # input fractions -> input pixel centres -> image pixels
        to_image = lambda f: (f * INPUT - 0.5) @ back[:, :2].T + back[:, 2]  # noqa: E731
        corners = to_image(d.box[[0, 1, 2, 1, 2, 3, 0, 3]].reshape(4, 2))
        found.append(Detection(np.r_[corners.min(axis=0), corners.max(axis=0)], to_image(d.keypoints), d.score))
    return found


def detect_faces(rgb: np.ndarray, min_score: float = MIN_SCORE) -> list[Detection]:
    """Faces scoring ``min_score`` or more in an image (detections from :data:`MIN_SCORE` up are
    merged by the suppression).

    The whole image is searched first; only where that detects nothing at all are the smaller
    windows of :func:`windows` searched (a face small in a large frame: a closer look also
    raises an animal's score, the shared monkey's from 0.78 to 0.84). Where neither holds a
    face of ``min_score``, the whole image turned by a quarter, a half and three quarters of a
    turn is searched (a phone video stored on its side, a photo upside down; the shared animal
    photos, turned, score 0.73 at most).

    Parameters
    ----------
    rgb
        (H, W, 3) uint8 RGB image.
    min_score
        Lowest detection score kept, 0..1.

    Returns
    -------
    list of Detection
        The faces, strongest first, boxes and keypoints in pixels of ``rgb``; empty when none.
    """
    h, w = rgb.shape[:2]
    whole, *parts = windows(w, h)
    found = _search(rgb, _window_map(whole))
    if not found:
        found = [d for p in parts for d in _search(rgb, _window_map(p))]
    faces = [d for d in suppress(found) if d.score >= min_score]
    for quarters in (1, 2, 3):
        if faces:
            break
        tw, th = (h, w) if quarters % 2 else (w, h)  # the turned image's size
        side = max(tw, th)
        turned = _compose(_turn_map(quarters, w, h), _window_map(((tw - side) // 2, (th - side) // 2, side)))
        faces = [d for d in suppress(_search(rgb, turned)) if d.score >= min_score]
    return faces
