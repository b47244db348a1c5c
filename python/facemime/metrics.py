"""The contour error metric of the project (NME, as the shared data's README defines it).

For one curve: resample prediction P and reference R at 100 points equally spaced in arc length,
take the mean distance of each sample set to the other polyline, average the two directions and
divide by the inter-ocular distance (IOD, pixels). Missing or non-finite curves score +inf.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np

SAMPLES = 100
#: NME above which a frame counts as a failure.
FAILURE_NME = 0.10


def resample(curve: np.ndarray, n: int = SAMPLES) -> np.ndarray:
    """``n`` points equally spaced in arc length along a polyline, both ends included.

    Parameters
    ----------
    curve
        (M, 2) float array, M >= 2: the polyline's (x, y) vertices, pixels.
    n
        How many points to take.

    Returns
    -------
    (n, 2) float64 array
        The points, (x, y) pixels, from the first vertex of ``curve`` to its last.

    Examples
    --------
    >>> resample(np.array([[0.0, 0.0], [4.0, 0.0]]), 5)[:, 0].tolist()
    [0.0, 1.0, 2.0, 3.0, 4.0]
    """
    seg = np.linalg.norm(np.diff(curve, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(seg)])
    t = np.linspace(0.0, s[-1], n)
    return np.stack([np.interp(t, s, curve[:, 0]), np.interp(t, s, curve[:, 1])], axis=1)


def _distance_to_polyline(points: np.ndarray, line: np.ndarray) -> np.ndarray:
    """Distance (pixels) from each of ``points`` (N, 2) to the nearest point of polyline ``line``."""
    a, b = line[:-1], line[1:]
    ab = b - a
    denom = np.maximum((ab * ab).sum(axis=1), 1e-12)
    t = np.clip(((points[:, None, :] - a[None]) * ab[None]).sum(axis=2) / denom, 0.0, 1.0)
    nearest = a[None] + t[..., None] * ab[None]
    return np.linalg.norm(points[:, None, :] - nearest, axis=2).min(axis=1)


def curve_error(pred: object, ref: np.ndarray) -> float:
    """Symmetric mean curve distance: the mean of the two directions' mean sample distances.

    Parameters
    ----------
    pred
        The predicted curve: (M, 2) array-like of (x, y) pixels, or None when missing.
    ref
        (M, 2) float array, M >= 2: the reference curve's (x, y) pixels.

    Returns
    -------
    float
        The distance, pixels; +inf when ``pred`` is missing or malformed (not (M >= 2, 2), or a
        non-finite coordinate).
    """
    if pred is None:
        return float("inf")
    p = np.asarray(pred, dtype=np.float64)
    if p.ndim != 2 or p.shape[0] < 2 or p.shape[1] != 2 or not np.isfinite(p).all():
        return float("inf")
    r = np.asarray(ref, dtype=np.float64)
    d_pr = _distance_to_polyline(resample(p), r).mean()
    d_rp = _distance_to_polyline(resample(r), p).mean()
    return float((d_pr + d_rp) / 2.0)


def group_nme(
    pred: Mapping[str, object] | None, ref: Mapping[str, np.ndarray], names: Sequence[str], iod: float
) -> float:
    """Mean NME of some curves of one frame.

    Parameters
    ----------
    pred
        The frame's predicted curves by name, each (M, 2) (x, y) pixels; None when the frame has
        none.
    ref
        The frame's reference curves by name, each (M, 2) float array of (x, y) pixels.
    names
        The curves to score (each must be in ``ref``).
    iod
        The frame's inter-ocular distance (outer eye corners), pixels.

    Returns
    -------
    float
        The mean of the curves' :func:`curve_error` divided by ``iod`` (no unit); +inf if any
        predicted curve is missing or malformed.
    """
    pred = pred or {}
    return float(np.mean([curve_error(pred.get(n), ref[n]) for n in names])) / iod


def summarize(per_frame: np.ndarray) -> dict[str, float]:
    """Summary statistics of one video's per-frame NMEs.

    Parameters
    ----------
    per_frame
        (F,) float array: the NME of each frame, in frame order; +inf where a curve was not
        produced.

    Returns
    -------
    dict of str -> float
        ``mean`` (of the finite values), ``median`` and ``p90`` (of all, +inf included),
        ``failure_rate`` (share of frames above :data:`FAILURE_NME` or not finite) and ``drift``
        (mean of the last third of the frames less that of the first third, finite values);
        NaN where there are no frames (``drift``: fewer than 3).
    """
    v = np.asarray(per_frame, dtype=np.float64)
    finite = v[np.isfinite(v)]
    third = len(v) // 3
    first, last = v[:third], v[len(v) - third :]
    mean_f = lambda x: float(np.mean(x[np.isfinite(x)])) if np.isfinite(x).any() else float("nan")  # noqa: E731
    return {
        "mean": float(finite.mean()) if finite.size else float("nan"),
        "median": float(np.quantile(v, 0.5, method="inverted_cdf")) if v.size else float("nan"),
        "p90": float(np.quantile(v, 0.9, method="inverted_cdf")) if v.size else float("nan"),
        "failure_rate": float(np.mean(~(v <= FAILURE_NME))) if v.size else float("nan"),
        "drift": mean_f(last) - mean_f(first) if third else float("nan"),
    }


def pooled_summary(per_video: Sequence[np.ndarray]) -> dict[str, float]:
    """Summary over several videos, each weighing the same.

    Parameters
    ----------
    per_video
        Per video, its (F,) float array of per-frame NMEs (as :func:`summarize` takes); videos
        without frames are skipped.

    Returns
    -------
    dict of str -> float
        The keys of :func:`summarize`: ``mean``, ``failure_rate`` and ``drift`` are means of the
        per-video values (NaN ones skipped); ``median`` and ``p90`` are percentiles of all frames,
        each weighted by 1 / its video's frame count.
    """
    summaries = [summarize(v) for v in per_video if len(v)]
    out = {k: float(np.nanmean([s[k] for s in summaries])) for k in ("mean", "failure_rate", "drift")}
    values = np.concatenate([np.asarray(v, np.float64) for v in per_video if len(v)])
    weights = np.concatenate([np.full(len(v), 1.0 / len(v)) for v in per_video if len(v)])
    order = np.argsort(values)
    cum = np.cumsum(weights[order]) / weights.sum()
    for key, q in (("median", 0.5), ("p90", 0.9)):
        out[key] = float(values[order][np.searchsorted(cum, q)])
    return out


#: Face Mesh points of each eye in a reference (the subject's right first): the corners (image-left
#: one first), the upper and lower lids' middles, the iris's centre (478-point refined landmarks).
EYE_POINTS = ((33, 133, 159, 145, 468), (362, 263, 386, 374, 473))


def reference_eyes(landmarks: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The eyes of a Face Mesh reference, per frame, relative to its first frame.

    Parameters
    ----------
    landmarks
        (T, 478, 2+) float array: refined Face Mesh landmarks (the shared data's), (x, y) pixels
        first.

    Returns
    -------
    opening : (T, 2) float64 array
        Per eye (the subject's right first), the distance between the lids' middles over the eye's
        width (corner to corner), over the first frame's.
    iris : (T, 2, 2) float64 array
        Per eye, the iris centre's (u, v) shift from its first-frame place relative to the eye's
        corners, eye widths: u along the eye towards its image-right corner, v across it, down.
    """
    p = np.asarray(landmarks, np.float64)[:, :, :2]
    opening, iris = np.zeros((len(p), 2)), np.zeros((len(p), 2, 2))
    for eye, (a, b, up, low, centre) in enumerate(EYE_POINTS):
        width = np.linalg.norm(p[:, b] - p[:, a], axis=1)
        along = (p[:, b] - p[:, a]) / width[:, None]
        across = np.stack([-along[:, 1], along[:, 0]], axis=1)
        rel = p[:, centre] - (p[:, a] + p[:, b]) / 2
        o = np.linalg.norm(p[:, up] - p[:, low], axis=1) / width
        opening[:, eye] = o / o[0]
        iris[:, eye] = np.stack([(rel * along).sum(1), (rel * across).sum(1)], axis=1) / width[:, None]
    return opening, iris - iris[:1]
