"""``facemime run``: analyse a face video and re-synthesise it on an actor, frame by frame.

Writes a side-by-side video (the original with the tracked contours | the synthesised picture:
the face in the driven actor's scene, or alone with ``mask_only``) that browsers play, and the
``facemime.track/1`` JSON with contours, head pose, knot offsets, look (the eyes,
:mod:`facemime.types.look`) and expression weights (:mod:`facemime.animate.expressions`)
per frame, and on request the weights as CSV (``frame,time_s,<names...>``); when the face is
synthesised in its own scene, also how far each frame departs from that synthesis
(:mod:`facemime.animate.departure`): per frame ``scene_departure`` (0..1) and
``scene_departs`` (bool), and top-level ``scene_departs`` (the [first, last] frame ranges
reported). Outputs appear only when complete. Given a track file instead of a video
(:func:`run_track`), it writes the synthesised picture of the track's motion alone.
"""

from __future__ import annotations

import time
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from facemime.animate.analysis import Analysis, analysed
from facemime.animate.arkit import NAMES as ARKIT
from facemime.animate.arkit import ArkitSolver
from facemime.animate.departure import DEPARTS_AT, departure
from facemime.animate.expressions import NAMES as CONTROLS
from facemime.animate.expressions import named_weights
from facemime.animate.synth import Puppet, UserMotion
from facemime.errors import InputFileError, InvalidInputError
from facemime.io.actor_file import load_actor
from facemime.io.contours_json import TrackWriter
from facemime.io.outputs import Outputs, write_text
from facemime.io.video import CODECS, VideoReader, VideoWriter
from facemime.progress import track as progress
from facemime.render.raster import fill
from facemime.shared_constants import BACKGROUND, NO_FACE_DIM
from facemime.track.overlay import draw_contours
from facemime.track.params import TrackerParams
from facemime.types.actor import Actor
from facemime.types.head import model_iod
from facemime.types.pose import project


@dataclass
class RunResult:
    """What :func:`run_video` did: frames, frames without a face, the files written, warnings,
    the [first, last] ranges of frames that depart from their synthesis, and
    seconds per stage (``decode``, ``track``, ``pose``, ``look``, ``synth``, ``compose``, ``fit``,
    ``encode``: handing frames to the encoder, which encodes them on its own thread)."""

    frames: int
    frames_without_face: int
    files: list[Path]
    warnings: list[str] = field(default_factory=list)
    seconds: dict[str, float] = field(default_factory=dict)
    departs: list[list[int]] = field(default_factory=list)

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
        return {k: self.seconds[k] / self._busy for k in ("decode", "track", "pose", "look", "synth", "compose")}


