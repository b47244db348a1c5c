"""Type stubs of the private native module ``facemime._core`` (checked by tests/test_core_stubs.py)."""

import numpy as np
import numpy.typing as npt

__version__: str
MAX_IMAGE_SIDE: int
MAX_IMAGE_PIXELS: int

def render_mesh_into(
    out: npt.NDArray[np.uint8],
    texture: npt.NDArray[np.uint8],
    tex_points: npt.NDArray[np.float64],
    points: npt.NDArray[np.float64],
    depth: npt.NDArray[np.float64],
    triangles: npt.NDArray[np.uint32],
    filter: str,
    depth_mode: str,
    cull_back_faces: bool,
) -> tuple[int, int, int, int]: ...
def coverage(
    points: npt.NDArray[np.float64],
    triangles: npt.NDArray[np.uint32],
    width: int,
    height: int,
) -> npt.NDArray[np.uint32]: ...
