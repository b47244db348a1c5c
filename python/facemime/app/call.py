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

from facemime.call.sender import KEYFRAME, PACKET_FRAMES, RATE, WARMUP, Sender
from facemime.call.server import GOING_AWAY, PORT, Hub, make_server
from facemime.errors import InvalidInputError
from facemime.io.live_source import open_source
from facemime.io.outputs import OutputFileError, check_outputs, temporary_sibling
from facemime.types.actor import Actor

__all__ = ["KEYFRAME", "PACKET_FRAMES", "PORT", "RATE", "WARMUP", "Call"]

#: The suffix of a recording (``--record``).
SUFFIX = ".fmstream"


class _Recording:
    """The stream's bytes as sent, written to a temporary file beside ``path`` and put in place
    by :meth:`close` (kept when the call is stopped: every chunk in it is whole).

    Parameters
    ----------
    path
        The recording's ``.fmstream`` file.
    """

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
    """A live call: a source analysed and streamed by a :class:`~facemime.call.sender.Sender` to
    the clients of a server on 127.0.0.1. Opening checks the inputs, binds the port and fits the
    actor on the first frame (or places the given one; a source without a face fails there, in
    one line); :meth:`start` serves and streams, :meth:`wait` returns when the source has ended,
    :meth:`close` (or leaving a ``with`` block) stops everything within a second or two.

    Parameters
    ----------
    source
        A video file (played at its own frame rate), or a camera's index (a whole number, such as
        ``0``, that names no file).
    actor
        The actor to send; None fits one on the first frame. The stream carries it.
    port
        The server's TCP port on 127.0.0.1 (default :data:`PORT`, 8766; 0: any free port, see
        :attr:`port`).
    quality
        0 (coarsest) to 10 (finest); None takes the finest whose warm-up frames code within
        ``rate``.
    packet_frames
        Frames per packet, 1-32 (default :data:`PACKET_FRAMES`, 2): more add delay, fewer add bytes
        of framing.
    record
        A file (its name ending in ``.fmstream``) that gets the stream's bytes as sent, put in
        place by :meth:`close`; None records nothing. Refused when it exists (unless ``force``) or
        is one of the inputs.
    force
        Write over an existing ``record``.
    loop
        Play a video file again and again, as one continuing stream.
    web
        The folder of the receiver's page and script; None: the package's ``web`` folder.
    keyframe
        Seconds between scheduled intra packets (default :data:`KEYFRAME`, 5 s; at least one
        packet); a receiver can also ask for one.
    warmup
        Seconds of analysed frames the motion's basis is learned from before the stream starts
        (default :data:`WARMUP`, 2 s); they are not streamed.
    actor_path
        The file ``actor`` was loaded from, so that ``record`` is refused when it is that file;
        None when there is none.
    rate
        The motion's target rate, kbit/s (default :data:`RATE`, 2), used when ``quality`` is None.
    """

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
        """The TCP port the server is bound to on 127.0.0.1 (the free one chosen for port 0)."""
        assert self.server is not None  # made when the call opens
        return self.server.socket.getsockname()[1]

    @property
    def url(self) -> str:
        """The receiver page's address, ``http://127.0.0.1:PORT/``."""
        return f"http://127.0.0.1:{self.port}/"

    # The sender's sink: every chunk to the recording and to the clients.
    def start_stream(self, header: bytes, actor: bytes) -> None:
        """The stream starts (called by the sender): to the recording and every client.

        Parameters
        ----------
        header
            The stream's header chunk (``docs/bitstream.md``).
        actor
            Its actor chunk.
        """
        if self._recording is not None:
            self._recording.write(header + actor)
        self.hub.start(header, actor)

    def packet(self, first: int, arrived: list[float], data: bytes) -> None:
        """A packet (called by the sender): to the recording and every client.

        Parameters
        ----------
        first
            Index of its first frame, counting the streamed frames from the stream's start.
        arrived
            When each of its frames arrived, ms since the epoch.
        data
            The packet chunk.
        """
        if self._recording is not None:
            self._recording.write(data)
        self.hub.packet(first, arrived, data)

    def end(self, error: str | None) -> None:
        """The source has ended (called by the sender): every client gets the end message.

        Parameters
        ----------
        error
            Why, when the source failed; None when it simply ended.
        """
        self.hub.end(error)

    def start(self) -> None:
        """Serve, and start reading, analysing and streaming."""
        assert self.server is not None  # made when the call opens
        self._serving = threading.Thread(target=self.server.serve_forever, name="call server", daemon=True)
        self._serving.start()
        self.sender.start()

    def wait(self, timeout: float | None = None) -> bool:
        """Wait for the source to end. Raises what stopped the sender, if anything did.

        Parameters
        ----------
        timeout
            Seconds to wait at most; None waits until the source ends.

        Returns
        -------
        bool
            Whether the sender has ended (the source ended or failed, or the call was stopped).
        """
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
