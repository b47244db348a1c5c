"""Video output that browsers play: H.264 in MP4 (``.mp4``) or VP9 in WebM (``.webm``),
4:2:0 chroma, encoded by FFmpeg through PyAV. Frames are RGB uint8 (H, W, 3)."""

from __future__ import annotations

import os
from fractions import Fraction
from pathlib import Path
from types import TracebackType

import av
import numpy as np

from facemime.errors import InvalidInputError
from facemime.io.outputs import temporary_sibling

CODECS = {".mp4": ("libx264", {"crf": "20", "preset": "veryfast", "movflags": "+faststart"}),
          ".webm": ("libvpx-vp9", {"crf": "32", "b": "0", "deadline": "realtime", "cpu-used": "8"})}


class VideoWriter:
    """Write frames to a browser-playable video; the file appears under its name only when the
    writer closes without an error (a failed run leaves nothing behind).

    Frame sizes must be even (4:2:0); odd sizes are padded by one pixel of the edge colour.

    >>> import tempfile, pathlib
    >>> out = pathlib.Path(tempfile.mkdtemp()) / "clip.mp4"
    >>> with VideoWriter(out, fps=25) as w:
    ...     for i in range(5):
    ...         w.write(np.full((32, 48, 3), 40 * i, np.uint8))
    >>> out.stat().st_size > 0
    True
    """

    def __init__(self, path: str | Path, fps: float):
        self.path = Path(path)
        if self.path.suffix.lower() not in CODECS:
            raise InvalidInputError(f"video output must end in .mp4 or .webm, got {self.path.name!r}")
        if not (0 < fps <= 240):
            raise InvalidInputError(f"fps must be in (0, 240], got {fps}")
        self.fps = Fraction(fps).limit_denominator(1001)
        self._tmp: Path | None = None
        self._container = None
        self._stream = None
        self.frames = 0

    def __enter__(self) -> "VideoWriter":
        self._tmp = temporary_sibling(self.path)
        return self

    def write(self, frame: np.ndarray) -> None:
        """Append one (H, W, 3) uint8 RGB frame; every frame must have the first one's size."""
        if not (isinstance(frame, np.ndarray) and frame.dtype == np.uint8 and frame.ndim == 3 and frame.shape[2] == 3):
            raise InvalidInputError(f"video frames must be (H, W, 3) uint8 RGB, got {getattr(frame, 'shape', frame)}")
        h, w = frame.shape[:2]
        if h % 2 or w % 2:
            frame = np.pad(frame, ((0, h % 2), (0, w % 2), (0, 0)), mode="edge")
        if self._stream is None:
            codec, options = CODECS[self.path.suffix.lower()]
            fmt = "mp4" if self.path.suffix.lower() == ".mp4" else "webm"
            self._container = av.open(str(self._tmp), "w", format=fmt,
                                      options={"movflags": options["movflags"]} if "movflags" in options else {})
            self._stream = self._container.add_stream(codec, rate=self.fps)
            self._stream.width, self._stream.height = frame.shape[1], frame.shape[0]
            self._stream.pix_fmt = "yuv420p"
            self._stream.options = {k: v for k, v in options.items() if k != "movflags"}
        elif (frame.shape[1], frame.shape[0]) != (self._stream.width, self._stream.height):
            raise InvalidInputError(f"video frame size changed from {self._stream.width}x{self._stream.height} to {w}x{h}")
        for packet in self._stream.encode(av.VideoFrame.from_ndarray(np.ascontiguousarray(frame), format="rgb24")):
            self._container.mux(packet)
        self.frames += 1

    def __exit__(self, exc_type: type | None, exc: BaseException | None, tb: TracebackType | None) -> None:
        try:
            if self._container is not None:
                if exc_type is None:
                    for packet in self._stream.encode():
                        self._container.mux(packet)
                self._container.close()
            if exc_type is None:
                if self.frames == 0:
                    raise InvalidInputError(f"no frames were written to {self.path}")
                os.replace(self._tmp, self.path)
        finally:
            if self._tmp is not None:
                self._tmp.unlink(missing_ok=True)
