"""``facemime view``: the interactive viewer, served to a web browser on this machine.

A video is analysed live as it plays (original with contours | synthesised face); a track file
written by ``facemime run`` replays its recorded motion. Keys in the browser add motion, as the
paper's keyboard did: arrows turn and tilt the head, ``q``/``e`` roll it, ``+``/``-`` zoom,
``x``/``z`` exaggerate or calm the mouth and brow motion, ``r`` resets, space pauses.

The page shows an MJPEG stream (``/stream``); ``/key?k=NAME`` applies a key and answers the new
state as JSON; ``/frame.jpg`` is the current frame. The server listens on 127.0.0.1 only.
"""

from __future__ import annotations

import json
import threading
import time
from collections.abc import Iterator
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from urllib.parse import parse_qs, urlparse

import cv2
import numpy as np

from facemime.animate.analysis import Analysis
from facemime.animate.synth import BACKGROUND, Puppet, UserMotion
from facemime.errors import InputFileError, InvalidInputError, NoFaceError
from facemime.fit.actor import Actor, generic_actor
from facemime.fit.placement import model_iod
from facemime.io.contours_json import read_motion
from facemime.io.video import VideoReader
from facemime.render.projection import Pose
from facemime.render.texture_map import fill
from facemime.track.overlay import draw_contours

#: Key -> the change it makes to the user motion.
KEYS = {
    "ArrowLeft": {"yaw": -5.0}, "ArrowRight": {"yaw": 5.0}, "ArrowUp": {"pitch": -5.0}, "ArrowDown": {"pitch": 5.0},
    "q": {"roll": 5.0}, "e": {"roll": -5.0}, "+": {"zoom": 1.1}, "=": {"zoom": 1.1}, "-": {"zoom": 1 / 1.1},
    "x": {"gain": 1.25}, "z": {"gain": 0.8},
}
HELP = "arrows: turn and tilt · q/e: roll · +/-: zoom · x/z: more/less motion · r: reset · space: pause"


class Viewer:
    """The viewer's state and frames, without the web server: feed keys with :meth:`key`, take
    frames (RGB uint8) with :meth:`frame`.

    ``source``: a video file (analysed live) or a ``facemime.track/1`` file with motion (from
    ``facemime run``); ``actor``: the face to drive (default: for a video, the face fitted on its
    first frame; for a track file, the generic head). A video is decoded on a thread of its
    reader's while the viewer plays it: :meth:`close` (or leaving a ``with`` block) stops it.
    """

    def __init__(self, source: str | Path, actor: Actor | None = None):
        self.source = Path(source)
        if not self.source.exists():
            raise InputFileError(f"{self.source} does not exist")
        self.user = UserMotion()
        self.paused = False
        self._lock = threading.Lock()
        self._actor = actor
        self._is_track = self.source.suffix.lower() == ".json"
        if self._is_track:
            video, model, self._motions = read_motion(self.source)
            self.size = (int(video.get("width", 512)), int(video.get("height", 512)))
            self.fps = float(video.get("fps", 25.0))
            driven = actor or generic_actor()
            iod = model.get("iod", model_iod(driven.model))
            self._puppet = Puppet(driven, np.asarray(model["feature_sizes"], float), float(iod))
        else:
            with VideoReader(self.source) as r:
                self.size, self.fps = (r.width, r.height), r.fps
        self._frames = self._play()
        self._shown = next(self._frames)

    def _play(self) -> Iterator[tuple[np.ndarray | None, Pose, np.ndarray, Puppet]]:
        """(left panel or None, pose, knot offsets, puppet) per frame, looping forever."""
        while True:
            if self._is_track:
                for m in self._motions:
                    yield None, Pose(**m["pose"]), m["offsets"], self._puppet
                continue
            analysis = None
            with VideoReader(self.source) as reader:
                for frame in reader:
                    if analysis is None:
                        try:
                            analysis = Analysis(frame, str(self.source))
                        except NoFaceError as e:
                            raise NoFaceError(f"{e}; the video must start with a frontal face") from None
                        puppet = Puppet(self._actor or analysis.actor, analysis.deformer.feature_sizes(),
                                        model_iod(analysis.actor.model))
                        m = analysis.last
                    else:
                        m = analysis.update(frame)
                    yield (draw_contours(frame, m.contours, m.lost) if m.face else frame), m.pose, m.offsets, puppet
            if analysis is None:
                raise InputFileError(f"video {self.source} has no frames")

    def _render(self) -> np.ndarray:
        left, pose, offsets, puppet = self._shown
        synth = fill(np.empty((self.size[1], self.size[0], 3), np.uint8), BACKGROUND)
        puppet.render(pose, offsets, self.size, self.user, out=synth)
        return synth if left is None else np.hstack([left, synth])

    def key(self, name: str) -> dict:
        """Apply key ``name`` (see :data:`KEYS`; also ``r`` and `` ``); returns :meth:`state`."""
        with self._lock:
            if name in KEYS:
                self.user = self.user.changed(**KEYS[name])
            elif name == "r":
                self.user = UserMotion()
            elif name == " ":
                self.paused = not self.paused
            else:
                raise InvalidInputError(f"unknown key {name!r}")
        return self.state()

    def frame(self) -> np.ndarray:
        """The next frame, drawn with the current user motion (the same moment while paused)."""
        with self._lock:
            if not self.paused:
                self._shown = next(self._frames)
            return self._render()

    def close(self) -> None:
        """Stops playing: the video's reader, and its decoding thread, end."""
        with self._lock:
            self._frames.close()

    def __enter__(self) -> "Viewer":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def state(self) -> dict:
        """The user motion and whether playback is paused, as a JSON-ready dict."""
        u = self.user
        return {"yaw": u.yaw, "pitch": u.pitch, "roll": u.roll, "zoom": round(u.zoom, 4), "exaggerate": round(u.gain, 4),
                "paused": self.paused}


