"""``facemime live``: a face's motion, live, to avatar software over the VMC protocol.

A video file (played at its own pace) or a camera is analysed frame by frame as ``run`` analyses
it (:func:`facemime.animate.analysis.analysed`: the contours, the head pose from the landmarks,
smoothed against jitter, the eyes); each frame's ARKit values
(:class:`facemime.animate.arkit.ArkitSolver`) and head pose go out at once as one OSC bundle
(:mod:`facemime.live.vmc`). A frame whose face is not found repeats the last values. The
latency of a frame is from its arrival (a camera's frame read, a file's frame due) to its
datagram sent.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

import numpy as np

from facemime.animate.analysis import FrameMotion, analysed
from facemime.animate.arkit import ArkitSolver
from facemime.errors import InputFileError
from facemime.export.performance import METRES
from facemime.io.live_source import FileSource, open_source
from facemime.live.vmc import DEFAULT_ADDRESS, VmcSender, frame_bundle, unity_quaternion, unity_translation

__all__ = ["DEFAULT_ADDRESS", "Live", "LiveStats"]


@dataclass
class LiveStats:
    """What a live run sent: frames, those with the face found, seconds from the first frame's
    arrival to the last datagram, and each frame's latency (ms)."""

    frames: int = 0
    face_frames: int = 0
    seconds: float = 0.0
    latencies: list[float] = field(default_factory=list)

    @property
    def fps(self) -> float:
        """Frames sent per second (0 before two frames)."""
        return (self.frames - 1) / self.seconds if self.frames > 1 and self.seconds > 0 else 0.0

    def latency(self, percentile: float = 50.0, last: int | None = None) -> float:
        """A percentile of the frames' latencies.

        Parameters
        ----------
        percentile
            0-100.
        last
            Only the last this many frames; None: all.

        Returns
        -------
        float
            Milliseconds; NaN before any frame.
        """
        values = self.latencies[-last:] if last else self.latencies
        return float(np.percentile(values, percentile)) if values else float("nan")


class Live:
    """A live run: the VMC address checked and the source opened, and the first frame analysed
    (the actor fitted on it: a source without a face fails here, in one line); :meth:`run` sends
    until the source ends or :meth:`stop` is called.

    Parameters
    ----------
    source
        A video file (played at its own frame rate), or a camera's index (a whole number, such as
        ``0``, that names no file).
    vmc
        The VMC receiver, ``HOST:PORT``.
    loop
        Play a video file again and again.
    paced
        False: a video file's frames as fast as they are analysed (a benchmark's sustained rate).
    """

    def __init__(self, source: str, vmc: str = DEFAULT_ADDRESS, loop: bool = False, paced: bool = True):
        self.sender = VmcSender(vmc)
        try:
            self.source = open_source(source, loop) if paced else FileSource(source, loop, paced=False)
        except BaseException:
            self.sender.close()
            raise
        self.stats = LiveStats()
        self._stop = threading.Event()
        self._arrived = 0.0
        self._frames = self.source.frames(self._stop)
        self._analysed = analysed(self._pictures(), self.source.name, fps=self.source.fps, eye_model=True)
        try:
            started = next(self._analysed, None)
            if started is None:
                raise InputFileError(f"{self.source.name} has no frames")
        except BaseException:
            self.close()
            raise
        _, analysis, self._first = started
        model = analysis.actor.model
        self._solver = ArkitSolver(model)
        self._metres = METRES.get(model.unit, 0.001)
        self._start = time.perf_counter()

    def _pictures(self) -> Iterator[np.ndarray]:
        """The source's frames, noting each one's arrival for the latency."""
        for frame, arrived in self._frames:
            self._arrived = arrived
            yield frame

    def stop(self) -> None:
        """Ask :meth:`run` (in another thread) to end: it does within a frame."""
        self._stop.set()

    def run(self, report: Callable[[LiveStats], None] | None = None) -> LiveStats:
        """Send every frame until the source ends or :meth:`stop` is called.

        Parameters
        ----------
        report
            Called with the stats after every frame sent.

        Returns
        -------
        LiveStats
            What was sent.
        """
        first_arrival = self._arrived
        self._send(self._first)
        if report is not None:
            report(self.stats)
        for _, _, motion in self._analysed:
            self._send(motion)
            self.stats.seconds = (time.time() * 1000 - first_arrival) / 1000
            if report is not None:
                report(self.stats)
        return self.stats

    def _send(self, motion: FrameMotion) -> None:
        values = self._solver.step(
            motion.offsets, motion.look, motion.landmark_closure, motion.landmark_jaw, motion.lid_closure
        )
        datagram = frame_bundle(
            values,
            unity_quaternion(motion.pose),
            unity_translation(motion.pose, self._first.pose, self._metres),
            time.perf_counter() - self._start,
        )
        self.sender.send(datagram)
        self.stats.latencies.append(time.time() * 1000 - self._arrived)
        self.stats.frames += 1
        self.stats.face_frames += int(motion.face)

    def close(self) -> None:
        """Stop reading and close the source and the socket."""
        self._stop.set()
        self._analysed.close()
        self._frames.close()
        self.source.close()
        self.sender.close()

    def __enter__(self) -> Live:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
