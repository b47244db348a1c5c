"""Tracking a whole video file: read the init contours, run the :class:`Tracker` over every
frame from the init frame on, write the ``facemime.track/1`` JSON and optionally an overlay video
(H.264 MP4 or VP9 WebM) with the contours drawn. Outputs appear only when complete, both or
neither."""

from __future__ import annotations

import time
from contextlib import nullcontext
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from facemime.animate.head_pose import PoseFollower
from facemime.errors import InputFileError, InvalidInputError, NoFaceError
from facemime.io.contours_json import read_init, track_document, write_json
from facemime.io.outputs import Outputs
from facemime.io.video import CODECS, VideoReader, VideoWriter
from facemime.progress import track as progress
from facemime.track.knots import FrameResult
from facemime.track.overlay import draw_contours
from facemime.track.params import TrackerParams
from facemime.track.redetect import FaceTracker, Redetection
from facemime.types.contours import FEATURES


@dataclass
class TrackRun:
    """Summary of a tracked video: frames tracked (the first one included), seconds spent
    starting on the first frame (finding the face without an init, the tracker's set-up) and
    tracking the frames after it (decoding and encoding excluded from both), frames with a lost
    feature, frames the face landmark model put the contours right on, warnings for the user."""

    frames: int
    start_seconds: float
    seconds: float
    frames_with_lost: int
    redetected: list[int]
    warnings: list[str]


def track_video(
    video: str | Path,
    init: str | Path | None,
    out: str | Path,
    overlay: str | Path | None = None,
    force: bool = False,
    params: TrackerParams | None = None,
    redetection: Redetection | None = None,
    pose: bool = True,
) -> TrackRun:
    """Track a video and write the track file and, if asked, an overlay video, both or neither.
    The landmark model puts the contours right where they went astray
    (:class:`facemime.track.redetect.FaceTracker`).

    Parameters
    ----------
    video
        The video to track (any FFmpeg reads).
    init
        A ``facemime.init/1`` file: the eight contours on its frame (0 unless it names one), where
        tracking starts. None: the largest face's landmarks on the first frame that shows a face
        start the tracker. The frames before the start are not tracked.
    out
        The ``facemime.track/1`` file to write (must end in ``.json``): per tracked frame its
        0-based index, contours ((x, y) pixels), confidence per feature, lost features, whether
        the landmark model put it right and, with ``pose``, the head pose.
    overlay
        A video to write as well, ``.mp4`` (H.264) or ``.webm`` (VP9): every frame of ``video``,
        the tracked ones with the contours drawn; None: none.
    force
        Write over existing outputs (an input is refused all the same).
    params
        Tracker settings; None: the defaults.
    redetection
        When the landmark model checks the tracker; None: the defaults.
    pose
        Also measure the head pose of every frame with the face (the generic head fitted on the
        start frame, followed as ``run`` follows it: :class:`facemime.animate.head_pose.PoseFollower`;
        one landmark pass a frame). Where the start frame shows no face the landmark model finds
        (an init on a face it cannot see), the track has no pose, with a warning.

    Returns
    -------
    TrackRun
        Frames tracked, seconds starting and tracking, frames with a lost feature, the frames put
        right by the landmark model and warnings.
    """
    out = Path(out)
    if out.suffix.lower() != ".json":
        raise InvalidInputError(f"the track file must end in .json, got {out.name!r}")
    if overlay is not None and Path(overlay).suffix.lower() not in CODECS:
        raise InvalidInputError(f"overlay video must end in .mp4 or .webm, got {Path(overlay).name!r}")
    paths = [out] + ([Path(overlay)] if overlay is not None else [])
    with Outputs(paths, force, inputs=[video, init]) as outputs, VideoReader(video) as reader:
        start, contours = read_init(init, size=(reader.width, reader.height)) if init is not None else (0, None)
        writer = VideoWriter(outputs.stage(overlay), reader.fps) if overlay is not None else None
        frames: list[dict] = []
        tracker: FaceTracker | None = None
        follower: PoseFollower | None = None
        pose_warning: str | None = None
        face_before = True
        start_seconds, seconds, lost_frames, decoded = 0.0, 0.0, 0, 0
        with writer if writer is not None else nullcontext():
            for index, frame in enumerate(progress(reader, reader.frames or None, "tracking")):
                decoded += 1
                if index < start:
                    if writer is not None:
                        writer.write(frame)
                    continue
                t0 = time.perf_counter()
                if tracker is None:
                    try:
                        tracker = FaceTracker(frame, contours, params, redetection)
                    except NoFaceError:  # only without init: look on the next frame
                        if writer is not None:
                            writer.write(frame)
                        continue
                    start = index
                    result = FrameResult(index, tracker.contours, dict.fromkeys(FEATURES, 1.0))
                    if pose:
                        follower, pose_warning = _follow_pose(frame, index, video, tracker, reader.fps)
                    face = True
                    start_seconds = time.perf_counter() - t0
                else:
                    result = tracker.update(frame)
                    face = result.face
                    if follower is not None:
                        follower.update(frame, face_before, face)
                    seconds += time.perf_counter() - t0
                lost_frames += bool(result.lost)
                entry = {
                    "index": index,
                    "contours": result.contours,
                    "confidence": result.confidence,
                    "lost": result.lost,
                    "redetected": result.redetected,
                }
                if follower is not None and face:
                    entry["pose"] = follower.pose.as_dict()
                frames.append(entry)
                face_before = face
                if writer is not None:
                    writer.write(draw_contours(frame, result.contours, result.lost))
            if decoded == 0:
                raise InputFileError(f"video {video} has no frames")
            if tracker is None and init is None:
                raise NoFaceError(
                    f"no face found in any of the {decoded} frames of {video}; pass the contours with --init INIT.json"
                )
            if tracker is None:
                raise InvalidInputError(f"init frame {start} is beyond the last frame ({decoded - 1}) of {video}")
        info = {"width": reader.width, "height": reader.height, "fps": reader.fps, "frames": decoded}
        write_json(
            outputs.stage(out),
            track_document(
                info, frames, {"processing_seconds": round(start_seconds + seconds, 4), "frames_processed": len(frames)}
            ),
        )
    first = "the first frame" if start == 0 else f"frame {start}"
    warnings = list(reader.warnings)
    if tracker.faces > 1:
        warnings.append(f"{tracker.faces} faces found in {first} of {video}; tracking the largest")
    if init is None and start > 0:
        warnings.append(f"no face in frames 0-{start - 1} of {video}; tracking from frame {start}")
    if pose_warning is not None:
        warnings.append(pose_warning)
    return TrackRun(
        len(frames), start_seconds, seconds, lost_frames, [f["index"] for f in frames if f["redetected"]], warnings
    )


def _follow_pose(
    frame: np.ndarray, index: int, video: str | Path, tracker: FaceTracker, fps: float
) -> tuple[PoseFollower | None, str | None]:
    """The head pose's follower from the start frame, or None and the warning that says why not
    (no face the landmark model finds there)."""
    if tracker.motion is None:
        return None, "the tracker's settings turn its head motion off: the track has no head pose"
    try:
        return PoseFollower.on_face(frame, f"frame {index} of {video}", tracker, fps), None
    except NoFaceError:
        return None, f"no face the landmark model finds on frame {index} of {video}: the track has no head pose"
