"""The face models shipped with facemime (``facemime/networks/models``, see its README for their
origin, licence and checksums), loaded by OpenCV's ``cv2.dnn`` once per thread: a network holds
its input and its layers' buffers, so two threads running one network at once corrupt each
other's pass (OpenCV 5.1 stops with an assertion about a buffer's shape)."""

from __future__ import annotations

import threading
from importlib import resources
from typing import Any

import cv2

from facemime.errors import FacemimeError

#: The shipped model files.
MODELS = ("face_detection_short_range.tflite", "face_landmark.tflite", "iris_landmark.tflite")
_loaded = threading.local()


def load_network(name: str) -> cv2.dnn.Net:
    """A shipped TFLite model as an OpenCV network of this thread's own (loaded on the
    thread's first call).

    Parameters
    ----------
    name
        The model file, one of :data:`MODELS`; another, or one that cannot be loaded, raises
        :class:`FacemimeError`.

    Returns
    -------
    cv2.dnn.Net
        The network, the same one on each call from this thread.
    """
    nets: dict[str, cv2.dnn.Net] = _loaded.__dict__.setdefault("nets", {})
    if name not in nets:
        nets[name] = _read(name)
    return nets[name]


def _read(name: str) -> cv2.dnn.Net:
    """Load the shipped model ``name``; a :class:`FacemimeError` in one line where it cannot be."""
    if name not in MODELS:
        raise FacemimeError(f"unknown face model {name!r}; shipped: {', '.join(MODELS)}")
    with resources.as_file(resources.files("facemime.networks") / "models" / name) as path:
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
