"""``facemime view``'s web server: the :class:`~facemime.app.view.Viewer`'s frames and keys served
to a browser on this machine.

The page shows an MJPEG stream (``/stream``); ``/key?k=NAME`` applies a key and answers the new
state as JSON; ``/frame.jpg`` is the next frame. The server listens on 127.0.0.1 only, answers
only requests addressed to this machine and from its own pages
(:func:`facemime.local_only.addressed_here`: 403 otherwise), of at most :data:`MAX_HEAD` bytes
and without a body, and serves at most ``max_clients`` connections at once (503 beyond), each dropped after ``timeout``
seconds without progress.

Every client sees the same frames: one thread plays the viewer at its frame rate while anyone
watches (:class:`Broadcast`), encodes each frame once and keeps the last :attr:`Broadcast.KEEP`;
each client sends them in order from its own frame number on, waiting for the next one, and one
that falls further behind skips to the newest. An error of the source (a video that changes its
frame size, an undecodable one) ends playing: it is written to stderr as one line, and every
stream ends with an image of the message.
"""

from __future__ import annotations

import functools
import io
import json
import socket
import sys
import textwrap
import threading
import time
from collections import deque
from collections.abc import Generator
from contextlib import closing, suppress
from http import HTTPStatus
from http.client import LineTooLong
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from typing import Any, cast
from urllib.parse import parse_qs, urlparse

import cv2
import numpy as np

from facemime.app.view import HELP, KEYS, Viewer
from facemime.errors import FacemimeError, InvalidInputError
from facemime.local_only import addressed_here

#: The most bytes of a request's line and headers together.
MAX_HEAD = 8192


PAGE = """<!doctype html><html lang="en"><head><meta charset="utf-8"><title>facemime view</title>
<style>body{background:#222;color:#ddd;font:14px system-ui,sans-serif;text-align:center}img{max-width:98vw}</style>
</head><body><img src="/stream" alt="facemime"><p>%s</p><p id="s"></p><script>
addEventListener('keydown', async ev => {
  const k = ev.key; if (!%s.includes(k)) return; ev.preventDefault();
  const r = await fetch('/key?k=' + encodeURIComponent(k)); document.getElementById('s').textContent = await r.text();
});</script></body></html>"""


def jpeg(frame: np.ndarray) -> bytes:
    """Encode a frame as JPEG (quality 85).

    Parameters
    ----------
    frame
        (H, W, 3) uint8 RGB image.

    Returns
    -------
    bytes
        The JPEG file.
    """
    return cv2.imencode(".jpg", cv2.cvtColor(frame, cv2.COLOR_RGB2BGR), [cv2.IMWRITE_JPEG_QUALITY, 85])[1].tobytes()


def describe(e: BaseException) -> str:
    """An error as one line.

    Parameters
    ----------
    e
        The error.

    Returns
    -------
    str
        Its message, whitespace collapsed; for an unexpected one (not a
        :class:`~facemime.errors.FacemimeError`), ``unexpected TYPE: message (a bug in facemime)``.
    """
    text = str(e) if isinstance(e, FacemimeError) else f"unexpected {type(e).__name__}: {e} (a bug in facemime)"
    return " ".join(text.split())


def report(e: BaseException) -> None:
    """Tell an error of the server's threads on stderr, in one line (``facemime: error: ...``).

    Parameters
    ----------
    e
        The error (see :func:`describe`).
    """
    print(f"facemime: error: {describe(e)}", file=sys.stderr, flush=True)


def message_image(text: str) -> np.ndarray:
    """An image of a message, light red on the page's dark grey.

    Parameters
    ----------
    text
        The message; characters outside ASCII are shown as ``?``, lines wrapped at 64 characters.

    Returns
    -------
    (24 + 28 × lines, 760, 3) uint8 array
        RGB.
    """
    lines = textwrap.wrap(text.encode("ascii", "replace").decode(), 64) or [""]
    image = np.full((24 + 28 * len(lines), 760, 3), 34, np.uint8)
    for i, line in enumerate(lines):
        cv2.putText(image, line, (16, 34 + 28 * i), cv2.FONT_HERSHEY_SIMPLEX, 0.6, (255, 140, 140), 1, cv2.LINE_AA)
    return image


