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

from facemime._core import __version__
from facemime.errors import FacemimeError, InputFileError, InvalidInputError, ModelFormatError

__all__ = ["FacemimeError", "InputFileError", "InvalidInputError", "ModelFormatError", "__version__"]
