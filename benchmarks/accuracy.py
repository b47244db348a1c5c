"""Tracking accuracy on the ten shared videos (NME of the shared data README), initialised from
the reference contours of the first frame, against three baselines measured in the same run:

- static: the first frame's contours held;
- LK: OpenCV's pyramidal Lucas-Kanade (calcOpticalFlowPyrLK, 21×21 window, 3 levels) tracking the
  same points frame to frame, with a forward-backward check (a point whose back-tracked position
  lands more than 1 px from where it started keeps its previous position);
- landmarks alone: the package's face landmark model read every frame (one pass on the crop the
  last landmarks frame, as the analysis runs it for the head pose), no snakes. The references
  are a Face Mesh's too (MediaPipe's, with its iris refinement): this baseline shares their
  convention, and its figures flatter it against the snakes, which settle on the image's edges.

Next to the NME, **mouth opening**: per frame, the error of the inner lips' opening (the
distance from the inner upper to the inner lower lip along the mouth's normal, mean over the
middle half of the mouth) over the IOD. NME hides an inner mouth that stays shut over teeth
(its error is spread over the curves' points); this figure does not.

The tracker is the product's (:class:`facemime.track.redetect.FaceTracker`: the snakes, put right
by the face landmark model where they went astray); the same snakes without re-detection run
beside it. With ``--variants`` the tracker also runs with other image operators H (gradient magnitude,
luma only, colour only) to show why the default is what it is. With ``--starts N`` the default
tracker also starts from N − 1 perturbed references (Gaussian noise of :data:`START_NOISE` px on
every point, seeds 1..N−1): a face-pulling video's failures swing with such noise, and one start
tells little about them. With ``--automatic`` it also starts from the face landmarks found on
the first frame, as ``facemime track`` does without ``--init``, and prints that start's figures
per video next to the reference start's.

    python benchmarks/accuracy.py [--data ../shared/data] [--videos lp_d0,vr_1] [--variants] [--starts 8]
                                  [--automatic]

Prints one table per feature group and, last, one JSON line with every figure.
"""

from __future__ import annotations

import argparse
import itertools
import json
import time
from dataclasses import replace
from pathlib import Path

import cv2
import numpy as np

from facemime.io.video import VideoReader
from facemime.metrics import group_nme, pooled_summary, resample, summarize
from facemime.networks.finder import follow_face
from facemime.track.params import TrackerParams
from facemime.track.redetect import FaceTracker, Redetection
from facemime.types.contours import CONTOUR_NAMES, GROUPS, from_face_mesh

VIDEOS = ("lp_d0", "lp_d3", "lp_d6", "lp_d12", "vr_1", "vr_2", "st_aoc", "st_kh", "mt_sun", "mt_yongen")
ROOT = Path(__file__).resolve().parents[1]
SCORED = tuple(GROUPS) + ("mouth_opening",)
START_NOISE = 0.2  # px: standard deviation of the noise on the perturbed starts' points


def mouth_opening(contours: dict) -> float:
    """Inner-lip opening (px): lower minus upper inner lip along the normal of the corner line,
    mean over the middle half of the mouth."""
    upper, lower = resample(contours["mouth_inner_upper"], 9), resample(contours["mouth_inner_lower"], 9)
    along = upper[-1] - upper[0]
    down = np.array([-along[1], along[0]]) / max(float(np.linalg.norm(along)), 1e-9)
    return float(((lower - upper)[2:7] @ down).mean())


#: The snakes alone: no landmark checks (a feature lost for good stays lost).
NO_REDETECTION = Redetection(check_every=0, lost_for=0)
Method = tuple[TrackerParams, Redetection]


def variants() -> dict[str, Method]:
    p, r = TrackerParams(), Redetection()
    luma_only = {k: replace(getattr(p, k), luma=1.0, chroma=0.0) for k in ("mouth", "mouth_inner", "brows")}
    colour_only = {k: replace(getattr(p, k), luma=0.0, chroma=1.0) for k in ("mouth", "mouth_inner")}
    return {
        "facemime (directional, luma + colour)": (p, r),
        "facemime without re-detection": (p, NO_REDETECTION),
        "facemime, H = gradient magnitude": (p.with_(operator="magnitude"), r),
        "facemime, H = directional luma only": (p.with_(**luma_only), r),
        "facemime, H = directional colour only (mouth)": (p.with_(**colour_only), r),
    }