class Broadcast:
    """The viewer's frames, as JPEG, for every client at once: one thread plays the viewer at its
    frame rate while anyone watches (:meth:`frames`) and keeps the last :data:`KEEP` frames; an
    error of the viewer's stops playing for good, with ``error`` its one-line message, reported on
    stderr once.

    Parameters
    ----------
    viewer
        The viewer to play.
    """

    #: Frames kept for clients that fall behind; one further behind skips to the newest frame.
    KEEP = 16

    def __init__(self, viewer: Viewer):
        self.viewer = viewer
        self.error: str | None = None
        self._recent: deque[bytes] = deque(maxlen=self.KEEP)
        self._played = 0  # the number of the newest frame in _recent
        self._watchers = 0
        self._player: threading.Thread | None = None
        self._closed = False
        self._changed = threading.Condition()

    def _past(self, frame: int) -> bool:
        """Whether ``frame`` has been played, or playing has stopped."""
        return self._played >= frame or self._closed or self.error is not None

    def frames(self) -> Generator[tuple[int, bytes], None, None]:
        """The frames played from now on, in order, until playing stops (an error, or
        :meth:`close`); a client more than :data:`KEEP` frames behind skips to the newest. Starts
        the player thread if none runs.

        Yields
        ------
        tuple of (int, bytes)
            The frame's number (counting the frames played since the broadcast began, from 1) and
            its JPEG file.
        """
        with self._changed:
            self._watchers += 1
            if self._player is None and not self._closed and self.error is None:
                self._player = threading.Thread(target=self._play, name="viewer player", daemon=True)
                self._player.start()
            want = self._played + 1
        try:
            while True:
                with self._changed:
                    self._changed.wait_for(functools.partial(self._past, want))
                    if self._closed or self._played < want:
                        return
                    oldest = self._played - len(self._recent) + 1
                    if want < oldest:  # too far behind: on with the newest
                        want = self._played
                    body = self._recent[want - oldest]
                yield want, body
                want += 1
        finally:
            with self._changed:
                self._watchers -= 1

    def _play(self) -> None:
        """The player thread: a frame every 1/fps seconds until no one watches or playing stops."""
        while True:
            start = time.monotonic()
            try:
                body = jpeg(self.viewer.frame())
            except Exception as e:  # noqa: BLE001 (any error of the source stops playing, told in one line)
                with self._changed:
                    self.error, self._player = describe(e), None
                    self._changed.notify_all()
                report(e)
                return
            with self._changed:
                self._recent.append(body)
                self._played += 1
                self._changed.notify_all()
                self._changed.wait_for(lambda: self._closed, 1 / self.viewer.fps - (time.monotonic() - start))
                if self._closed or not self._watchers:
                    self._player = None
                    return

    def close(self) -> None:
        """Stop playing, for good: streams end, and the player thread has ended on return."""
        with self._changed:
            self._closed = True
            self._changed.notify_all()
            player = self._player
        if player is not None:
            player.join()


class _Head(io.BufferedIOBase):
    """A request's reader that gives at most :data:`MAX_HEAD` bytes, in lines (the request line
    and headers): beyond, it raises :class:`LineTooLong`.

    Parameters
    ----------
    rfile
        The connection's buffered binary reader.
    """

    def __init__(self, rfile: Any):
        self._rfile, self._left = rfile, MAX_HEAD

    def readline(self, size: int | None = -1) -> bytes:
        size = -1 if size is None else size
        line = self._rfile.readline(self._left + 1 if size < 0 else min(size, self._left + 1))
        self._left -= len(line)
        if self._left < 0:
            raise LineTooLong(f"request line and headers over {MAX_HEAD} bytes")
        return line

    def close(self) -> None:
        self._rfile.close()


