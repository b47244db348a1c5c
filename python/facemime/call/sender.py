"""The sending end of ``facemime call``: frames read at their own pace (a video file at its frame
rate, a camera as frames come), analysed live, and coded into one live stream
(:class:`~facemime.codec.stream.MotionEncoder`) whose chunks go to a :class:`Sink` (the server's
clients, and the recording).

The basis of the knot offsets cannot be learned from the whole clip live: it is learned from the
first :data:`WARMUP` seconds of analysed frames, which are analysed but not streamed; the stream
(header, actor, packets) starts after them. Frame indices in the messages count the streamed
frames from the stream's start (packet s holds frames s × P ...), as ``docs/bitstream.md`` does.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass, field, replace
from typing import Protocol

import numpy as np

from facemime import _core
from facemime.animate.analysis import FrameMotion, analysed
from facemime.codec.clip import Clip, encode_clip
from facemime.codec.params import Basis, pose_vector
from facemime.codec.stream import DEFAULT_QUALITY, LADDER, MotionEncoder, Settings
from facemime.errors import InputFileError, InvalidInputError
from facemime.io.actor_file import actor_bytes
from facemime.io.live_source import CameraSource, FileSource
from facemime.types.actor import Actor

#: Seconds of analysed frames the basis is learned from before the stream starts (not streamed).
WARMUP = 2.0
# Measured on the ten shared videos with the basis from the first 2 s, at 2 frames a packet: the
# motion's rate at quality 3 was 1.80 kbit/s on average (2.49 at most), at 4 1.95 (2.76), at 5 2.19
# (3.15); a keyframe of 2 s instead of 5 s changes them by ~0.03. No one quality keeps every face
# under 2 kbit/s, hence the choice from the warm-up (RATE). A packet of 2 frames waits one frame for
# its second: more frames a packet cost latency, fewer cost framing (8 bytes a packet).
#: The motion's rate a call aims at, kbit/s: the stream takes the finest quality whose warm-up
#: frames code within it (``--quality`` sets one instead).
RATE = 2.0
#: Frames per packet.
PACKET_FRAMES = 2
#: Seconds between scheduled intra packets (a receiver can also ask for one).
KEYFRAME = 5.0


class Sink(Protocol):
    """Where the sender's stream goes (:class:`~facemime.app.call.Call`: the recording, and the
    server's :class:`~facemime.call.server.Hub`)."""

    def start_stream(self, header: bytes, actor: bytes) -> None:
        """A stream starts.

        Parameters
        ----------
        header
            The header chunk.
        actor
            The actor chunk.
        """

    def packet(self, first: int, arrived: list[float], data: bytes) -> None:
        """A packet is made.

        Parameters
        ----------
        first
            The index of the packet's first frame from the stream's start.
        arrived
            Each of its frames' arrival at the sender, ms since the epoch.
        data
            The packet chunk.
        """

    def end(self, error: str | None) -> None:
        """The source has ended.

        Parameters
        ----------
        error
            Why, when it failed; None when it ended normally.
        """


@dataclass
class SenderStats:
    """What the sender did: frames analysed in the warm-up and streamed, bytes of the header,
    actor and packets, intra requests (asked, honoured), and per packet the seconds from its
    first and last frame's arrival to its hand-over to the clients."""

    warmup_frames: int = 0
    frames: int = 0
    header_bytes: int = 0
    actor_bytes: int = 0
    packet_bytes: int = 0
    packets: int = 0
    intra_asked: int = 0
    intra_honoured: int = 0
    delays: list[tuple[float, float]] = field(default_factory=list)

    def motion_kbit_s(self, fps: float) -> float:
        """The packets' rate over the streamed frames.

        Parameters
        ----------
        fps
            The source's frame rate, frames/s.

        Returns
        -------
        float
            kbit/s; 0 before any frame was streamed.
        """
        return self.packet_bytes * 8 / 1000 / (self.frames / fps) if self.frames else 0.0