def run_tracker(
    frames: list[np.ndarray], init: dict | None, method: Method
) -> tuple[list[dict], int, list[int], float]:
    """The contours of frames 1.. tracked from ``init`` (None: the first frame's landmarks),
    the frames with a lost feature, those re-detected, and the seconds of the landmark checks."""
    tracker = FaceTracker(frames[0], init, *method)
    out, lost = [], 0
    for frame in frames[1:]:
        r = tracker.update(frame)
        out.append(r.contours)
        lost += bool(r.lost)
    return out, lost, tracker.redetected, tracker.checking_seconds


def run_lk(frames: list[np.ndarray], init: dict) -> list[dict]:
    grays = [cv2.cvtColor(f, cv2.COLOR_RGB2GRAY) for f in frames]
    sizes = [len(init[n]) for n in CONTOUR_NAMES]
    pts = np.concatenate([init[n] for n in CONTOUR_NAMES]).astype(np.float32)
    out = []
    for prev, cur in itertools.pairwise(grays):
        lk = {"winSize": (21, 21), "maxLevel": 3}
        p1, st1, _ = cv2.calcOpticalFlowPyrLK(prev, cur, pts.reshape(-1, 1, 2), None, **lk)
        back, st2, _ = cv2.calcOpticalFlowPyrLK(cur, prev, p1, None, **lk)
        ok = (st1.ravel() == 1) & (st2.ravel() == 1) & (np.linalg.norm(back.reshape(-1, 2) - pts, axis=1) <= 1.0)
        pts = np.where(ok[:, None], p1.reshape(-1, 2), pts)
        out.append(dict(zip(CONTOUR_NAMES, np.split(pts.astype(np.float64), np.cumsum(sizes)[:-1]))))
    return out


def run_landmarks(frames: list[np.ndarray], first: np.ndarray) -> list[dict]:
    """The contours of frames 1.. read from the package's face landmark model alone: one pass a
    frame on the crop the last landmarks frame (from the reference's on the first frame), as the
    analysis runs it for the pose; where the crop shows no face the last contours stay."""
    out, last = [], first
    for frame in frames[1:]:
        found = follow_face(frame, last)
        if found is not None:
            last = found
        out.append(from_face_mesh(last))
    return out


