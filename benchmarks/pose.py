"""Head pose on the ten shared videos against the reference Face Mesh points (issue 63).

Truth: the reference's rotation of each frame relative to the first, by orthogonal Procrustes of
its rigid 3-D landmarks (:data:`facemime.animate.landmark_pose.RIGID`: forehead, temples, nose,
eye corners, cheekbones) on the first frame's. Each estimate's rotation is taken relative to its
own first frame the same way (R_t R_0^T), as yaw, pitch and roll (degrees,
:func:`facemime.render.projection.rotation_matrix`'s convention):

- **run**: the pose of ``facemime run``'s analysis (:class:`facemime.animate.analysis.Analysis`);
- **landmarks**: :class:`facemime.animate.landmark_pose.LandmarkPose` on one landmark pass a frame
  (:func:`facemime.face.finder.follow_face`: the crop the last frame's landmarks frame, no
  detection), unfiltered, then through :class:`~facemime.animate.landmark_pose.PoseFilter`
  (One-Euro) and a constant-velocity Kalman filter at the settings asked for.

Per video and axis: the mean absolute error (degrees), that of reporting no rotation at all, and
the slope of the estimate on the truth (least squares through the origin; 1 = fully measured).
Also the landmark pass's and the alignment's milliseconds a frame (this machine, one thread).

    python benchmarks/pose.py [--data ../shared/data] [--videos lp_d0,vr_1] [--frames N]
                              [--filters C:B,...] [--kalman Q:R,...]

Prints a table per video, the means over the videos, and one JSON line with every figure.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import json
import time
from pathlib import Path

import cv2
import numpy as np

from facemime.animate.analysis import Analysis
from facemime.animate.landmark_pose import RIGID, LandmarkPose, PoseFilter, angles, camera_points, procrustes
from facemime.face.finder import find_face, follow_face
from facemime.io.video import VideoReader
from facemime.render.projection import Pose, rotation_matrix

VIDEOS = ("lp_d0", "lp_d3", "lp_d6", "lp_d12", "mt_sun", "mt_yongen", "st_aoc", "st_kh", "vr_1", "vr_2")
ROOT = Path(__file__).resolve().parents[1]
AXES = ("yaw", "pitch", "roll")


def reference_angles(landmarks: np.ndarray, valid: np.ndarray) -> np.ndarray:
    """(T, 3) yaw, pitch, roll of each frame's rigid reference points relative to frame 0's (NaN
    where the reference has no face)."""
    first = camera_points(landmarks[0][list(RIGID)])
    out = np.full((len(landmarks), 3), np.nan)
    for t in np.flatnonzero(valid):
        _, rot, _ = procrustes(first, camera_points(landmarks[t][list(RIGID)]))
        out[t] = angles(rot)
    return out


def relative(poses: list[Pose]) -> np.ndarray:
    """(T, 3) yaw, pitch, roll of each pose's rotation relative to the first's."""
    r0 = rotation_matrix(poses[0].yaw, poses[0].pitch, poses[0].roll)
    return np.array([angles(rotation_matrix(p.yaw, p.pitch, p.roll) @ r0.T) for p in poses])


def figures(estimate: np.ndarray, truth: np.ndarray) -> dict[str, dict[str, float]]:
    """Per axis: mean absolute error, that of no rotation, slope of estimate on truth."""
    ok = np.isfinite(truth).all(axis=1) & np.isfinite(estimate).all(axis=1)
    e, t = estimate[ok], truth[ok]
    return {
        axis: {
            "mae": float(np.abs(e[:, k] - t[:, k]).mean()),
            "none": float(np.abs(t[:, k]).mean()),
            "slope": float((e[:, k] @ t[:, k]) / max(t[:, k] @ t[:, k], 1e-12)),
            "et": float(e[:, k] @ t[:, k]),
            "tt": float(t[:, k] @ t[:, k]),
        }
        for k, axis in enumerate(AXES)
    }


class ConstantVelocity:
    """A constant-velocity Kalman filter of a pose's six values, each on its own, in the units of
    :class:`~facemime.animate.landmark_pose.PoseFilter` (degrees, percent of scale, model units):
    process noise ``q`` (units² a second³, white acceleration), measurement noise ``r`` (units²).
    The issue's other candidate beside the One-Euro filter, measured here only."""

    def __init__(self, fps: float, q: float, r: float):
        dt = 1.0 / fps
        self.f = np.array([[1.0, dt], [0.0, 1.0]])
        self.q = q * np.array([[dt**3 / 3, dt**2 / 2], [dt**2 / 2, dt]])
        self.r = r
        self.x: np.ndarray | None = None  # (6, 2) value and speed
        self.p = np.zeros((6, 2, 2))
        self.unit = 1.0

    def __call__(self, pose: Pose) -> Pose:
        if self.x is None:
            self.unit = pose.scale
        u = self.unit
        z = np.array([pose.yaw, pose.pitch, pose.roll, 100.0 * np.log(pose.scale), pose.tx / u, pose.ty / u])
        if self.x is None:
            self.x = np.column_stack([z, np.zeros(6)])
            self.p[:] = np.diag([self.r, 1e3])
        else:
            self.x = self.x @ self.f.T
            self.p = self.f @ self.p @ self.f.T + self.q
            gain = self.p[:, :, 0] / (self.p[:, 0, 0] + self.r)[:, None]  # (6, 2)
            self.x = self.x + gain * (z - self.x[:, 0])[:, None]
            self.p = self.p - gain[:, :, None] * self.p[:, None, 0, :]
        v = self.x[:, 0]
        return Pose(
            yaw=float(v[0]), pitch=float(v[1]), roll=float(v[2]), scale=float(np.exp(v[3] / 100.0)),
            tx=float(v[4] * u), ty=float(v[5] * u),
        )  # fmt: skip


