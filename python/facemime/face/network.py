"""The face models shipped with facemime (``facemime/face/models``, see its README for their
origin, licence and checksums), loaded once per process by OpenCV's ``cv2.dnn``."""

from __future__ import annotations

from functools import cache
from importlib import resources
from typing import Any

import cv2

from facemime.errors import FacemimeError

#: The shipped model files.
MODELS = ("face_detection_short_range.tflite", "face_landmark.tflite")


@cache
def load_network(name: str) -> cv2.dnn.Net:
    """The shipped TFLite model ``name`` (one of :data:`MODELS`) as an OpenCV network."""
    if name not in MODELS:
        raise FacemimeError(f"unknown face model {name!r}; shipped: {', '.join(MODELS)}")
    with resources.as_file(resources.files("facemime.face") / "models" / name) as path:
        if not path.is_file():
            raise FacemimeError(f"the face model {name} is missing from the installed package; reinstall facemime")
        try:
            if hasattr(cv2.dnn, "ENGINE_CLASSIC"):
                # OpenCV 5's new engine gives only one of each model's two outputs (5.0.0); called
                # through Any, as OpenCV 4's annotations lack the argument and OpenCV 5's have it
                dnn: Any = cv2.dnn
                return dnn.readNetFromTFLite(str(path), engine=cv2.dnn.ENGINE_CLASSIC)
            return cv2.dnn.readNetFromTFLite(str(path))
        except cv2.error as e:
            raise FacemimeError(
                f"the face model {name} cannot be loaded by OpenCV {cv2.__version__}: {str(e).strip().splitlines()[-1]}"
            ) from None