class ViewerServer(ThreadingHTTPServer):
    """The viewer's web server (see :func:`make_server`), on 127.0.0.1. Closing it stops the
    broadcast, cuts every open connection and waits for their threads: no thread of the server
    outlives it (a process that exits right after, as ``facemime view`` on Ctrl-C, has none left
    writing to a socket or to stderr).

    Parameters
    ----------
    port
        The TCP port to listen on (0: any free port).
    handler
        The request handler class (:func:`make_server`'s).
    broadcast
        The frames the clients are sent.
    max_clients
        The most connections served at once; more are answered 503.
    """

    daemon_threads = False  # joined by server_close (ThreadingMixIn), once their connections are cut

    def __init__(self, port: int, handler: type[BaseHTTPRequestHandler], broadcast: Broadcast, max_clients: int):
        super().__init__(("127.0.0.1", port), handler)
        self.broadcast = broadcast
        self._slots = threading.BoundedSemaphore(max_clients)
        self._open: set[socket.socket] = set()  # the connections being served
        self._open_lock = threading.Lock()

    def process_request(self, request: Any, client_address: Any) -> None:
        """Serve a connection on a thread of its own, or answer 503 and close it when
        ``max_clients`` are being served.

        Parameters
        ----------
        request
            The connection's socket.
        client_address
            The client's (host, port).
        """
        if not self._slots.acquire(blocking=False):
            with suppress(OSError):
                request.sendall(
                    b"HTTP/1.0 503 Service Unavailable\r\nContent-Type: text/plain\r\n"
                    b"Content-Length: 33\r\nConnection: close\r\n\r\ntoo many clients; try again later"
                )
            self.shutdown_request(request)
            return
        with self._open_lock:
            self._open.add(request)
        super().process_request(request, client_address)

    def process_request_thread(self, request: Any, client_address: Any) -> None:
        """Serve a connection (on its thread), then free its slot.

        Parameters
        ----------
        request
            The connection's socket.
        client_address
            The client's (host, port).
        """
        try:
            super().process_request_thread(request, client_address)
        finally:
            with self._open_lock:
                self._open.discard(request)
            self._slots.release()

    def handle_error(self, request: Any, client_address: Any) -> None:
        """A request's error (the one being handled) in one line on stderr, none for a client
        gone or too slow.

        Parameters
        ----------
        request
            The connection's socket.
        client_address
            The client's (host, port).
        """
        e = sys.exc_info()[1]
        if e is not None and not isinstance(e, (ConnectionError, TimeoutError)):
            report(e)

    def server_close(self) -> None:
        """Stop listening and playing, cut the open connections (a client that reads nothing, or
        sends nothing, would otherwise hold its thread up to ``timeout``) and join their threads."""
        self.socket.close()
        self.broadcast.close()
        with self._open_lock:
            for connection in self._open:
                with suppress(OSError):
                    connection.shutdown(socket.SHUT_RDWR)
        super().server_close()