PAGE = """<!doctype html><html lang="en"><head><meta charset="utf-8"><title>facemime view</title>
<style>body{background:#222;color:#ddd;font:14px system-ui,sans-serif;text-align:center}img{max-width:98vw}</style>
</head><body><img src="/stream" alt="facemime"><p>%s</p><p id="s"></p><script>
addEventListener('keydown', async ev => {
  const k = ev.key; if (!%s.includes(k)) return; ev.preventDefault();
  const r = await fetch('/key?k=' + encodeURIComponent(k)); document.getElementById('s').textContent = await r.text();
});</script></body></html>"""


def jpeg(frame: np.ndarray) -> bytes:
    """An RGB frame as JPEG bytes."""
    return cv2.imencode(".jpg", cv2.cvtColor(frame, cv2.COLOR_RGB2BGR), [cv2.IMWRITE_JPEG_QUALITY, 85])[1].tobytes()


def make_server(viewer: Viewer, port: int = 8765) -> ThreadingHTTPServer:
    """The web server of ``viewer`` on 127.0.0.1:``port`` (0: any free port); not yet serving."""
    keys = json.dumps(sorted(KEYS) + ["r", " "])

    class Handler(BaseHTTPRequestHandler):
        def log_message(self, *args: object) -> None:  # quiet: progress goes nowhere
            pass

        def _send(self, body: bytes, kind: str, status: HTTPStatus = HTTPStatus.OK) -> None:
            self.send_response(status)
            self.send_header("Content-Type", kind)
            self.send_header("Content-Length", str(len(body)))
            self.send_header("Cache-Control", "no-store")
            self.end_headers()
            self.wfile.write(body)

        def do_GET(self) -> None:  # noqa: N802 (http.server's name)
            url = urlparse(self.path)
            if url.path == "/":
                self._send((PAGE % (HELP, keys)).encode(), "text/html; charset=utf-8")
            elif url.path == "/frame.jpg":
                self._send(jpeg(viewer.frame()), "image/jpeg")
            elif url.path == "/key":
                try:
                    state = viewer.key(parse_qs(url.query).get("k", [""])[0])
                except InvalidInputError as e:
                    self._send(str(e).encode(), "text/plain; charset=utf-8", HTTPStatus.BAD_REQUEST)
                    return
                self._send(json.dumps(state).encode(), "application/json")
            elif url.path == "/stream":
                self.send_response(HTTPStatus.OK)
                self.send_header("Content-Type", "multipart/x-mixed-replace; boundary=frame")
                self.end_headers()
                try:
                    while True:
                        t0 = time.perf_counter()
                        body = jpeg(viewer.frame())
                        self.wfile.write(b"--frame\r\nContent-Type: image/jpeg\r\nContent-Length: %d\r\n\r\n" % len(body) + body + b"\r\n")
                        time.sleep(max(0.0, 1.0 / viewer.fps - (time.perf_counter() - t0)))
                except (BrokenPipeError, ConnectionResetError):
                    return
            else:
                self._send(b"not found", "text/plain", HTTPStatus.NOT_FOUND)

    try:
        return ThreadingHTTPServer(("127.0.0.1", port), Handler)
    except OSError as e:
        raise InvalidInputError(f"cannot listen on port {port}: {e.strerror or e}; pick another with --port") from None
