"""The web side of ``facemime call``: one port on 127.0.0.1 serving the receiver's page (``/``,
``/receiver.js``, from the package's ``web`` folder) and the live stream as a WebSocket
(``/stream``).

Requests must be addressed to this machine and come from the server's own pages
(:func:`facemime.local_only.addressed_here`: 403 otherwise).

The WebSocket protocol (server → client; every chunk of the stream is one binary message):

- ``{"type":"hello","source":NAME,"fps":FPS,"width":W,"height":H}`` (text) on connecting;
- the header chunk, then the actor chunk, as soon as the stream has started (at once, or when
  the sender's warm-up ends);
- per packet: ``{"type":"frames","first":F,"arrived":[MS,...]}`` (text), then the packet chunk:
  F is the index of the packet's first frame from the stream's start (packet s holds frames
  s × P ...), ``arrived`` each of its frames' arrival at the sender, ms since the epoch (the
  clock of ``performance.timeOrigin + performance.now()`` on this machine);
- ``{"type":"end"}`` (text, with ``"error": MESSAGE`` when the source failed) when the source
  has ended; the server then closes with code 1000.

Client → server: only the text ``{"type":"intra"}``, asking for the next packet to be intra (for
every receiver; a request while the next packet is intra already changes nothing). Anything else
(binary, not JSON, another type) closes the connection with code 1003; a message over
:data:`MAX_MESSAGE` bytes with 1009. A client that falls :data:`MAX_BEHIND` seconds behind is
closed with 1008; the sender never waits for a client. When the call stops, clients still
connected are closed with 1001.
"""

from __future__ import annotations

import contextlib
import email.utils
import json
import logging
import socket
import threading
import time
from collections import deque
from collections.abc import Callable
from importlib import resources
from importlib.resources.abc import Traversable
from pathlib import Path
from urllib.parse import urlsplit

from websockets.datastructures import Headers
from websockets.exceptions import ConnectionClosed
from websockets.http11 import Request, Response
from websockets.sync.server import Server, ServerConnection, serve

from facemime.errors import InvalidInputError
from facemime.local_only import addressed_here

#: The port ``facemime call`` listens on unless told (0: any free port).
PORT = 8766
#: The largest message a client may send, bytes (beyond: closed with 1009).
MAX_MESSAGE = 1024
#: Seconds of messages a client may have waiting before it is closed (1008) as too slow.
MAX_BEHIND = 2.0
#: Stream connections at once (more are answered 503).
MAX_CLIENTS = 16
#: Seconds a closing handshake may take before the connection is dropped.
CLOSE_TIMEOUT = 1.0
#: Path -> (file in the web folder, content type).
PAGES = {
    "/": ("index.html", "text/html; charset=utf-8"),
    "/receiver.js": ("receiver.js", "text/javascript; charset=utf-8"),
}
#: WebSocket close codes.
NORMAL, GOING_AWAY, UNSUPPORTED, POLICY = 1000, 1001, 1003, 1008

_LOGGER = logging.getLogger("facemime.call.websockets")
_LOGGER.addHandler(logging.NullHandler())  # the library's own messages: none (errors are told in one line)
_LOGGER.propagate = False


def web_folder() -> Traversable:
    """The package's ``web`` folder.

    Returns
    -------
    Traversable
        The folder of the receiver's page and script.
    """
    return resources.files("facemime") / "web"


