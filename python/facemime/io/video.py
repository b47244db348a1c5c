"""Video input (any FFmpeg-readable file, decoded to RGB, turned upright as its container says) and video output that
browsers play: H.264 in MP4 (``.mp4``) or VP9 in WebM (``.webm``), 4:2:0 chroma, encoded by FFmpeg through PyAV.
Frames are RGB uint8 (H, W, 3)."""

from __future__ import annotations

import contextlib
import itertools
import math
import os
import queue
import threading
from collections.abc import Callable, Iterator
from fractions import Fraction
from pathlib import Path
from types import TracebackType

import av
import cv2
import numpy as np
from av.video.reformatter import VideoReformatter

from facemime.errors import InputFileError, InvalidInputError, OutputFileError
from facemime.io.outputs import temporary_sibling

# VP9 in real time makes no use of frames held back ("lag"): a video of the same size (0.1 % apart), without 25 raw
# frames held (0.7 GB at 7680x2160).
CODECS = {
    ".mp4": ("libx264", {"crf": "20", "preset": "veryfast", "movflags": "+faststart"}),
    ".webm": ("libvpx-vp9", {"crf": "32", "b": "0", "deadline": "realtime", "cpu-used": "8", "lag-in-frames": "0"}),
}
#: Frames of more pixels than 4K UHD's are encoded by x264 without B-frames and look-ahead
#: ("zerolatency"): 0.9 GB less memory at 7680x2160 (a 4K video beside its synthesis), files
#: somewhat larger.
LARGE_FRAME = 3840 * 2160
#: Frames of more pixels than 1920x1080 are decoded by 2 threads (each holds a frame: 25 MB at 3840x2160), not
#: FFmpeg's one more than the cores: 2 decode 3840x2160 H.264 at 60 frames/s, the tracker takes 12.
LARGE_DECODE = 1920 * 1080


