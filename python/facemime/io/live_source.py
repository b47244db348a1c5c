"""Live sources of frames, read at their own pace: a video file played at its frame rate, or a
camera as its frames come (``facemime call`` and ``facemime live``). Frames are (H, W, 3) uint8
RGB; each comes with its arrival time, ms since the epoch.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Generator
from pathlib import Path

import numpy as np

from facemime.errors import InputFileError
from facemime.io.video import VideoReader

#: Frame rate assumed for a camera that does not tell its own, frames/s.
CAMERA_FPS = 30.0
#: The largest camera number (OpenCV's device index) tried.
MAX_CAMERA = 9999


class FileSource:
    """A video file played at its own frame rate: the first frame at once; the pace starts when
    the next is asked for (the first, the actor's fit, done), frame i ≥ 1 being due
    ``(i - 1) / fps`` seconds after that.

    Parameters
    ----------
    path
        Path of the video file.
    loop
        Play it again and again (the indices keep counting).
    paced
        False: each frame as soon as it is asked for, arriving when read (a benchmark's source).
    """

    def __init__(self, path: str | Path, loop: bool = False, paced: bool = True):
        self.path, self.loop, self.paced = Path(path), loop, paced
        self._reader = VideoReader(self.path)
        self.name, self.fps = self.path.name, self._reader.fps
        self.size = (self._reader.width, self._reader.height)

    def frames(self, stop: threading.Event) -> Generator[tuple[np.ndarray, float]]:
        """Each frame when due, until ``stop`` is set.

        Parameters
        ----------
        stop
            Set to end the frames (a wait for a frame's time ends at once).

        Yields
        ------
        frame : (H, W, 3) uint8 array
            RGB.
        arrival : float
            When the frame was due, ms since the epoch (a frame read late, the reader being
            behind, arrived when due, as from a camera).
        """
        reader, i, base = self._reader, 0, None
        while True:
            with reader:
                for frame in reader:
                    late = 0.0
                    if base is not None and self.paced:
                        wait = base + i / self.fps - time.monotonic()
                        if wait > 0 and stop.wait(wait):
                            return
                        late = max(0.0, -wait)
                    if stop.is_set():
                        return
                    yield frame, (time.time() - late) * 1000
                    if base is None:  # the pace starts once the first frame (the actor's fit) is done
                        base = time.monotonic() - 1 / self.fps
                    i += 1
            if not self.loop:
                return
            reader = VideoReader(self.path)
            if (reader.width, reader.height) != self.size:
                reader.close()
                raise InputFileError(f"video {self.path} changed its frame size while playing")

    def close(self) -> None:
        self._reader.close()


class CameraSource:
    """A camera, its frames as they come. Its first frame is read here (a camera that gives none
    fails here).

    Parameters
    ----------
    index
        OpenCV's device index of the camera.
    """

    def __init__(self, index: int):
        import cv2

        self._cv2 = cv2
        level = cv2.utils.logging.getLogLevel()
        cv2.utils.logging.setLogLevel(cv2.utils.logging.LOG_LEVEL_SILENT)  # no lines of OpenCV's on a failure
        try:
            if not 0 <= index <= MAX_CAMERA:
                raise InputFileError(f"camera {index} cannot be opened (camera numbers are 0-{MAX_CAMERA})")
            self._cap = cv2.VideoCapture(index)
            ok, frame = self._cap.read() if self._cap.isOpened() else (False, None)
        finally:
            cv2.utils.logging.setLogLevel(level)
        if not ok or frame is None:
            self._cap.release()
            raise InputFileError(f"camera {index} cannot be opened (no such camera, or it is busy)")
        self._first, self._arrived = frame, time.time() * 1000
        self.name = f"camera {index}"
        fps = self._cap.get(cv2.CAP_PROP_FPS)
        self.fps = float(fps) if 1 <= fps <= 240 else CAMERA_FPS
        self.size = (frame.shape[1], frame.shape[0])

    def frames(self, stop: threading.Event) -> Generator[tuple[np.ndarray, float]]:
        """The camera's frames as they come, until ``stop`` is set.

        Parameters
        ----------
        stop
            Set to end the frames (checked between frames).

        Yields
        ------
        frame : (H, W, 3) uint8 array
            RGB.
        arrival : float
            When it was read, ms since the epoch.
        """
        frame, arrived = self._first, self._arrived
        while frame is not None and not stop.is_set():
            yield self._cv2.cvtColor(frame, self._cv2.COLOR_BGR2RGB), arrived
            ok, frame = self._cap.read()
            arrived = time.time() * 1000
            if not ok:
                raise InputFileError(f"{self.name} stopped giving frames")

    def close(self) -> None:
        self._cap.release()


def open_source(source: str, loop: bool = False) -> FileSource | CameraSource:
    """A video file, or a camera.

    Parameters
    ----------
    source
        Path of a video file, or a camera's index: a whole number naming no file.
    loop
        Play a file again and again.

    Returns
    -------
    FileSource or CameraSource
        The source, open.
    """
    if source.isascii() and source.isdigit() and not Path(source).exists():
        return CameraSource(int(source))
    return FileSource(source, loop)