def make_server(viewer: Viewer, port: int = 8765, timeout: float = 10.0, max_clients: int = 16) -> ViewerServer:
    """The web server of a viewer, on 127.0.0.1; not yet serving. It serves the page (``/``),
    the MJPEG stream (``/stream``), the next frame (``/frame.jpg``) and keys (``/key?k=NAME``),
    see the module docstring.

    Parameters
    ----------
    viewer
        The viewer whose frames are served.
    port
        The TCP port to listen on (default 8765; 0: any free port, see ``server_address``).
    timeout
        Seconds without progress after which a connection is dropped.
    max_clients
        The most connections served at once; beyond, one is answered 503.

    Returns
    -------
    ViewerServer
        The server, bound and listening; call ``serve_forever`` to serve.
    """
    if isinstance(port, bool) or not isinstance(port, int) or not 0 <= port <= 65535:
        raise InvalidInputError(f"port must be a whole number from 0 to 65535 (0: any free port), got {port!r}")
    keys = json.dumps(sorted(KEYS) + ["r", " "])
    broadcast = Broadcast(viewer)

    class Handler(BaseHTTPRequestHandler):
        def log_message(self, *args: object) -> None:  # quiet: progress goes nowhere
            pass

        def setup(self) -> None:
            super().setup()
            self.rfile = _Head(self.rfile)

        def handle_one_request(self) -> None:
            try:
                super().handle_one_request()
            except LineTooLong:  # in the request line (parse_request answers an overlong header itself)
                self.requestline, self.request_version, self.command = "", "", ""
                self.send_error(HTTPStatus.REQUEST_HEADER_FIELDS_TOO_LARGE, f"over {MAX_HEAD} bytes")

        def parse_request(self) -> bool:
            """Parse the request line and headers; refuse requests not addressed to this machine
            by name (403) and requests with a body (413).

            Returns
            -------
            bool
                Whether the request is to be answered (False: the error is sent already).
            """
            if not super().parse_request():
                return False
            hosts, origins = self.headers.get_all("Host", []), self.headers.get_all("Origin", [])
            if not addressed_here(hosts, origins, cast(ViewerServer, self.server).server_port):
                self.send_error(HTTPStatus.FORBIDDEN, "only pages of this machine may use the viewer")
                return False
            if self.headers.get("Content-Length", "0").strip() != "0" or "Transfer-Encoding" in self.headers:
                self.send_error(HTTPStatus.REQUEST_ENTITY_TOO_LARGE, "requests with a body are not accepted")
                return False
            return True

        def _send(self, body: bytes, kind: str, status: HTTPStatus = HTTPStatus.OK) -> None:
            self.send_response(status)
            self.send_header("Content-Type", kind)
            self.send_header("Content-Length", str(len(body)))
            self.send_header("Cache-Control", "no-store")
            self.end_headers()
            self.wfile.write(body)

        def _stopped(self) -> str:
            return broadcast.error or "the viewer has stopped"

        def do_GET(self) -> None:
            url = urlparse(self.path)
            if url.path == "/":
                self._send((PAGE % (HELP, keys)).encode(), "text/html; charset=utf-8")
            elif url.path == "/frame.jpg":
                with closing(broadcast.frames()) as frames:
                    frame = next(frames, None)
                if frame is None:
                    self._send(self._stopped().encode(), "text/plain; charset=utf-8", HTTPStatus.SERVICE_UNAVAILABLE)
                else:
                    self._send(frame[1], "image/jpeg")
            elif url.path == "/key":
                try:
                    state = viewer.key(parse_qs(url.query).get("k", [""])[0])
                except InvalidInputError as e:
                    self._send(str(e).encode(), "text/plain; charset=utf-8", HTTPStatus.BAD_REQUEST)
                    return
                self._send(json.dumps(state).encode(), "application/json")
            elif url.path == "/stream":
                self._stream()
            else:
                self._send(b"not found", "text/plain", HTTPStatus.NOT_FOUND)

        def _stream(self) -> None:
            """The frames as they play, each a part with its number (``X-Frame``); when an error
            stops playing, a last part with an image of its message (``X-Error``: the text)."""
            self.send_response(HTTPStatus.OK)
            self.send_header("Content-Type", "multipart/x-mixed-replace; boundary=frame")
            self.send_header("Cache-Control", "no-store")
            self.end_headers()
            part = b"--frame\r\nContent-Type: image/jpeg\r\nContent-Length: %d\r\n%s\r\n%s\r\n"
            try:
                with closing(broadcast.frames()) as frames:
                    for number, body in frames:
                        self.wfile.write(part % (len(body), b"X-Frame: %d\r\n" % number, body))
                if broadcast.error is not None:
                    body = jpeg(message_image(f"facemime: {broadcast.error}"))
                    self.wfile.write(
                        part % (len(body), b"X-Error: %s\r\n" % broadcast.error.encode("ascii", "replace"), body)
                    )
                self.wfile.write(b"--frame--\r\n")
            except (ConnectionError, TimeoutError):  # the client has gone, or is too slow
                return

    Handler.timeout = timeout
    try:
        return ViewerServer(port, Handler, broadcast, max_clients)
    except OSError as e:
        raise InvalidInputError(f"cannot listen on port {port}: {e.strerror or e}; pick another with --port") from None