class VideoWriter:
    """Write frames to a browser-playable video; the file appears under its name only when the
    writer closes without an error (a failed run leaves nothing behind).

    Frame sizes must be even (4:2:0); odd sizes are padded by one pixel of the edge colour.
    Frames are encoded on a thread of the writer's own, beside the caller's work: :meth:`write`
    converts a frame to the encoder's 4:2:0 layout (so the caller may reuse its buffer at once)
    and waits only while :data:`QUEUED` frames, or as many as fit in :data:`QUEUED_BYTES`, are
    still to be encoded. An encoding error is raised by the next :meth:`write` or on closing.

    Parameters
    ----------
    path
        The video file to write: ``.mp4`` (H.264) or ``.webm`` (VP9).
    fps
        Frame rate, frames/s: any positive, finite number (kept as a fraction of denominator at
        most 1001).

    Examples
    --------
    >>> import tempfile, pathlib
    >>> out = pathlib.Path(tempfile.mkdtemp()) / "clip.mp4"
    >>> with VideoWriter(out, fps=25) as w:
    ...     for i in range(5):
    ...         w.write(np.full((32, 48, 3), 40 * i, np.uint8))
    >>> out.stat().st_size > 0
    True
    """

    #: Frames converted and waiting for the encoder at most.
    QUEUED = 4
    #: Bytes of converted frames waiting for the encoder at most (but one frame at least).
    QUEUED_BYTES = 32 * 2**20

    def __init__(self, path: str | Path, fps: float):
        self.path = Path(path)
        if self.path.suffix.lower() not in CODECS:
            raise InvalidInputError(f"video output must end in .mp4 or .webm, got {self.path.name!r}")
        if not (0 < fps < math.inf):
            raise InvalidInputError(f"fps must be positive and finite, got {fps}")
        self.fps = Fraction(fps).limit_denominator(1001)
        self._tmp: Path | None = None
        self._container: av.container.OutputContainer | None = None
        self._stream: av.video.stream.VideoStream | None = None
        self._queue: queue.Queue[np.ndarray | None] | None = None
        self._encoder: threading.Thread | None = None
        self._error: BaseException | None = None
        self._cancelled = False
        self.frames = 0

    def __enter__(self) -> VideoWriter:
        self._tmp = temporary_sibling(self.path)
        return self

    def write(self, frame: np.ndarray) -> None:
        """Append one frame.

        Parameters
        ----------
        frame
            (H, W, 3) uint8 RGB image; every frame must have the first one's size.
        """
        if not (isinstance(frame, np.ndarray) and frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3):
            raise InvalidInputError(f"video frames must be (H, W, 3) uint8 RGB, got {getattr(frame, 'shape', frame)}")
        self._raise_error()
        h, w = frame.shape[:2]
        if h % 2 or w % 2:
            frame = np.pad(frame, ((0, h % 2), (0, w % 2), (0, 0)), mode="edge")
        if self._stream is None:
            codec, options = CODECS[self.path.suffix.lower()]
            fmt = "mp4" if self.path.suffix.lower() == ".mp4" else "webm"
            self._container = container = av.open(
                str(self._tmp),
                "w",
                format=fmt,
                options={"movflags": options["movflags"]} if "movflags" in options else {},
            )
            stream = container.add_stream(codec, rate=self.fps)
            assert isinstance(stream, av.VideoStream)  # a video codec's
            self._stream = stream
            stream.width, stream.height = frame.shape[1], frame.shape[0]
            stream.pix_fmt = "yuv420p"
            pixels = frame.shape[0] * frame.shape[1]
            large: dict[str, object] = {"tune": "zerolatency"} if codec == "libx264" and pixels > LARGE_FRAME else {}
            stream.options = {k: v for k, v in options.items() if k != "movflags"} | large
            i420_bytes = pixels * 3 // 2
            self._queue = frames = queue.Queue[np.ndarray | None](
                max(1, min(self.QUEUED, self.QUEUED_BYTES // i420_bytes))
            )
            self._encoder = threading.Thread(target=self._encode, name=f"encoder {self.path.name}", daemon=True)
            self._encoder.start()
        elif (frame.shape[1], frame.shape[0]) != (self._stream.width, self._stream.height):
            raise InvalidInputError(
                f"video frame size changed from {self._stream.width}x{self._stream.height} to {w}x{h}"
            )
        else:
            assert self._queue is not None  # made with the stream
            frames = self._queue
        # OpenCV's RGB -> I420 (BT.601, limited range, as FFmpeg's default) takes a tenth of
        # the time of the encoder's own conversion.
        frames.put(cv2.cvtColor(np.ascontiguousarray(frame), cv2.COLOR_RGB2YUV_I420))
        self.frames += 1

    def _encode(self) -> None:
        """The encoder thread: encodes queued frames until None, then flushes the encoder. After
        an error, or once cancelled, it keeps taking frames (so that no writer waits forever)
        and encodes none."""
        frames, stream, container = self._queue, self._stream, self._container
        assert frames is not None and stream is not None and container is not None  # started by write()
        while (i420 := frames.get()) is not None:
            if self._error is None and not self._cancelled:
                self._guarded(container, lambda: stream.encode(av.VideoFrame.from_ndarray(i420, format="yuv420p")))
        if self._error is None and not self._cancelled:
            self._guarded(container, lambda: stream.encode())

    def _guarded(
        self, container: av.container.OutputContainer, encode: Callable[[], list[av.Packet[av.VideoStream]]]
    ) -> None:
        """Mux the packets ``encode`` gives; keep an error for the writer's thread to raise."""
        try:
            for packet in encode():
                container.mux(packet)
        except (av.FFmpegError, OSError) as e:
            self._error = OutputFileError(f"cannot write video {self.path}: {_reason(e)}")
        except BaseException as e:  # noqa: BLE001 (an unexpected error, raised as it is)
            self._error = e

    def _raise_error(self) -> None:
        if self._error is not None:
            raise self._error

    def __exit__(self, exc_type: type | None, exc: BaseException | None, tb: TracebackType | None) -> None:
        try:
            if self._encoder is not None and self._queue is not None:
                self._cancelled = exc_type is not None
                self._queue.put(None)
                self._encoder.join()
            if self._container is not None:
                try:
                    self._container.close()
                except (av.FFmpegError, OSError) as e:  # the file's end cannot be written (a full disk)
                    self._error = self._error or OutputFileError(f"cannot write video {self.path}: {_reason(e)}")
            if exc_type is None:
                self._raise_error()
                if self.frames == 0:
                    raise InvalidInputError(f"no frames were written to {self.path}")
                if self._tmp is not None:
                    os.replace(self._tmp, self.path)
        finally:
            if self._tmp is not None:
                self._tmp.unlink(missing_ok=True)


class VideoReader:
    """Decode a video file into RGB uint8 (H, W, 3) frames, in order, the right way up.

    ``width``, ``height`` (pixels, as displayed), ``fps`` (frames per second), ``frames`` (the
    container's frame count, 0 when unknown) and ``rotation`` (degrees counter-clockwise that
    every frame is turned by: the container's display rotation, as phones write it, or its
    ``rotate`` tag, in quarter turns) are known after opening, which decodes the first frame.
    A missing or unreadable file, a file with no video stream or none of whose frames decodes,
    raises :class:`InputFileError` with one line naming it.

    Frames are decoded on a thread of the reader's own, at most :data:`AHEAD` (and no more than
    :data:`AHEAD_BYTES`) ahead of the caller, so that decoding runs beside the caller's work on
    the frames already given; an error of the file or of the conversion to RGB is raised, as
    :class:`InputFileError`, where the caller's iteration reaches it. A damaged packet that does
    not decode is skipped, as players do. Stopping early (``break``, or :meth:`close`) stops the
    decoding. ``decoded`` counts the frames given; ``warnings`` lists, one line each, what was
    wrong with the file once an iteration has reached its end: fewer frames than the container
    declares (a truncated file), damaged packets skipped.

    Parameters
    ----------
    path
        The video file: any FFmpeg-readable one.
    """

    #: Frames decoded and waiting for the caller at most (2, 4 and 8 gave the same speed to
    #: ``facemime track``; fewer frames hold less memory on large videos).
    AHEAD = 4
    #: Bytes of frames decoded and waiting for the caller at most (but one frame at least):
    #: 4 frames to 1920x1080, 1 of 3840x2160.
    AHEAD_BYTES = 32 * 2**20
    #: Frames fewer than the container declares that pass without a warning (counts that
    #: containers round).
    SHORT_OK = 2
    #: Threads FFmpeg decodes with: 0 lets it choose (one a core, or 2 for large frames); a
    #: process that should keep to one core (a batch worker, ``facemime.batch.worker``) sets 1.
    DECODE_THREADS = 0

    def __init__(self, path: str | Path):
        self.path = Path(path)
        if not self.path.exists():
            raise InputFileError(f"video {self.path} does not exist")
        if not self.path.is_file():
            raise InputFileError(f"video {self.path} is not a file")
        try:
            self._container = av.open(str(self.path), "r")
        except (av.FFmpegError, OSError, UnicodeDecodeError) as e:
            raise InputFileError(f"cannot read video {self.path}: {_reason(e)}") from None
        if not self._container.streams.video:
            self._container.close()
            raise InputFileError(f"cannot read video {self.path}: it has no video stream")
        self._stream = self._container.streams.video[0]
        self._stream.thread_type = "AUTO"
        codec = self._stream.codec_context
        if codec is None:  # a damaged header: the stream's codec is not known
            self._container.close()
            raise InputFileError(
                f"cannot read video {self.path}: its video stream's codec is unknown (a damaged file?)"
            )
        if self.DECODE_THREADS:
            codec.thread_count = self.DECODE_THREADS
        elif codec.width * codec.height > LARGE_DECODE:
            codec.thread_count = 2
        self.damaged = 0
        self._source = self._packets_decoded()
        try:
            self._first: av.VideoFrame | None = next(self._source, None)
        except (av.FFmpegError, OSError) as e:
            self._container.close()
            raise InputFileError(f"cannot read video {self.path}: {_reason(e)}") from None
        if self._first is None:
            self._container.close()
            raise InputFileError(f"video {self.path} has no decodable frames")
        quarters = round(self._first.rotation / 90) or round(-_rotate_tag(self._stream.metadata) / 90)
        self.rotation = 90 * (quarters % 4)
        self._turn = {90: cv2.ROTATE_90_COUNTERCLOCKWISE, 180: cv2.ROTATE_180, 270: cv2.ROTATE_90_CLOCKWISE}.get(
            self.rotation
        )
        self.width, self.height = self._first.width, self._first.height
        if self.rotation in (90, 270):
            self.width, self.height = self.height, self.width
        rate = self._stream.average_rate or self._stream.guessed_rate
        self.fps = float(rate) if rate and 0 < float(rate) < math.inf else 25.0
        self.frames = int(self._stream.frames or 0)
        self.decoded = 0
        self.warnings: list[str] = []
        self._ahead = max(1, min(self.AHEAD, self.AHEAD_BYTES // (self.width * self.height * 3)))
        # One converter for all frames: ``VideoFrame.to_ndarray`` sets up a new one per frame.
        self._to_rgb = VideoReformatter()
        self._decoding: tuple[threading.Thread, threading.Event, queue.Queue[object]] | None = None

    def _packets_decoded(self) -> Iterator[av.VideoFrame]:
        """The stream's frames. A packet the demuxer marks corrupt (as the last one of a truncated
        file: decoded, it costs the frames being decoded beside it) or the decoder refuses is
        counted in ``damaged`` and skipped."""
        for packet in self._container.demux(self._stream):
            if packet.is_corrupt:
                self.damaged += 1
                continue
            try:
                frames = self._stream.decode(packet)
            except av.FFmpegError:
                self.damaged += 1
                continue
            yield from frames

    def __iter__(self) -> Iterator[np.ndarray]:
        self._stop_decoding()
        frames: queue.Queue[object] = queue.Queue(self._ahead)
        stop = threading.Event()
        decoder = threading.Thread(
            target=self._decode, args=(frames, stop), name=f"decoder {self.path.name}", daemon=True
        )
        self._decoding = (decoder, stop, frames)
        decoder.start()
        try:
            while (item := frames.get()) is not None:
                if item is _END:
                    self._check_end()
                    break
                if isinstance(item, BaseException):
                    raise item
                assert isinstance(item, np.ndarray)
                self.decoded += 1
                yield item
        finally:
            self._stop_decoding()

    def _decode(self, frames: queue.Queue[object], stop: threading.Event) -> None:
        """The decoder thread: queues each frame, then :data:`_END` at the end of the file or
        the error that ended it; returns once ``stop`` is set."""
        try:
            source = self._source if self._first is None else itertools.chain([self._first], self._source)
            self._first = None
            for frame in source:
                # One thread: FFmpeg's threaded conversion costs twice the time on a small frame.
                rgb = self._to_rgb.reformat(frame, format="rgb24", threads=1).to_ndarray()
                frames.put(rgb if self._turn is None else cv2.rotate(rgb, self._turn))
                if stop.is_set():
                    return
            end: BaseException | object = _END
        except (av.FFmpegError, OSError) as e:
            end = InputFileError(f"cannot decode video {self.path}: {_reason(e)}")
        except BaseException as e:  # noqa: BLE001 (an unexpected error, raised as it is in the caller's thread)
            end = e
        frames.put(end)

    def _check_end(self) -> None:
        """Set ``warnings`` once the file's end is reached."""
        self.warnings = []
        if self.frames - self.decoded > self.SHORT_OK:
            self.warnings.append(
                f"video {self.path} ended after {self.decoded} of the {self.frames} frames its "
                "container declares (a truncated file?)"
            )
        if self.damaged:
            self.warnings.append(
                f"{self.damaged} damaged packet(s) of video {self.path} did not decode and were skipped"
            )

    def _stop_decoding(self) -> None:
        """Stops the decoder thread, if any, taking the frames it still queues."""
        if self._decoding is None:
            return
        decoder, stop, frames = self._decoding
        stop.set()
        while decoder.is_alive():
            with contextlib.suppress(queue.Empty):
                frames.get(timeout=0.01)
        decoder.join()
        while not frames.empty():  # what it queued last
            frames.get_nowait()
        frames.put_nowait(None)  # an iteration resumed after this ends
        self._decoding = None

    def close(self) -> None:
        """Stop the decoding and close the file."""
        self._stop_decoding()
        self._container.close()

    def __enter__(self) -> VideoReader:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


#: What the decoder thread queues at the end of the file.
_END = object()


def _rotate_tag(metadata: dict[str, str]) -> float:
    """A stream's ``rotate`` tag (any case): degrees clockwise, 0 when absent or not a number."""
    tag = next((v for k, v in metadata.items() if k.lower() == "rotate"), "0")
    try:
        return float(tag)
    except ValueError:
        return 0.0


def _reason(e: BaseException) -> str:
    text = getattr(e, "strerror", None) or str(e)
    return text.split(":")[-1].strip() if "Errno" in text else text.strip() or type(e).__name__
