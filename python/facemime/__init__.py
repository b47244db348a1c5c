"""facemime: track mouth and eyebrow motion with dynamic contours and re-synthesise it on a
textured 3D head model, in real time on a CPU (after Nesi & Magnolfi, 1996).

Conventions used across the package:

- Images are numpy ``uint8`` arrays, (H, W, 3) RGB or (H, W) gray.
- Image points are float arrays of shape (N, 2) holding (x, y) pixels: x to the right, y down,
  (0, 0) at the *centre* of the top-left pixel.
- Model space is right-handed: x to the subject's left (the image's right in a frontal view),
  y up, z out of the face towards the camera; the unit is the millimetre.
- Left/right of the face are the subject's own.
"""

from __future__ import annotations

import importlib
from typing import Any

from facemime._core import __version__
from facemime.errors import FacemimeError, InputFileError, InvalidInputError, ModelFormatError, NoFaceError

#: The public API: name -> the module that defines it, imported on first use (``import facemime``
#: stays light: the command line and the errors need none of these modules). Where each lives, and
#: its documentation, is that module's; these names stay when modules move.
_API = {
    # one function per command, files in and out (as the command line runs them)
    "fit_file": "facemime.app.fit",
    "track_video": "facemime.app.track",
    "run_video": "facemime.app.run",
    "encode_video": "facemime.app.coding",
    "decode_stream": "facemime.app.coding",
    "export_track": "facemime.app.export",
    "run_batch": "facemime.app.batch",
    "Live": "facemime.app.live",
    "run_demo": "facemime.app.demo",
    # frame by frame, in memory
    "read_photo": "facemime.io.photo",
    "VideoReader": "facemime.io.video",
    "VideoWriter": "facemime.io.video",
    "fit_actor": "facemime.fit.actor",
    "Actor": "facemime.types.actor",
    "load_actor": "facemime.io.actor_file",
    "save_actor": "facemime.io.actor_file",
    "FaceTracker": "facemime.track.redetect",
    "Analysis": "facemime.animate.analysis",
    "start_analysis": "facemime.animate.analysis",
    "analysed": "facemime.animate.analysis",
    "Puppet": "facemime.animate.synth",
    "UserMotion": "facemime.animate.synth",
    "ArkitSolver": "facemime.animate.arkit",
    "Pose": "facemime.types.pose",
    "Look": "facemime.types.look",
    "MotionEncoder": "facemime.codec.stream",
    "MotionDecoder": "facemime.codec.decoder",
}

__all__ = [
    "FacemimeError", "InputFileError", "InvalidInputError", "ModelFormatError", "NoFaceError", "__version__", *_API,
]  # fmt: skip


def __getattr__(name: str) -> Any:
    if name not in _API:
        raise AttributeError(f"module 'facemime' has no attribute {name!r}")
    value = getattr(importlib.import_module(_API[name]), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_API))
