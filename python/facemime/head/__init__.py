"""The 3-D head: the generic head shipped with facemime and the painted texture it is shown with
before anyone is fitted to it (the head model's type is :class:`facemime.types.HeadModel`, its
files are read by :mod:`facemime.io.head_file` and :mod:`facemime.io.wfm`)."""

from facemime.head.generic import generic_head
from facemime.head.texture import painted_texture

__all__ = ["generic_head", "painted_texture"]