class SideBySide:
    """The per-frame work of ``run`` without the video encoding: each frame analysed,
    re-synthesised on the driven actor and composed side by side (the original with the tracked
    contours | the synthesised face; a frame without a face shows the synthesis dimmed).
    Iterating yields each frame's (H, 2W, 3) uint8 RGB canvas, one buffer overwritten frame after
    frame.

    While it runs, the track file's per-frame entries are appended to :attr:`records`,
    :attr:`frames` counts them, :attr:`weights` holds each frame's (E,) expression weights,
    :attr:`departs` the [first, last] ranges of frames that depart from their synthesis (only
    measured when the video's own face is synthesised in its own scene), and :attr:`seconds` the
    time per stage (``decode``: waiting for the next frame; ``track``, ``pose``, ``look``,
    ``fit``, filled in at the end; ``synth``, the departure measure included; ``compose``).
    :attr:`analysis` is None until the first frame.

    Parameters
    ----------
    frames
        (H, W, 3) uint8 RGB frames, all of one size.
    name
        Names the video in messages.
    target
        The actor to drive; None: the actor fitted on the first frame.
    user
        Motion added on top of the measured one (extra degrees of yaw, pitch, roll; zoom;
        exaggeration); default none.
    params
        Tracker settings; None: the defaults.
    records
        Where the per-frame entries go: a list, or a :class:`facemime.io.contours_json.TrackWriter`
        that writes them out as they come; None: a new list.
    mask_only
        Show the face alone on a plain backdrop, not in its actor's scene.
    fps
        The video's frame rate, frames/s, for the pose filter.
    """

    def __init__(
        self,
        frames: Iterable[np.ndarray],
        name: str,
        target: Actor | None = None,
        user: UserMotion = UserMotion(),
        params: TrackerParams | None = None,
        records: list[dict] | TrackWriter | None = None,
        mask_only: bool = False,
        fps: float = 25.0,
    ):
        self._frames, self._name, self._target, self._user, self._params = frames, name, target, user, params
        self._fps = fps
        self._mask_only = mask_only
        self.records = [] if records is None else records
        self.departs: list[list[int]] = []
        self.frames = 0
        self.seconds = dict.fromkeys(("decode", "track", "pose", "look", "synth", "compose"), 0.0)
        self.analysis: Analysis | None = None
        #: Per frame, the expression weights (E,) solved from its offsets and look.
        self.weights: list[np.ndarray] = []

    def _timed_frames(self) -> Iterator[np.ndarray]:
        """The source's frames, the time spent waiting for each added to ``seconds["decode"]``."""
        stream = iter(self._frames)
        while True:
            t0 = time.perf_counter()
            frame = next(stream, None)
            self.seconds["decode"] += time.perf_counter() - t0
            if frame is None:
                return
            yield frame

    def __iter__(self) -> Iterator[np.ndarray]:
        seconds, canvas, synth, puppet = self.seconds, None, None, None
        frames = analysed(self._timed_frames(), self._name, params=self._params, fps=self._fps, eye_model=True)
        for frame, analysis, motion in frames:
            h, w = frame.shape[:2]
            if self.analysis is None:
                self.analysis = analysis
                actor = self.analysis.actor
                driven = actor if self._target is None else self._target
                puppet = Puppet(
                    driven, self.analysis.deformer.feature_sizes(), model_iod(actor.model), actor.pose, self._mask_only
                )
                # the surround is compared only where the synthesis is of this very picture
                compare = puppet.scene is not None and self._target is None
                outline = actor.model.groups["face_outline"]
                canvas = np.empty((h, 2 * w, 3), np.uint8)
                synth = np.empty((h, w, 3), np.uint8)
                solver = ArkitSolver(actor.model)
            assert puppet is not None and synth is not None and canvas is not None  # made on the first frame
            t1 = time.perf_counter()
            if puppet.scene is None:
                fill(synth, BACKGROUND)
            puppet.render(motion.pose, motion.offsets, (w, h), self._user, out=synth, look=motion.look)
            record = {
                "index": self.frames,
                "contours": motion.contours,
                "confidence": motion.confidence,
                "lost": motion.lost,
                "redetected": motion.redetected,
                "face": motion.face,
                "pose": motion.pose.as_dict(),
                "offsets": motion.offsets,
                "look": motion.look.as_dict(),
            }
            values = solver.step(
                motion.offsets, motion.look, motion.landmark_closure, motion.landmark_jaw, motion.lid_closure
            )
            self.weights.append(solver.controls)
            record["weights"] = named_weights(CONTROLS, solver.controls)
            record["arkit"] = named_weights(ARKIT, values)
            if compare and motion.face and puppet.shown is not None:  # shown: set by the render above
                vertices, shown = puppet.shown
                share = departure(frame, synth, project(vertices[outline], shown)[0])
                record.update(scene_departure=share, scene_departs=share > DEPARTS_AT)
                if share > DEPARTS_AT:
                    if self.departs and self.departs[-1][1] == self.frames - 1:
                        self.departs[-1][1] = self.frames
                    else:
                        self.departs.append([self.frames, self.frames])
            t2 = time.perf_counter()
            if motion.face:
                draw_contours(frame, motion.contours, motion.lost, out=canvas[:, :w])
            else:
                canvas[:, :w] = frame
            canvas[:, w:] = synth if motion.face else (synth * NO_FACE_DIM).astype(np.uint8)
            self.records.append(record)
            self.frames += 1
            seconds["synth"] += t2 - t1
            seconds["compose"] += time.perf_counter() - t2
            yield canvas
        if self.analysis is not None:
            t = self.analysis.timings
            seconds.update(track=t.track, pose=t.pose, fit=t.fit, look=t.look)

    def result(self, files: list[Path], encode_seconds: float = 0.0) -> RunResult:
        """What the run did, once iterated to the end; raises
        :class:`~facemime.errors.InputFileError` when there were no frames.

        Parameters
        ----------
        files
            The files the run wrote, for the result.
        encode_seconds
            The time the caller spent encoding the canvases, seconds (``seconds["encode"]``).

        Returns
        -------
        RunResult
            Frames, frames without a face, ``files``, the analysis's warnings, seconds per stage
            and the departing ranges.
        """
        if self.analysis is None:
            raise InputFileError(f"video {self._name} has no frames")
        return RunResult(
            self.frames,
            self.analysis.frames_without_face,
            files,
            list(self.analysis.warnings),
            {**self.seconds, "encode": encode_seconds},
            [list(r) for r in self.departs],
        )


