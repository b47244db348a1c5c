"""Head pose on the ten shared videos against the reference Face Mesh points (issue 63).

Truth: the reference's rotation of each frame relative to the first, by orthogonal Procrustes of
its rigid 3-D landmarks (:data:`facemime.animate.landmark_pose.RIGID`: forehead, temples, nose,
eye corners, cheekbones) on the first frame's. Each estimate's rotation is taken relative to its
own first frame the same way (R_t R_0^T), as yaw, pitch and roll (degrees,
:func:`facemime.types.pose.rotation_matrix`'s convention):

- **run**: the pose of ``facemime run``'s analysis (:class:`facemime.animate.analysis.Analysis`);
- **landmarks**: :class:`facemime.animate.landmark_pose.LandmarkPose` on one landmark pass a frame
  (:func:`facemime.networks.finder.follow_face`: the crop the last frame's landmarks frame, no
  detection), unfiltered, then through :class:`~facemime.animate.landmark_pose.PoseFilter`
  (One-Euro) and a constant-velocity Kalman filter at the settings asked for.

- **openseeface** (with ``--openseeface DIR``): the peer, OpenSeeFace's tracker (BSD-2,
  github.com/emilianavt/OpenSeeFace; a checkout at DIR with its ``models`` folder, and
  ``onnxruntime`` installed apart: neither is a facemime dependency), landmark model
  ``--openseeface-model`` (0 by default: the only one its repository snapshot here holds whole),
  one thread: its head rotation, OpenCV's ``solvePnP`` of its 3-D face model, in this frame.

Per video and axis: the mean absolute error (degrees), that of reporting no rotation at all, and
the slope of the estimate on the truth (least squares through the origin; 1 = fully measured).
Also milliseconds a frame (this machine, one thread): the landmark pass and the alignment, the
whole of ``run``'s analysis (contours, pose, eyes), and the peer's tracker.

    python benchmarks/pose.py [--data ../shared/data] [--videos lp_d0,vr_1] [--frames N]
                              [--filters C:B,...] [--kalman Q:R,...] [--openseeface DIR]

Prints a table per video, the means over the videos, and one JSON line with every figure.
"""

from __future__ import annotations

import os

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import argparse
import json
import sys
import time
from pathlib import Path
from types import SimpleNamespace

import cv2
import numpy as np

from facemime.animate.analysis import Analysis
from facemime.animate.landmark_pose import RIGID, LandmarkPose, PoseFilter, angles, camera_points, procrustes
from facemime.io.video import VideoReader
from facemime.networks.finder import find_face, follow_face
from facemime.types.pose import Pose, rotation_matrix

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


#: OpenSeeFace's camera frame to this benchmark's (x right, y up, z back): its landmarks are (row,
#: column), so its solvePnP sees the picture transposed; after the swap, OpenCV's frame (x right,
#: y down, z forward) turned half a turn about the optical axis is the one in which the signs of
#: its yaw, pitch and roll agree with the reference's (found on lp_d3, st_aoc and st_kh: each
#: other choice reversed one or two of them on all three).
PEER_FRAME = np.diag([-1.0, 1.0, -1.0]) @ np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])


class OpenSeeFace:
    """The peer: OpenSeeFace's tracker from a checkout at ``folder``, for frames of ``size``
    (width, height), landmark model ``model``, one thread."""

    def __init__(self, folder: Path, size: tuple[int, int], model: int):
        sys.path.insert(0, str(folder))
        import tracker as osf  # the peer's module, from its checkout

        def flat_pnp(*args, **kwargs):
            # its code turns solvePnP's (3, 1) vectors into rows and adds them to 3-vectors, which
            # numpy 2 refuses; flat vectors give it what it expects (its own arithmetic unchanged)
            ok, rvec, tvec = cv2.solvePnP(*args, **kwargs)
            return ok, rvec.reshape(3), tvec.reshape(3)

        names = {n: getattr(cv2, n) for n in dir(cv2) if not n.startswith("__") and n != "solvePnP"}
        osf.cv2 = SimpleNamespace(**names, solvePnP=flat_pnp)
        self._tracker = osf.Tracker(
            *size, model_type=model, max_threads=1, silent=True, model_dir=str(folder / "models"), max_faces=1
        )
        self._rotation = np.eye(3)

    def rotation(self, rgb: np.ndarray) -> np.ndarray:
        """The head's rotation in ``rgb`` (the last one where it finds no face)."""
        faces = self._tracker.predict(cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR))
        if faces and faces[0].success:
            seen = cv2.Rodrigues(np.asarray(faces[0].rotation, np.float64))[0]
            self._rotation = PEER_FRAME @ seen @ PEER_FRAME.T
        return self._rotation


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
    peer: tuple[Path, int] | None = None,
) -> dict:
    ref = np.load(reference)
    run_poses, landmark_poses, peer_rotations = [], [], []
    passes, aligns, runs, peer_times = [], [], [], []
    with VideoReader(video) as reader:
        for n, frame in enumerate(reader):
            if frames is not None and n >= frames:
                break
            if peer is not None:
                if n == 0:
                    other = OpenSeeFace(peer[0], (frame.shape[1], frame.shape[0]), peer[1])
                t0 = time.perf_counter()
                peer_rotations.append(other.rotation(frame))
                peer_times.append(time.perf_counter() - t0)
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
            t0 = time.perf_counter()
            run_poses.append(analysis.update(frame).pose)
            runs.append(time.perf_counter() - t0)
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
    if peer_rotations:
        estimates["openseeface"] = np.array([angles(r @ peer_rotations[0].T) for r in peer_rotations])
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
        "run_ms": 1000 * float(np.mean(runs)) if runs else float("nan"),
        "peer_ms": 1000 * float(np.mean(peer_times)) if peer_times else float("nan"),
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
    parser.add_argument("--openseeface", type=Path, default=None, help="an OpenSeeFace checkout: run the peer too")
    parser.add_argument("--openseeface-model", type=int, default=0, help="the peer's landmark model (0-4)")
    args = parser.parse_args()
    cv2.setNumThreads(1)
    peer = None if args.openseeface is None else (args.openseeface, args.openseeface_model)
    settings = [tuple(float(v) for v in f.split(":")) for f in args.filters.split(",") if f]
    kalman = [tuple(float(v) for v in f.split(":")) for f in args.kalman.split(",") if f]
    results = {}
    for name in args.videos.split(","):
        data = args.data / "video"
        r = measure(data / f"{name}.mp4", data / f"{name}.landmarks.npz", args.frames, settings, kalman, peer)
        results[name] = r
        print(
            f"{name} ({r['frames']} frames; landmark pass {r['pass_ms']:.1f} ms, alignment {r['align_ms']:.2f} ms, "
            f"run's analysis {r['run_ms']:.1f} ms, peer {r['peer_ms']:.1f} ms; "
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
    for key, what in (("pass_ms", "landmark pass"), ("run_ms", "run's analysis"), ("peer_ms", "peer")):
        print(f"  {what}: {np.mean([r[key] for r in results.values()]):.1f} ms a frame")
    print(json.dumps(results))


if __name__ == "__main__":
    main()
