"""The generic head shipped with facemime: about 120 vertices in millimetres, its origin between
the outer eye corners, which are 90 mm apart (``data/generic_head.json``, made by
``tools/build_generic_head.py``)."""

from __future__ import annotations

from importlib import resources

from facemime.io.head_file import parse_head
from facemime.types.head import HeadModel


def generic_head() -> HeadModel:
    """The generic head shipped with facemime (about 120 vertices, millimetres).

    Returns
    -------
    HeadModel
        Read afresh from ``data/generic_head.json``: model units millimetres, origin between the
        outer eye corners (90 mm apart), with texture coordinates, vertex groups and deformation
        units.
    """
    text = resources.files("facemime.head").joinpath("data/generic_head.json").read_text(encoding="utf-8")
    return parse_head(text, "generic_head.json")