def weights_csv(weights: list[np.ndarray], fps: float) -> str:
    """Expression weights as CSV text.

    Parameters
    ----------
    weights
        Per frame, an (E,) float array of the weights (0-1) in the order of
        :data:`facemime.animate.expressions.NAMES`.
    fps
        The video's frame rate, frames/s (0 or less: every time is 0).

    Returns
    -------
    str
        A header ``frame,time_s,<names>``, then a row per frame: its 0-based index, its time in
        seconds (``index / fps``) and the weights, 4 decimals each; newline-terminated lines.
    """
    from facemime.animate.expressions import NAMES

    lines = [",".join(("frame", "time_s") + NAMES)]
    for i, w in enumerate(weights):
        lines.append(f"{i},{i / fps if fps > 0 else 0.0:.4f}," + ",".join(f"{x:.4f}" for x in w))
    return "\n".join(lines) + "\n"


def video_output(out: str | Path) -> Path:
    """Check the name of a video ``run`` writes.

    Parameters
    ----------
    out
        The output video; refused (:class:`~facemime.errors.InvalidInputError`) unless it ends in
        ``.mp4`` or ``.webm`` (any case).

    Returns
    -------
    Path
        ``out`` as a path.
    """
    out = Path(out)
    if out.suffix.lower() not in CODECS:
        raise InvalidInputError(f"the output video must end in .mp4 or .webm, got {out.name!r}")
    return out


def write_frames(writer: VideoWriter, frames: Iterable[np.ndarray]) -> float:
    """Hand each frame to a video writer.

    Parameters
    ----------
    writer
        The open video writer.
    frames
        (H, W, 3) uint8 RGB images of the writer's size; made lazily, their making not timed.

    Returns
    -------
    float
        The seconds spent in ``writer.write`` (the encoding).
    """
    encode = 0.0
    for image in frames:
        t0 = time.perf_counter()
        writer.write(image)
        encode += time.perf_counter() - t0
    return encode


