"""Images decoded from bytes in memory (an actor file's members, a stream's payloads), without
the image libraries' own messages: libpng writes its warnings and errors about a damaged file
straight to the process's standard error, beside facemime's one line about it."""

from __future__ import annotations

import os
from collections.abc import Iterator
from contextlib import contextmanager

import cv2
import numpy as np


@contextmanager
def _silent_stderr() -> Iterator[None]:
    """File descriptor 2 sent to the null device for the block (what C libraries write to)."""
    saved, null = os.dup(2), os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(null, 2)
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)
        os.close(null)


def decode_rgb(data: bytes) -> np.ndarray | None:
    """An encoded image (PNG, WebP, JPEG, BMP: what OpenCV reads) as RGB.

    Parameters
    ----------
    data
        The image file's bytes.

    Returns
    -------
    (H, W, 3) uint8 array or None
        RGB, C-contiguous (grey and alpha images converted); None when the bytes do not decode.
    """
    if not data:
        return None
    with _silent_stderr():
        image = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR)
    if image is None or image.ndim != 3 or image.shape[2] != 3:
        return None
    return np.ascontiguousarray(cv2.cvtColor(image, cv2.COLOR_BGR2RGB))