class Client:
    """One stream connection's queue of messages (text or binary), filled by the sender's thread
    without waiting, emptied by the connection's own thread (:meth:`take`).

    Parameters
    ----------
    connection
        The client's WebSocket connection.
    """

    def __init__(self, connection: ServerConnection):
        self.connection = connection
        self._items: deque[tuple[float, str | bytes]] = deque()
        self._changed = threading.Condition()
        self.closing: tuple[int, str] | None = None  # (code, reason) to close with
        self._drain = False  # send what is queued before closing
        self._gone = False

    def put(self, *messages: str | bytes) -> None:
        """Queue messages; a client whose oldest message waits over :data:`MAX_BEHIND` s is
        closed instead (1008).

        Parameters
        ----------
        *messages
            The messages, in order: str for a text message, bytes for a binary one.
        """
        now = time.monotonic()
        with self._changed:
            if self.closing is not None or self._gone:
                return
            if self._items and now - self._items[0][0] > MAX_BEHIND:
                behind = True
            else:
                behind = False
                self._items.extend((now, m) for m in messages)
                self._changed.notify_all()
        if behind:
            self.close(POLICY, f"more than {MAX_BEHIND:g} s behind")
            # its thread is stuck sending: cut the connection if it has not closed in a second
            timer = threading.Timer(CLOSE_TIMEOUT, self._abort)
            timer.daemon = True
            timer.start()

    def close(self, code: int, reason: str, drain: bool = False) -> None:
        """Close the connection (the first call only counts).

        Parameters
        ----------
        code
            The WebSocket close code.
        reason
            The close reason, text.
        drain
            Send the messages queued first; False: drop them and close at once.
        """
        with self._changed:
            if self.closing is None:
                self.closing, self._drain = (code, reason), drain
                if not drain:
                    self._items.clear()
                self._changed.notify_all()

    def vanished(self) -> None:
        """The connection has closed (the client left, or it broke)."""
        with self._changed:
            self._gone = True
            self._changed.notify_all()

    def take(self) -> str | bytes | None:
        """The next message to send, waiting for one.

        Returns
        -------
        str, bytes or None
            The message (str: text, bytes: binary); None when the connection is to close
            (:attr:`closing` says how; None there: it has closed).
        """
        with self._changed:
            self._changed.wait_for(lambda: self._items or self.closing is not None or self._gone)
            if self._items and not self._gone and (self.closing is None or self._drain):
                return self._items.popleft()[1]
            return None

    def _abort(self) -> None:
        with contextlib.suppress(OSError):
            self.connection.socket.shutdown(socket.SHUT_RDWR)


class Hub:
    """The stream's clients: the sender hands each chunk over once (:meth:`start`,
    :meth:`packet`, :meth:`end`), every client gets it in its own queue.

    Parameters
    ----------
    hello
        The fields of the first message of every client besides its type: ``source``, ``fps``
        (frames/s), ``width``, ``height`` (pixels).
    on_intra
        Called (no arguments; its result ignored) on a client's request for an intra packet.
    """

    def __init__(self, hello: dict, on_intra: Callable[[], object]):
        self._hello = json.dumps({"type": "hello", **hello})
        self.on_intra = on_intra
        self._lock = threading.Condition()
        self._clients: set[Client] = set()
        self._start: tuple[bytes, bytes] | None = None
        self._end: str | None = None
        self.served = 0  # stream connections so far

    @property
    def ended(self) -> bool:
        """Whether the source has ended (:meth:`end`)."""
        return self._end is not None

    def __len__(self) -> int:
        with self._lock:
            return len(self._clients)

    def join(self, client: Client) -> None:
        """A client connects: it gets the hello, the stream's start if it has started, and the
        end (then it is closed) if the source has ended.

        Parameters
        ----------
        client
            The new client's queue.
        """
        with self._lock:
            self.served += 1
            self._clients.add(client)
            client.put(self._hello)
            if self._start is not None:
                client.put(*self._start)
            if self._end is not None:
                client.put(self._end)
                client.close(NORMAL, "the source has ended", drain=True)

    def leave(self, client: Client) -> None:
        """A client has gone.

        Parameters
        ----------
        client
            Its queue.
        """
        with self._lock:
            self._clients.discard(client)
            self._lock.notify_all()

    def start(self, header: bytes, actor: bytes) -> None:
        """The stream starts: its header and actor chunks, to every client now and later.

        Parameters
        ----------
        header
            The header chunk.
        actor
            The actor chunk; b"": none (the stream does not carry the actor).
        """
        with self._lock:
            self._start = (header, actor) if actor else (header,)
            for c in self._clients:
                c.put(*self._start)

    def packet(self, first: int, arrived: list[float], data: bytes) -> None:
        """A packet chunk, to every client after its ``frames`` message.

        Parameters
        ----------
        first
            The index of the packet's first frame from the stream's start.
        arrived
            Each of its frames' arrival at the sender, ms since the epoch.
        data
            The packet chunk.
        """
        text = json.dumps({"type": "frames", "first": first, "arrived": [round(t, 3) for t in arrived]})
        with self._lock:
            for c in self._clients:
                c.put(text, data)

    def end(self, error: str | None = None) -> None:
        """The source has ended: every client gets the end message and is closed (1000).

        Parameters
        ----------
        error
            Why the source failed (its whitespace collapsed into single spaces in the message);
            None: it ended normally.
        """
        with self._lock:
            self._end = json.dumps({"type": "end"} | ({"error": " ".join(error.split())} if error else {}))
            for c in self._clients:
                c.put(self._end)
                c.close(NORMAL, "the source has ended", drain=True)

    def close_all(self, code: int = GOING_AWAY, reason: str = "the call is over") -> None:
        """Close every client now, dropping its queued messages.

        Parameters
        ----------
        code
            The WebSocket close code.
        reason
            The close reason, text.
        """
        with self._lock:
            for c in self._clients:
                c.close(code, reason)

    def wait_empty(self, timeout: float) -> bool:
        """Wait for every client to have left.

        Parameters
        ----------
        timeout
            The longest wait, seconds.

        Returns
        -------
        bool
            Whether they have.
        """
        with self._lock:
            return self._lock.wait_for(lambda: not self._clients, timeout)