def run_video(
    video: str | Path,
    out: str | Path,
    actor: str | Path | Actor | None = None,
    track: str | Path | None = None,
    user: UserMotion = UserMotion(),
    force: bool = False,
    params: TrackerParams | None = None,
    mask_only: bool = False,
    weights: str | Path | None = None,
) -> RunResult:
    """Analyse a video, re-synthesise it on an actor and write the side-by-side video and the
    track file (see the module docstring). All outputs or none are written; existing ones are
    refused unless ``force``, an input always.

    Parameters
    ----------
    video
        The face video to analyse (any FFmpeg reads).
    out
        The side-by-side video to write, ``.mp4`` (H.264) or ``.webm`` (VP9), at the video's frame
        rate: the original with the tracked contours | the synthesised picture, twice its width.
    actor
        The actor to drive: an ``.actor`` file or an :class:`Actor`; None: the actor fitted on the
        first frame. Shown in its own scene unless ``mask_only`` (or it has none).
    track
        The ``facemime.track/1`` file to write (must end in ``.json``); None: ``out`` with the
        suffix ``.json``.
    user
        Motion added on top of the measured one (extra degrees of yaw, pitch, roll; zoom;
        exaggeration); default none.
    force
        Write over existing outputs.
    params
        Tracker settings; None: the defaults.
    mask_only
        Show the face alone on a plain backdrop, not in its actor's scene.
    weights
        A ``.csv`` file to write the expression weights to as well (:func:`weights_csv`); None:
        none.

    Returns
    -------
    RunResult
        Frames, frames without a face, the files written, warnings, the departing ranges and
        seconds per stage.
    """
    out = video_output(out)
    track = out.with_suffix(".json") if track is None else Path(track)
    if track.suffix.lower() != ".json":
        raise InvalidInputError(f"the track file must end in .json, got {track.name!r}")
    csv = None if weights is None else Path(weights)
    if csv is not None and csv.suffix.lower() != ".csv":
        raise InvalidInputError(f"the weights file must end in .csv, got {csv.name!r}")
    actor_path = actor if isinstance(actor, (str, Path)) else None
    with Outputs([out, track] + ([csv] if csv else []), force, inputs=[video, actor_path]) as outputs:
        target = load_actor(actor) if isinstance(actor, (str, Path)) else actor
        with (
            VideoReader(video) as reader,
            VideoWriter(outputs.stage(out), reader.fps) as writer,
            TrackWriter(outputs.stage(track)) as records,
        ):
            work = SideBySide(
                progress(reader, reader.frames or None, "running"),
                str(video),
                target,
                user,
                params,
                records,
                mask_only,
                reader.fps,
            )
            encode = write_frames(writer, work)
            if work.analysis is None:
                raise InputFileError(f"video {video} has no frames")
            result = work.result([out, track] + ([csv] if csv else []), encode)
            result.warnings.extend(reader.warnings)
            busy = sum(v for k, v in result.seconds.items() if k not in ("encode", "fit", "decode"))
            info = {"width": reader.width, "height": reader.height, "fps": reader.fps, "frames": result.frames}
            records.close(
                info,
                {"processing_seconds": round(busy, 4), "frames_processed": result.frames},
                work.analysis.model_block,
                {"scene_departs": result.departs} if result.departs else None,
            )
            if csv is not None:
                write_text(outputs.stage(csv), weights_csv(work.weights, reader.fps))
    return result


def run_track(
    track: str | Path,
    out: str | Path,
    actor: str | Path | Actor | None = None,
    user: UserMotion = UserMotion(),
    force: bool = False,
    mask_only: bool = False,
) -> RunResult:
    """Play the motion of a track file on an actor and write the synthesised picture alone, at
    the track's size and frame rate, frames without a face dimmed (:mod:`facemime.animate.replay`).
    The output is written complete or not at all.

    Parameters
    ----------
    track
        A ``facemime.track/1`` file (from :func:`run_video`, or expression weights written by
        hand).
    out
        The video to write, ``.mp4`` (H.264) or ``.webm`` (VP9). Refused when it exists (unless
        ``force``) or is one of the inputs.
    actor
        The actor to play it: an ``.actor`` file or an :class:`Actor`; None: the generic painted
        head. Shown in its own scene unless ``mask_only`` (or it has none).
    user
        Motion added on top of the track's (extra degrees of yaw, pitch, roll; zoom;
        exaggeration); default none.
    force
        Write over an existing ``out``.
    mask_only
        Show the face alone on a plain backdrop, not in its actor's scene.

    Returns
    -------
    RunResult
        Frames, frames without a face, ``[out]``, no warnings and seconds per stage: ``decode``
        reading the track, ``synth``, ``encode`` (the others 0).
    """
    from facemime.animate.replay import load_replay

    out = video_output(out)
    actor_path = actor if isinstance(actor, (str, Path)) else None
    with Outputs([out], force, inputs=[track, actor_path]) as outputs:
        seconds = dict.fromkeys(("decode", "track", "pose", "look", "synth", "compose"), 0.0)
        t0 = time.perf_counter()
        replay = load_replay(track, load_actor(actor) if isinstance(actor, (str, Path)) else actor)
        puppet = replay.puppet(mask_only)
        seconds["decode"] = time.perf_counter() - t0

        def frames() -> Iterator[np.ndarray]:
            for m in progress(replay.motion, len(replay.motion), "playing"):
                t = time.perf_counter()
                image = puppet.render(m.pose, m.offsets, replay.size, user, look=m.look)
                seconds["synth"] += time.perf_counter() - t
                yield image if m.face else (image * NO_FACE_DIM).astype(np.uint8)

        with VideoWriter(outputs.stage(out), replay.fps) as writer:
            encode = write_frames(writer, frames())
    return RunResult(
        len(replay.motion), sum(not m.face for m in replay.motion), [out], [], {**seconds, "encode": encode}
    )
