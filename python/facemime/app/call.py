"""``facemime call``: a live videophone sender. A video file (played at its own pace) or a camera
is analysed frame by frame and coded into a facemime stream (``docs/bitstream.md``), served to
receivers in web browsers on this machine over a WebSocket (:mod:`facemime.call.server`, where
the protocol is described); :mod:`facemime.call.sender` reads, analyses and codes the frames.
"""

from __future__ import annotations

import os
import threading
from pathlib import Path
from typing import BinaryIO

from facemime.call.sender import KEYFRAME, PACKET_FRAMES, RATE, WARMUP, Sender, open_source
from facemime.call.server import GOING_AWAY, PORT, Hub, make_server
from facemime.errors import InvalidInputError
from facemime.io.outputs import OutputFileError, check_outputs, temporary_sibling
from facemime.types.actor import Actor

__all__ = ["KEYFRAME", "PACKET_FRAMES", "PORT", "RATE", "WARMUP", "Call"]

#: The suffix of a recording (``--record``).
SUFFIX = ".fmstream"


class _Recording:
    """The stream's bytes as sent, written to a temporary file beside ``path`` and put in place
    by :meth:`close` (kept when the call is stopped: every chunk in it is whole)."""

    def __init__(self, path: Path):
        self.path, self._tmp = path, temporary_sibling(path)
        self._file: BinaryIO | None = self._tmp.open("wb")
        self.started = False

    def write(self, data: bytes) -> None:
        assert self._file is not None, "written after close"
        try:
            self._file.write(data)
            self._file.flush()
        except OSError as e:
            raise OutputFileError(f"cannot write {self.path}: {e.strerror or e}") from None

    def close(self, keep: bool) -> None:
        if self._file is None:
            return
        self._file.close()
        self._file = None
        try:
            if keep:
                os.replace(self._tmp, self.path)
        finally:
            self._tmp.unlink(missing_ok=True)


class Call:
    """A live call: ``source`` (a video file, or a camera's index), analysed and streamed by a
    :class:`~facemime.call.sender.Sender` to the clients of a server on 127.0.0.1:``port``.
    ``record``: an ``.fmstream`` file that gets the stream's bytes as sent (refused when it exists,
    unless ``force``); ``loop``: play a file again and again; ``web``: the folder of the page
    (default: the package's). Opening checks the inputs and fits the actor on the first frame;
    :meth:`start` serves and streams, :meth:`wait` returns when the source has ended, :meth:`close`
    (or leaving a ``with`` block) stops everything within a second or two."""

    def __init__(
        self,
        source: str | Path,
        actor: Actor | None = None,
        port: int = PORT,
        quality: int | None = None,
        packet_frames: int = PACKET_FRAMES,
        record: str | Path | None = None,
        force: bool = False,
        loop: bool = False,
        web: Path | None = None,
        keyframe: float = KEYFRAME,
        warmup: float = WARMUP,
        actor_path: str | Path | None = None,
        rate: float = RATE,
    ):
        self.record_path = None if record is None else Path(record)
        if self.record_path is not None:
            if self.record_path.suffix.lower() != SUFFIX:
                raise InvalidInputError(f"the recording must end in {SUFFIX}, got {self.record_path.name!r}")
            check_outputs([self.record_path], force, inputs=[source, actor_path])
        self._recording: _Recording | None = None
        self.source = open_source(str(source), loop)
        self._serving: threading.Thread | None = None
        self.server = None
        try:
            if self.record_path is not None:
                self._recording = _Recording(self.record_path)
            self.sender = Sender(self.source, self, actor, quality, packet_frames, keyframe, warmup, rate)
            self.hub = Hub(
                {
                    "source": self.source.name,
                    "fps": self.source.fps,
                    "width": self.source.size[0],
                    "height": self.source.size[1],
                },
                self.sender.request_intra,
            )
            self.server = make_server(self.hub, port, web)
        except BaseException:
            self.source.close()
            if self._recording is not None:
                self._recording.close(keep=False)
            if self.server is not None:
                self.server.socket.close()  # it never served: shutdown() would wait for serve_forever
            raise

    @property
    def port(self) -> int:
        assert self.server is not None  # made when the call opens
        return self.server.socket.getsockname()[1]

    @property
    def url(self) -> str:
        return f"http://127.0.0.1:{self.port}/"

    # The sender's sink: every chunk to the recording and to the clients.
    def start_stream(self, header: bytes, actor: bytes) -> None:
        if self._recording is not None:
            self._recording.write(header + actor)
        self.hub.start(header, actor)

    def packet(self, first: int, arrived: list[float], data: bytes) -> None:
        if self._recording is not None:
            self._recording.write(data)
        self.hub.packet(first, arrived, data)

    def end(self, error: str | None) -> None:
        self.hub.end(error)

    def start(self) -> None:
        """Serve, and start reading, analysing and streaming."""
        assert self.server is not None  # made when the call opens
        self._serving = threading.Thread(target=self.server.serve_forever, name="call server", daemon=True)
        self._serving.start()
        self.sender.start()

    def wait(self, timeout: float | None = None) -> bool:
        """Wait for the source to end (``timeout`` s at most); whether it has. Raises what stopped
        the sender, if anything did."""
        # an Event, not Thread.join: a signal's exception raised within a join can leave the thread
        # marked as ended while it runs on (CPython 3.11)
        ended = self.sender.finished.wait(timeout)
        if self.sender.error is not None:
            raise self.sender.error
        return ended

    def close(self) -> None:
        """Stop the sender; after the source's end, let the clients have what was sent (1 s at
        most); close the remaining clients (1001) and the server; put the recording in place."""
        self.sender.stop()
        if self.sender.ident is None:  # never started
            self.source.close()
        else:
            self.sender.finished.wait(2.0)
        if not self.hub.ended:
            self.hub.close_all(GOING_AWAY)
        self.hub.wait_empty(1.0)
        self.hub.close_all(GOING_AWAY)
        assert self.server is not None  # made when the call opens
        self.server.shutdown()
        if self._serving is not None:
            self._serving.join(2.0)
        if self._recording is not None:
            self._recording.close(keep=self.sender.error is None and self.sender.stats.header_bytes > 0)

    def __enter__(self) -> Call:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()