def _read(connection: ServerConnection, client: Client, hub: Hub) -> None:
    """A client's messages: intra requests; anything else closes it."""
    try:
        for message in connection:
            request = None
            if isinstance(message, str):
                with contextlib.suppress(ValueError):
                    request = json.loads(message)
            if isinstance(request, dict) and request.get("type") == "intra":
                hub.on_intra()
                continue
            client.close(UNSUPPORTED, 'only {"type":"intra"} is accepted')
            return
    except ConnectionClosed:
        pass
    client.vanished()


def _handle(connection: ServerConnection, hub: Hub) -> None:
    """A stream connection: its queue's messages sent in order until it closes."""
    client = Client(connection)
    hub.join(client)
    reader = threading.Thread(target=_read, args=(connection, client, hub), name="call client reader", daemon=True)
    reader.start()
    try:
        while (message := client.take()) is not None:
            connection.send(message)
        if client.closing is not None:
            connection.close(*client.closing)
    except (ConnectionClosed, OSError):
        pass
    finally:
        hub.leave(client)


def _response(status: int, phrase: str, body: bytes, kind: str) -> Response:
    return Response(
        status,
        phrase,
        Headers(
            [
                ("Date", email.utils.formatdate(usegmt=True)),
                ("Connection", "close"),
                ("Content-Length", str(len(body))),
                ("Content-Type", kind),
                ("Cache-Control", "no-store"),
            ]
        ),
        body,
    )


def make_server(hub: Hub, port: int = PORT, web: Path | Traversable | None = None) -> Server:
    """The call's server on 127.0.0.1, not yet serving.

    Parameters
    ----------
    hub
        The stream's clients.
    port
        The TCP port, 0-65535; 0: any free port.
    web
        The folder of the page and script; None: :func:`web_folder`.

    Returns
    -------
    Server
        The server, listening (its socket bound); ``serve_forever`` serves.
    """
    if isinstance(port, bool) or not isinstance(port, int) or not 0 <= port <= 65535:
        raise InvalidInputError(f"port must be a whole number from 0 to 65535 (0: any free port), got {port!r}")
    folder = web_folder() if web is None else web
    bound: list[int] = []

    def process_request(connection: ServerConnection, request: Request) -> Response | None:
        if not addressed_here(request.headers.get_all("Host"), request.headers.get_all("Origin"), bound[0]):
            return _response(403, "Forbidden", b"only pages of this machine may use the call", "text/plain")
        path = urlsplit(request.path).path
        if path == "/stream":
            if len(hub) >= MAX_CLIENTS:
                return _response(503, "Service Unavailable", b"too many clients; try again later", "text/plain")
            return None  # the WebSocket handshake
        if path not in PAGES:
            return _response(404, "Not Found", b"not found", "text/plain")
        name, kind = PAGES[path]
        try:
            body = (folder / name).read_bytes()
        except OSError:
            return _response(404, "Not Found", f"{name} is missing from this installation".encode(), "text/plain")
        return _response(200, "OK", body, kind)

    try:
        server = serve(
            lambda connection: _handle(connection, hub),
            "127.0.0.1",
            port,
            process_request=process_request,
            max_size=MAX_MESSAGE,
            compression=None,
            close_timeout=CLOSE_TIMEOUT,
            server_header=None,
            logger=_LOGGER,
        )
    except OSError as e:
        raise InvalidInputError(f"cannot listen on port {port}: {e.strerror or e}; pick another with --port") from None
    bound.append(server.socket.getsockname()[1])
    return server
