"""One frontal photo from an image file or from a frame of a video."""

from __future__ import annotations

from pathlib import Path

import cv2
import numpy as np

from facemime.errors import InputFileError, InvalidInputError
from facemime.io.video import VideoReader
from facemime.limits import check_image_file

#: Still-image file types read with OpenCV; anything else is opened as a video.
IMAGE_TYPES = (".png", ".jpg", ".jpeg", ".bmp", ".tif", ".tiff", ".webp")
#: Smallest photo side accepted, pixels: a face needs room for its features.
MIN_SIDE = 64


def read_photo(path: str | Path, frame: int = 0) -> np.ndarray:
    """The photo in an image file, or in a frame of a video.

    Parameters
    ----------
    path
        An image file (a suffix of :data:`IMAGE_TYPES`) or any video FFmpeg reads.
    frame
        0-based index of the video frame to take; must be 0 for a still image.

    Returns
    -------
    (H, W, 3) uint8 array
        RGB, a video frame turned upright; each side at least :data:`MIN_SIDE` pixels.
    """
    path = Path(path)
    if not path.exists():
        raise InputFileError(f"{path} does not exist")
    if not path.is_file():
        raise InputFileError(f"{path} is not a file")
    if frame < 0:
        raise InvalidInputError(f"--frame must be >= 0, got {frame}")
    if path.suffix.lower() in IMAGE_TYPES:
        if frame != 0:
            raise InvalidInputError(f"{path} is a still image; --frame applies to videos only")
        check_image_file(path)
        bgr = cv2.imread(str(path), cv2.IMREAD_COLOR)
        if bgr is None:
            raise InputFileError(f"cannot read {path}: not an image, or a corrupt one")
        image = cv2.cvtColor(bgr, cv2.COLOR_BGR2RGB)
    else:
        with VideoReader(path) as reader:
            found = next((f for i, f in enumerate(reader) if i == frame), None)
            if found is None:
                raise InvalidInputError(f"{path} has no frame {frame} (it has {reader.frames or 'fewer'} frames)")
            image = found
    if min(image.shape[:2]) < MIN_SIDE:
        raise InvalidInputError(
            f"{path} is {image.shape[1]}x{image.shape[0]} pixels; at least {MIN_SIDE} a side is needed"
        )
    return np.ascontiguousarray(image)
