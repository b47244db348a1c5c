"""The 3D wire-frame head: the generic model shipped with facemime, its vertex groups and
deformation units, and a loader for CANDIDE ``.wfm`` files."""

from facemime.model.head import REQUIRED_GROUPS, HeadModel, generic_head, load_head
from facemime.model.texture import painted_texture
from facemime.model.wfm import load_wfm
from facemime.shared_constants import CONTOUR_GROUPS

__all__ = ["CONTOUR_GROUPS", "REQUIRED_GROUPS", "HeadModel", "generic_head", "load_head", "load_wfm", "painted_texture"]
