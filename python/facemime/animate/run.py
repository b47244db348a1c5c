"""``facemime run``: analyse a face video and re-synthesise it on an actor, frame by frame.

Writes a side-by-side video (the original with the tracked contours | the synthesised face) that
browsers play, and the ``facemime.track/1`` JSON with contours, head pose and knot offsets per
frame. Outputs appear only when complete.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from facemime.animate.analysis import Analysis
from facemime.animate.synth import BACKGROUND, Puppet, UserMotion
from facemime.errors import InputFileError, InvalidInputError
from facemime.fit.actor import Actor
from facemime.fit.detect import NoFaceError
from facemime.fit.placement import model_iod
from facemime.io.actor_file import load_actor
from facemime.io.contours_json import track_document, write_json
from facemime.io.outputs import check_outputs
from facemime.io.video import CODECS, VideoReader, VideoWriter
from facemime.progress import track as progress
from facemime.render.projection import Pose
from facemime.render.texture_map import fill
from facemime.track.overlay import draw_contours
from facemime.track.tracker import TrackerParams

POSE_FIELDS = ("yaw", "pitch", "roll", "scale", "tx", "ty")
#: Tint of the synthesised half in frames without a face.
NO_FACE_DIM = 0.45


@dataclass
class RunResult:
    """What :func:`run_video` did: frames, frames without a face, the files written, warnings,
    and seconds per stage (``decode``, ``track``, ``pose``, ``synth``, ``compose``, ``fit``,
    ``encode``)."""

    frames: int
    frames_without_face: int
    files: list[Path]
    warnings: list[str] = field(default_factory=list)
    seconds: dict[str, float] = field(default_factory=dict)

    @property
    def _busy(self) -> float:
        """Seconds of per-frame work: all stages but video encoding and the one-off fit."""
        return max(sum(v for k, v in self.seconds.items() if k not in ("encode", "fit")), 1e-9)

    @property
    def fps(self) -> float:
        """Frames per second of the whole run with video encoding (and the one-off fit) excluded."""
        return self.frames / self._busy

    @property
    def shares(self) -> dict[str, float]:
        """Fraction of the per-frame work spent in each stage."""
        return {k: self.seconds[k] / self._busy for k in ("decode", "track", "pose", "synth", "compose")}


def pose_dict(pose: Pose) -> dict[str, float]:
    """The track file's ``pose`` entry."""
    return {k: getattr(pose, k) for k in POSE_FIELDS}


def run_video(video: str | Path, out: str | Path, actor: str | Path | Actor | None = None,
              track: str | Path | None = None, user: UserMotion = UserMotion(), force: bool = False,
              params: TrackerParams | None = None) -> RunResult:
    """Analyse ``video`` and write ``out`` (.mp4 or .webm, side by side) and ``track`` (default:
    ``out`` with the suffix ``.json``). ``actor``: an ``.actor`` file or an :class:`Actor` to
    drive (default: the actor fitted on the first frame). Existing outputs are refused unless
    ``force``."""
    out = Path(out)
    if out.suffix.lower() not in CODECS:
        raise InvalidInputError(f"the output video must end in .mp4 or .webm, got {out.name!r}")
    track = out.with_suffix(".json") if track is None else Path(track)
    if track.suffix.lower() != ".json":
        raise InvalidInputError(f"the track file must end in .json, got {track.name!r}")
    if track.resolve() == out.resolve():
        raise InvalidInputError("the output video and the track file must be different files")
    check_outputs([out, track], force)
    target = load_actor(actor) if isinstance(actor, (str, Path)) else actor
    seconds = dict.fromkeys(("decode", "track", "pose", "synth", "compose", "encode"), 0.0)
    frames: list[dict] = []
    warnings: list[str] = []
    analysis: Analysis | None = None
    puppet: Puppet | None = None
    with VideoReader(video) as reader, VideoWriter(out, reader.fps) as writer:
        size = (reader.width, reader.height)
        canvas = np.empty((reader.height, 2 * reader.width, 3), np.uint8)
        synth = np.empty((reader.height, reader.width, 3), np.uint8)
        stream = iter(progress(reader, reader.frames or None, "running"))
        while True:
            t0 = time.perf_counter()
            frame = next(stream, None)
            seconds["decode"] += time.perf_counter() - t0
            if frame is None:
                break
            if analysis is None:
                try:
                    analysis = Analysis(frame, f"the first frame of {video}", params)
                except NoFaceError as e:
                    raise NoFaceError(f"{e}; the video must start with a frontal face") from None
                warnings += analysis.warnings
                driven = analysis.actor if target is None else target
                puppet = Puppet(driven, analysis.deformer.feature_sizes(), model_iod(analysis.actor.model))
                motion = analysis.last
            else:
                motion = analysis.update(frame)
            t1 = time.perf_counter()
            fill(synth, BACKGROUND)
            puppet.render(motion.pose, motion.offsets, size, user, out=synth)
            t2 = time.perf_counter()
            if motion.face:
                draw_contours(frame, motion.contours, motion.lost, out=canvas[:, :reader.width])
            else:
                canvas[:, :reader.width] = frame
            canvas[:, reader.width:] = synth if motion.face else (synth * NO_FACE_DIM).astype(np.uint8)
            frames.append({"index": len(frames), "contours": motion.contours, "confidence": motion.confidence,
                           "lost": motion.lost, "face": motion.face, "pose": pose_dict(motion.pose),
                           "offsets": motion.offsets})
            t3 = time.perf_counter()
            writer.write(canvas)
            seconds["synth"] += t2 - t1
            seconds["compose"] += t3 - t2
            seconds["encode"] += time.perf_counter() - t3
        if analysis is None:
            raise InputFileError(f"video {video} has no frames")
        seconds.update(track=analysis.timings.track, pose=analysis.timings.pose, fit=analysis.timings.fit)
        info = {"width": reader.width, "height": reader.height, "fps": reader.fps, "frames": len(frames)}
        busy = sum(v for k, v in seconds.items() if k not in ("encode", "fit", "decode"))
        write_json(track, track_document(info, frames, {"processing_seconds": round(busy, 4), "frames_processed": len(frames)},
                                         analysis.model_block))
    return RunResult(len(frames), analysis.frames_without_face, [out, track], warnings, seconds)