def jitter(estimate: np.ndarray, truth: np.ndarray, fps: float) -> tuple[float, float]:
    """The mean frame-to-frame change of the rotation (degrees, the three angles' changes
    summed) over the stillest second of the reference: the estimate's and the reference's."""
    n = max(2, int(round(fps)))
    step = np.abs(np.diff(truth, axis=0)).sum(axis=1)
    est = np.abs(np.diff(estimate, axis=0)).sum(axis=1)
    if len(step) < n:
        return float("nan"), float("nan")
    sums = np.convolve(np.nan_to_num(step, nan=1e9), np.ones(n), "valid")
    i = int(np.argmin(sums))
    return float(est[i : i + n].mean()), float(step[i : i + n].mean())


def measure(
    video: Path,
    reference: Path,
    frames: int | None,
    settings: list[tuple[float, float]],
    kalman: list[tuple[float, float]] = (),
) -> dict:
    ref = np.load(reference)
    run_poses, landmark_poses = [], []
    passes, aligns = [], []
    with VideoReader(video) as reader:
        for n, frame in enumerate(reader):
            if frames is not None and n >= frames:
                break
            if n == 0:
                analysis = Analysis(frame, video.name)
                key = find_face(frame).landmarks
                estimator = LandmarkPose(
                    key, analysis.actor.pose, analysis.actor.model.vertices, analysis.actor.model.triangles
                )
                run_poses.append(analysis.actor.pose)
                landmark_poses.append(estimator.measure(key))
                last = key
                continue
            run_poses.append(analysis.update(frame).pose)
            t0 = time.perf_counter()
            found = follow_face(frame, last)
            t1 = time.perf_counter()
            passes.append(t1 - t0)
            if found is None:  # no face in the crop: the last pose stays
                landmark_poses.append(landmark_poses[-1])
                continue
            landmark_poses.append(estimator.measure(found))
            aligns.append(time.perf_counter() - t1)
            last = found
    count = len(run_poses)
    truth = reference_angles(ref["landmarks"][:count].astype(np.float64), ref["valid"][:count])
    fps = float(ref["fps"])
    estimates = {"run": relative(run_poses), "landmarks": relative(landmark_poses)}
    for cutoff, beta in settings:
        smooth = PoseFilter(fps, cutoff, beta)
        estimates[f"filtered {cutoff:g}/{beta:g}"] = relative([smooth(p) for p in landmark_poses])
    for q, r in kalman:
        smooth = ConstantVelocity(fps, q, r)
        estimates[f"kalman {q:g}/{r:g}"] = relative([smooth(p) for p in landmark_poses])
    out = {}
    for method, estimate in estimates.items():
        out[method] = figures(estimate, truth)
        out[method]["jitter"], out["reference jitter"] = jitter(estimate, truth, fps)
    return {
        "frames": count,
        **out,
        "pass_ms": 1000 * float(np.mean(passes)) if passes else float("nan"),
        "align_ms": 1000 * float(np.mean(aligns)) if aligns else float("nan"),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    parser.add_argument("--videos", default=",".join(VIDEOS))
    parser.add_argument("--frames", type=int, default=None, help="at most this many frames a video")
    parser.add_argument(
        "--filters", default="1:0.3", help="PoseFilter settings to compare, MIN_CUTOFF:BETA,... (Hz, Hz per unit/s)"
    )
    parser.add_argument(
        "--kalman", default="100:0.1,1000:0.1", help="constant-velocity Kalman settings to compare, Q:R,... (units)"
    )
    args = parser.parse_args()
    cv2.setNumThreads(1)
    settings = [tuple(float(v) for v in f.split(":")) for f in args.filters.split(",") if f]
    kalman = [tuple(float(v) for v in f.split(":")) for f in args.kalman.split(",") if f]
    results = {}
    for name in args.videos.split(","):
        data = args.data / "video"
        r = measure(data / f"{name}.mp4", data / f"{name}.landmarks.npz", args.frames, settings, kalman)
        results[name] = r
        print(
            f"{name} ({r['frames']} frames; landmark pass {r['pass_ms']:.1f} ms, alignment {r['align_ms']:.2f} ms; "
            f"reference jitter {r['reference jitter']:.3f}°)"
        )
        for method in (k for k in r if isinstance(r[k], dict)):
            cells = "  ".join(
                f"{a} {r[method][a]['mae']:5.2f}° (none {r[method][a]['none']:5.2f}) slope {r[method][a]['slope']:5.2f}"
                for a in AXES
            )
            print(f"  {method:18s} {cells}  jitter {r[method]['jitter']:.3f}°")
    print("mean over videos (slope: of all frames pooled; jitter: mean, the reference's in brackets)")
    first = next(iter(results.values()))
    reference_jitter = np.mean([r["reference jitter"] for r in results.values()])
    for method in (k for k in first if isinstance(first[k], dict)):
        rs = [r[method] for r in results.values()]
        cells = "  ".join(
            f"{a} {np.mean([r[a]['mae'] for r in rs]):5.2f}° "
            f"slope {sum(r[a]['et'] for r in rs) / sum(r[a]['tt'] for r in rs):5.2f}"
            for a in AXES
        )
        print(f"  {method:18s} {cells}  jitter {np.mean([r['jitter'] for r in rs]):.3f}° ({reference_jitter:.3f}°)")
    print(json.dumps(results))


if __name__ == "__main__":
    main()
