"""``facemime view``: the interactive viewer's state and frames (served to a web browser by
:mod:`facemime.app.view_server`).

A video is analysed live as it plays (original with contours | synthesised picture: the face in
its actor's scene, or alone with ``mask_only``); a track file written by ``facemime run`` replays
its recorded motion (on an actor with a scene, relative to the track's first pose). Keys in the browser add
motion, as the paper's keyboard did: arrows turn and tilt the head, ``q``/``e`` roll it, ``+``/``-`` zoom,
``x``/``z`` exaggerate or calm the mouth and brow motion, ``r`` resets, space pauses.
"""

from __future__ import annotations

import threading
from collections.abc import Generator, Iterable, Iterator
from pathlib import Path

import numpy as np

from facemime.animate.analysis import analysed
from facemime.animate.replay import FPS_RANGE, load_replay
from facemime.animate.synth import Puppet, UserMotion
from facemime.errors import InputFileError, InvalidInputError
from facemime.io.video import VideoReader
from facemime.render.raster import fill
from facemime.shared_constants import BACKGROUND
from facemime.track.overlay import draw_contours
from facemime.types.actor import Actor
from facemime.types.head import model_iod
from facemime.types.look import Look
from facemime.types.pose import Pose

#: Key -> the change it makes to the user motion.
KEYS = {
    "ArrowLeft": {"yaw": -5.0},
    "ArrowRight": {"yaw": 5.0},
    "ArrowUp": {"pitch": -5.0},
    "ArrowDown": {"pitch": 5.0},
    "q": {"roll": 5.0},
    "e": {"roll": -5.0},
    "+": {"zoom": 1.1},
    "=": {"zoom": 1.1},
    "-": {"zoom": 1 / 1.1},
    "x": {"gain": 1.25},
    "z": {"gain": 0.8},
}
HELP = "arrows: turn and tilt · q/e: roll · +/-: zoom · x/z: more/less motion · r: reset · space: pause"


class Viewer:
    """The viewer's state and frames, without the web server: feed keys with :meth:`key`, take
    frames (RGB uint8) with :meth:`frame`. The source plays in a loop; opening it analyses the
    first frame. A video is decoded on a thread of its reader's while the viewer plays it:
    :meth:`close` (or leaving a ``with`` block) stops it.

    Parameters
    ----------
    source
        A video file (analysed live, played at its frame rate clamped to 0.1-1000 frames/s) or a
        ``facemime.track/1`` file with motion (its name ending in ``.json``; from
        ``facemime run``).
    actor
        The face to drive; None: for a video, the face fitted on its first frame; for a track
        file, the generic painted head.
    mask_only
        Show the face alone on a plain backdrop, not in its actor's scene.
    """

    def __init__(self, source: str | Path, actor: Actor | None = None, mask_only: bool = False):
        self.source = Path(source)
        self._mask_only = mask_only
        if not self.source.exists():
            raise InputFileError(f"{self.source} does not exist")
        self.user = UserMotion()
        self.paused = False
        self._lock = threading.Lock()
        self._actor = actor
        self._is_track = self.source.suffix.lower() == ".json"
        if self._is_track:
            replay = load_replay(self.source, actor)
            self.size, self.fps, self._motions = replay.size, replay.fps, replay.motion
            self._puppet = replay.puppet(mask_only)
        else:
            with VideoReader(self.source) as r:
                self.size, self.fps = (r.width, r.height), min(max(r.fps, FPS_RANGE[0]), FPS_RANGE[1])
        self._frames = self._play()
        self._shown = next(self._frames)

    def _one_size(self, frames: Iterable[np.ndarray]) -> Iterator[np.ndarray]:
        """``frames``, refused in one line from the first whose size is not the video's."""
        for n, frame in enumerate(frames):
            if frame.shape[:2] != self.size[::-1]:
                raise InputFileError(
                    f"video {self.source} changes its frame size from {self.size[0]}x"
                    f"{self.size[1]} to {frame.shape[1]}x{frame.shape[0]} at frame {n}; "
                    "the viewer plays one frame size"
                )
            yield frame

    def _play(self) -> Generator[tuple[np.ndarray | None, Pose, np.ndarray, Look, Puppet], None, None]:
        """(left panel or None, pose, knot offsets, look, puppet) per frame, looping forever."""
        while True:
            if self._is_track:
                for m in self._motions:
                    yield None, m.pose, m.offsets, m.look, self._puppet
                continue
            analysis = None
            with VideoReader(self.source) as reader:
                for n, (frame, analysis, m) in enumerate(
                    analysed(self._one_size(reader), str(self.source), fps=self.fps)
                ):
                    if n == 0:
                        puppet = Puppet(
                            self._actor or analysis.actor,
                            analysis.deformer.feature_sizes(),
                            model_iod(analysis.actor.model),
                            analysis.actor.pose,
                            self._mask_only,
                        )
                    yield (
                        (draw_contours(frame, m.contours, m.lost) if m.face else frame),
                        m.pose,
                        m.offsets,
                        m.look,
                        puppet,
                    )
            if analysis is None:
                raise InputFileError(f"video {self.source} has no frames")

    def _render(self) -> np.ndarray:
        left, pose, offsets, look, puppet = self._shown
        synth = np.empty((self.size[1], self.size[0], 3), np.uint8)
        if puppet.scene is None:
            fill(synth, BACKGROUND)
        puppet.render(pose, offsets, self.size, self.user, out=synth, look=look)
        return synth if left is None else np.hstack([left, synth])

    def key(self, name: str) -> dict:
        """Apply a key; an unknown one raises :class:`~facemime.errors.InvalidInputError`.

        Parameters
        ----------
        name
            The key, as the browser names it: one of :data:`KEYS` (arrows turn and tilt by 5
            degrees, ``q``/``e`` roll by 5 degrees, ``+`` or ``=`` and ``-`` zoom in and out by a
            factor 1.1, ``x``/``z`` exaggerate by 1.25 or calm by 0.8), ``r`` (reset the user
            motion) or a space (pause or resume).

        Returns
        -------
        dict
            The new :meth:`state`.
        """
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
        """The next frame, drawn with the current user motion (the same moment while paused).

        Returns
        -------
        (H, 2W, 3) or (H, W, 3) uint8 array
            RGB: for a video, the original with the tracked contours beside the synthesised
            picture; for a track file, the synthesised picture alone, at the track's size.
        """
        with self._lock:
            if not self.paused:
                self._shown = next(self._frames)
            return self._render()

    def close(self) -> None:
        """Stops playing: the video's reader, and its decoding thread, end."""
        with self._lock:
            self._frames.close()

    def __enter__(self) -> Viewer:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    def state(self) -> dict:
        """The user motion and whether playback is paused.

        Returns
        -------
        dict
            JSON-ready: ``yaw``, ``pitch``, ``roll`` (degrees added), ``zoom`` (factor on the
            face's size), ``exaggerate`` (factor on the local deformation; both 4 decimals) and
            ``paused`` (bool).
        """
        u = self.user
        return {
            "yaw": u.yaw,
            "pitch": u.pitch,
            "roll": u.roll,
            "zoom": round(u.zoom, 4),
            "exaggerate": round(u.gain, 4),
            "paused": self.paused,
        }
