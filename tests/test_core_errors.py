"""Every input the native module refuses, whether the core or the binding refuses it, is raised as
facemime's :class:`~facemime.errors.InvalidInputError` (so the command line reports it in one line
with status 1, never as a bug of facemime)."""

import numpy as np
import pytest

from facemime import _core
from facemime.errors import InvalidInputError


def render(**changes):
    args = {
        "out": np.zeros((8, 8, 3), np.uint8),
        "texture": np.zeros((4, 4, 3), np.uint8),
        "tex_points": np.zeros((3, 2)),
        "points": np.array([[1.0, 1.0], [6.0, 1.0], [1.0, 6.0]]),
        "depth": np.zeros(3),
        "triangles": np.array([[0, 1, 2]], np.uint32),
        "filter": "bilinear",
        "depth_mode": "painter",
        "cull_back_faces": False,
    } | changes
    return _core.render_mesh_into(*args.values())


def test_a_valid_call_draws():
    assert render()[0] == 1  # one triangle drawn


@pytest.mark.parametrize(
    ("changes", "message"),
    [
        ({"filter": "cubic"}, "filter must be 'nearest' or 'bilinear'"),  # refused by the binding
        ({"out": np.zeros((8, 8, 3), np.uint8)[:, ::2]}, "out must be a C-contiguous"),  # by the binding
        ({"triangles": np.array([[0, 1, 7]], np.uint32)}, "7"),  # a vertex that does not exist: by the core
    ],
)
def test_refused_inputs_are_invalid_input_errors(changes, message):
    with pytest.raises(InvalidInputError, match=message):
        render(**changes)