def score(tracks: list[dict], landmarks: np.ndarray, valid: np.ndarray, iod: np.ndarray) -> dict[str, np.ndarray]:
    """Per-frame NME of each group and mouth-opening error over IOD, over the scored frames
    (1..T-1 with a reference face)."""
    per = {g: [] for g in SCORED}
    for i, contours in enumerate(tracks, start=1):
        if not valid[i]:
            continue
        ref = from_face_mesh(landmarks[i])
        for g, names in GROUPS.items():
            per[g].append(group_nme(contours, ref, names, float(iod[i])))
        per["mouth_opening"].append(abs(mouth_opening(contours) - mouth_opening(ref)) / float(iod[i]))
    return {g: np.array(v) for g, v in per.items()}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--videos", default=",".join(VIDEOS))
    ap.add_argument("--variants", action="store_true", help="also run other image operators H")
    ap.add_argument(
        "--starts",
        type=int,
        default=1,
        help=f"starts of the default tracker: the reference and N-1 with {START_NOISE} px of noise on it",
    )
    ap.add_argument(
        "--automatic",
        action="store_true",
        help="also start the default tracker from the automatic "
        "fit of the first frame (as `facemime track` without --init)",
    )
    args = ap.parse_args()
    cv2.setNumThreads(1)
    methods = variants() if args.variants else dict(list(variants().items())[:2])
    names = ["static", "LK + FB", "landmarks alone"] + list(methods)
    series: dict[str, dict[str, list[np.ndarray]]] = {m: {g: [] for g in SCORED} for m in names}
    lost: dict[str, dict[str, int]] = {m: {} for m in methods}
    redetected: dict[str, dict[str, list[int]]] = {m: {} for m in methods}
    checks_ms: dict[str, dict[str, float]] = {m: {} for m in methods}  # per frame, amortised
    per_video: dict[str, dict] = {}
    labels: list[int | str] = list(range(1, args.starts)) + (["automatic"] if args.automatic else [])
    starts = {label: {g: [] for g in SCORED} for label in labels}
    starts_lost: dict[int | str, dict[str, int]] = {label: {} for label in labels}
    starts_video: dict[int | str, dict[str, dict]] = {label: {} for label in labels}
    for video in args.videos.split(","):
        z = np.load(args.data / "video" / f"{video}.landmarks.npz")
        with VideoReader(args.data / "video" / f"{video}.mp4") as reader:
            frames = list(reader)
        lm, valid, iod = z["landmarks"], z["valid"], z["iod"]
        start = int(np.flatnonzero(valid)[0])
        frames, lm, valid, iod = frames[start:], lm[start:], valid[start:], iod[start:]
        init = from_face_mesh(lm[0])
        runs = {
            "static": [init] * (len(frames) - 1),
            "LK + FB": run_lk(frames, init),
            "landmarks alone": run_landmarks(frames, lm[0].astype(np.float64)),
        }
        for m, method in methods.items():
            t0 = time.perf_counter()
            runs[m], lost[m][video], redetected[m][video], checks = run_tracker(frames, init, method)
            checks_ms[m][video] = 1e3 * checks / (len(frames) - 1)
            print(f"{video}: {m}: {len(frames) / (time.perf_counter() - t0):.0f} frames/s", flush=True)
        for label in labels:
            other = None
            if label != "automatic":
                rng = np.random.default_rng(label)
                other = {n: c + rng.normal(0.0, START_NOISE, c.shape) for n, c in init.items()}
            tracks, starts_lost[label][video], _, _ = run_tracker(frames, other, next(iter(methods.values())))
            scores = score(tracks, lm, valid, iod)
            starts_video[label][video] = {g: summarize(v) for g, v in scores.items()}
            for g, v in scores.items():
                starts[label][g].append(v)
        per_video[video] = {}
        for m, tracks in runs.items():
            scores = score(tracks, lm, valid, iod)
            per_video[video][m] = {g: summarize(v) for g, v in scores.items()}
            for g in SCORED:
                series[m][g].append(scores[g])
    pooled = {m: {g: pooled_summary(series[m][g]) for g in SCORED} for m in names}
    for g in SCORED:
        what = "opening error / IOD" if g == "mouth_opening" else "NME"
        print(f"\n{g} ({what} over {len(per_video)} videos, init frame excluded)")
        print(f"  {'method':48s} {'mean':>7s} {'median':>7s} {'p90':>7s} {'fail%':>6s} {'drift':>7s}   per-video mean")
        for m in names:
            s = pooled[m][g]
            pv = " ".join(f"{v}={per_video[v][m][g]['mean']:.3f}" for v in per_video)
            print(
                f"  {m:48s} {s['mean']:7.4f} {s['median']:7.4f} {s['p90']:7.4f} "
                f"{100 * s['failure_rate']:6.2f} {s['drift']:7.4f}   {pv}"
            )
    for m in methods:
        print(f"frames with a lost feature, {m}: {lost[m]}")
        print(f"frames re-detected, {m}: { {v: len(r) for v, r in redetected[m].items()} }")
        print(
            f"landmark checks, {m}: ms per frame, amortised, one thread: "
            + ", ".join(f"{v} {ms:.3f}" for v, ms in checks_ms[m].items())
        )
    default = next(iter(methods))
    spread = [{"seed": 0, "pooled": {g: pooled[default][g] for g in GROUPS}, "frames_with_lost": lost[default]}]
    spread += [
        {
            "seed": seed,
            "pooled": {g: pooled_summary(starts[seed][g]) for g in GROUPS},
            "frames_with_lost": starts_lost[seed],
        }
        for seed in starts
    ]
    if starts:
        print(
            f"\nstarts of the default tracker (seed 0: the reference; numbers: {START_NOISE} px of noise on it; "
            "automatic: the fit of the first frame)"
        )
        print(
            "       seed  " + "  ".join(f"{g + ' mean / fail%':>26s}" for g in GROUPS) + "  frames with a lost feature"
        )
        for run in spread:
            figures = "  ".join(
                f"{run['pooled'][g]['mean']:17.4f} / {100 * run['pooled'][g]['failure_rate']:5.2f}" for g in GROUPS
            )
            print(f"  {run['seed']!s:>9s}  {figures}  {sum(run['frames_with_lost'].values())}")
    if "automatic" in starts_video:
        auto, ref = starts_video["automatic"], default
        print("\nautomatic start against the reference start, per video: mean NME / failure % (reference -> automatic)")
        for video in per_video:
            print(
                f"  {video:10s} "
                + "  ".join(
                    f"{g} {per_video[video][ref][g]['mean']:.4f}/{100 * per_video[video][ref][g]['failure_rate']:.1f}"
                    f" -> {auto[video][g]['mean']:.4f}/{100 * auto[video][g]['failure_rate']:.1f}"
                    for g in GROUPS
                )
            )
    print(
        json.dumps(
            {
                "pooled": pooled,
                "per_video": per_video,
                "frames_with_lost": lost,
                "redetected": redetected,
                "checks_ms_per_frame": checks_ms,
                "starts": spread[1:],
                "starts_per_video": starts_video,
            },
            allow_nan=True,
        )
    )


if __name__ == "__main__":
    main()