class Sender(threading.Thread):
    """Reads, analyses and codes a source's frames into a sink until the source ends or
    :meth:`stop` is called.

    The first frame is read and the actor fitted (or the given one placed) in the constructor, so
    that a source without a face fails there, in one line; :attr:`error` is what stopped the
    thread otherwise (None: the source ended, or it was stopped).

    Parameters
    ----------
    source
        Where the frames come from.
    sink
        Where the stream goes.
    actor
        The actor to place on the face; None: one is fitted on the first frame.
    quality
        The stream's quality, 0-10 (:data:`~facemime.codec.stream.LADDER`); None: the finest
        whose warm-up frames fit ``rate``.
    packet_frames
        Frames per packet, 1-32.
    keyframe
        Seconds between scheduled intra packets (less than a packet's is taken as a packet's).
    warmup
        Seconds of analysed frames (one at least) the basis is learned from before the stream
        starts; they are not streamed.
    rate
        The motion's rate aimed at without a ``quality``, kbit/s (> 0).
    """

    def __init__(
        self,
        source: FileSource | CameraSource,
        sink: Sink,
        actor: Actor | None = None,
        quality: int | None = None,
        packet_frames: int = PACKET_FRAMES,
        keyframe: float = KEYFRAME,
        warmup: float = WARMUP,
        rate: float = RATE,
    ):
        super().__init__(name="call sender", daemon=True)
        if not 1 <= packet_frames <= 32:
            raise InvalidInputError(f"frames per packet must be 1-32, got {packet_frames}")
        self.source, self.sink, self.fps = source, sink, source.fps
        packet = packet_frames / self.fps
        if not (np.isfinite(rate) and rate > 0):
            raise InvalidInputError(f"the target rate must be a positive number of kbit/s, got {rate}")
        self.quality, self.rate = quality, float(rate)
        self.settings = Settings(
            quality=DEFAULT_QUALITY if quality is None else quality, packet=packet, keyframe=max(keyframe, packet)
        )
        self.packet_frames, self.keyframe_packets = self.settings.framing(self.fps)
        self.warmup_frames = max(1, round(warmup * self.fps))
        self.stats = SenderStats()
        self.error: BaseException | None = None
        self._stopping = threading.Event()
        self.finished = threading.Event()  # set when the thread has ended
        self._lock = threading.Lock()  # the intra requests' state, shared with the clients' threads
        self._forced = False  # an intra packet was asked for and is not made yet
        self._packets_made = 0
        self._last_intra = False  # the last packet made was an intra packet
        self._frames = source.frames(self._stopping)
        self._arrived = 0.0  # when the frame being analysed arrived (wall clock, ms)
        self._analysed = analysed(self._pictures(), source.name, actor=actor, fps=source.fps)
        started = next(self._analysed, None)
        if started is None:
            raise InputFileError(f"{source.name} has no frames")
        _, self.analysis, motion = started
        self.actor = actor or self.analysis.actor
        # made now, not when the stream starts: encoding the texture and scene takes ~0.3 s, which
        # delayed the first packets that much
        self._actor_data = actor_bytes(self.actor, "webp", self.settings.texture)
        self._warm: list[tuple[FrameMotion, float]] = [(motion, self._arrived)]
        self.encoder: MotionEncoder | None = None

    def stop(self) -> None:
        """Ask the thread to end (it does within a frame)."""
        self._stopping.set()

    def request_intra(self) -> bool:
        """A receiver asks for an intra packet: the next packet is made one, unless it is one
        already, or the last packet made was one (on its way: a receiver that asks again every
        250 ms while out of sync asked before it came; if it was lost, the next request, after
        one more packet, is honoured).

        Returns
        -------
        bool
            Whether the request changed anything (it is honoured): False also before the stream
            starts.
        """
        with self._lock:
            self.stats.intra_asked += 1
            next_is_intra = self._forced or self._packets_made % self.keyframe_packets == 0
            if self.encoder is None or next_is_intra or self._last_intra:
                return False
            self._forced = True
            self.stats.intra_honoured += 1
            return True

    def run(self) -> None:
        error = None
        try:
            self._run()
        except Exception as e:  # noqa: BLE001 (told by the caller, in one line)
            self.error, error = e, e
        finally:
            self._analysed.close()
            self._frames.close()
            self.source.close()
            try:
                if error is not None or not self._stopping.is_set():  # the source has ended, or failed
                    self.sink.end(None if error is None else str(error))
            finally:
                self.finished.set()

    def _pictures(self) -> Iterator[np.ndarray]:
        """The source's frames, noting each one's arrival for the latency figures."""
        for frame, arrived in self._frames:
            self._arrived = arrived
            yield frame

    def _run(self) -> None:
        for _, _, motion in self._analysed:
            if self.encoder is None:
                self._warm.append((motion, self._arrived))
                if len(self._warm) >= self.warmup_frames:
                    self._start()
            else:
                self._push(motion, self._arrived)
        if self._stopping.is_set():
            return
        if self.encoder is None:  # the source ended within the warm-up: nothing to stream
            raise InputFileError(
                f"{self.source.name} has {len(self._warm)} frames, fewer than the {self.warmup_frames} of warm-up "
                "the call analyses before it streams"
            )
        self._send(self.encoder.finish())

    def _choose_quality(self) -> None:
        """Without a quality given: the finest whose warm-up frames, coded as the stream will be
        (their own basis and tables), fit :attr:`rate` (the coarsest when none does)."""
        clip = Clip(self.actor, self.fps, self.source.size, [m for m, _ in self._warm], [], 0.0)
        for quality in reversed(range(len(LADDER))):
            self.settings = replace(self.settings, quality=quality)
            packets = encode_clip(clip, self.settings, carry_actor=False)[2]
            if sum(map(len, packets)) * 8 / 1000 / (len(clip.motion) / self.fps) <= self.rate:
                return

    def _start(self) -> None:
        """The warm-up is over: choose the quality, learn the basis and the tables' classes, start
        the stream."""
        if self.quality is None:
            self._choose_quality()
        faces = [m for m, _ in self._warm if m.face]
        m = self.settings.basis_size
        basis = Basis.learn(np.array([f.offsets for f in faces]).reshape(len(faces), -1, 2), m)
        steps = self.settings.steps(len(basis.raw), True)
        values = np.array(
            [np.concatenate([pose_vector(f.pose), basis.coefficients(f.offsets), f.look.vector()]) for f in faces]
        )
        classes = _core.choose_classes(steps, self.settings.hysteresis, values.reshape(len(faces), len(steps)))
        encoder = MotionEncoder(
            self.actor,
            self.fps,
            self.source.size,
            basis,
            self.settings,
            True,
            classes,
            reference=self._warm[0][0].pose,
            look=True,
            actor_data=self._actor_data,
        )
        start = encoder.start()
        header = encoder.header
        self.stats.warmup_frames, self.stats.header_bytes = len(self._warm), len(header)
        self.stats.actor_bytes = len(start) - len(header)
        self._pending: list[float] = []  # arrival times of the frames of the packet being filled
        with self._lock:
            self.encoder = encoder
        self.sink.start_stream(header, start[len(header) :])

    def _push(self, motion: FrameMotion, arrived: float) -> None:
        with self._lock:
            if self._forced:
                self.encoder.request_intra()
        self._pending.append(arrived)
        self._send(self.encoder.push(motion.face, motion.lost, motion.pose, motion.offsets, motion.look).data)

    def _send(self, data: bytes) -> None:
        if not data:
            return
        frames = (data[0] & 31) + 1
        arrived, self._pending = self._pending[:frames], self._pending[frames:]
        first = self.stats.frames
        self.stats.frames += frames
        self.stats.packets += 1
        self.stats.packet_bytes += len(data)
        with self._lock:
            self._packets_made += 1
            self._last_intra = data[0] >> 5 == 3
            if self._last_intra:
                self._forced = False
        now = time.time() * 1000
        self.stats.delays.append(((now - arrived[0]) / 1000, (now - arrived[-1]) / 1000))
        self.sink.packet(first, arrived, data)
