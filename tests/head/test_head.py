import json
from collections import Counter

import numpy as np
import pytest

from facemime.errors import InputFileError, ModelFormatError
from facemime.head import generic_head
from facemime.io.head_file import HEAD_FORMAT, load_head
from facemime.shared_constants import CONTOUR_GROUPS
from facemime.types.head import REQUIRED_GROUPS

SNAKE_KNOTS = {
    "mouth_outer_upper": 11,
    "mouth_outer_lower": 11,
    "mouth_inner_upper": 11,
    "mouth_inner_lower": 11,
    "brow_left_upper": 5,
    "brow_left_lower": 5,
    "brow_right_upper": 5,
    "brow_right_lower": 5,
}


@pytest.fixture(scope="module")
def head():
    return generic_head()


def test_generic_head_size_and_unit(head):
    assert 100 <= len(head.vertices) <= 120
    assert head.unit == "mm"
    # Outer eye corners 90 mm apart, origin between them.
    right, left = head.vertices[head.groups["eye_right"][0]], head.vertices[head.groups["eye_left"][4]]
    assert np.linalg.norm(left - right) == pytest.approx(90, abs=0.5)
    assert np.allclose((left + right) / 2, 0, atol=0.5)


def test_winding_is_consistent_and_outward(head):
    t = head.triangles
    directed = Counter((int(a), int(b)) for tri in t for a, b in zip(tri, np.roll(tri, -1)))
    assert max(directed.values()) == 1, "an edge is used twice in the same direction: inconsistent winding"
    undirected = Counter(tuple(sorted(e)) for e in directed)
    assert max(undirected.values()) <= 2, "an edge is shared by more than two triangles"
    v = head.vertices
    normals = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])
    assert (normals[:, 2] > 0).all(), "every facet of a face mask looks towards the camera"


def test_contour_groups_match_the_snake_contours(head):
    assert set(REQUIRED_GROUPS) <= set(head.groups)
    for name in CONTOUR_GROUPS:
        g = head.groups[name]
        assert len(g) == SNAKE_KNOTS[name]
        assert (np.diff(head.vertices[g, 0]) > 0).all(), f"{name} must run image-left to image-right"
    for kind in ("outer", "inner"):
        up, lo = head.groups[f"mouth_{kind}_upper"], head.groups[f"mouth_{kind}_lower"]
        assert up[0] == lo[0] and up[-1] == lo[-1], "upper and lower lips share the corners"
    # Subject's left brow on the image's right (+x).
    assert (
        head.vertices[head.groups["brow_left_upper"], 0].min()
        > 0
        > head.vertices[head.groups["brow_right_upper"], 0].max()
    )


def test_deformation_units_move_the_right_way(head):
    g, v = head.groups, head.vertices
    lip = g["mouth_inner_lower"][5]
    assert head.deform({"jawOpen": 1})[lip, 1] < v[lip, 1] - 8
    brows = np.concatenate([g["brow_left_upper"], g["brow_right_upper"]])
    raised = head.deform({"browInnerUp": 1, "browOuterUpLeft": 1, "browOuterUpRight": 1})
    assert (raised[brows, 1] > v[brows, 1] + 5).all()
    assert (head.deform({"browDownRight": 1})[g["brow_right_lower"], 1] < v[g["brow_right_lower"], 1]).all()
    corner = g["mouth_outer_upper"][-1]  # image-right: the subject's left corner
    assert head.deform({"mouthStretchLeft": 1})[corner, 0] > v[corner, 0] + 4
    assert head.deform({"mouthSmileLeft": 1})[corner, 1] > v[corner, 1] + 3
    up = g["mouth_outer_upper"][5]
    assert head.deform({"mouthUpperUpLeft": 1, "mouthUpperUpRight": 1})[up, 1] > v[up, 1] + 2
    closed = head.deform({"eyeBlinkLeft": 1})
    ring = g["eye_left"]
    assert np.abs(closed[ring[1:4], 1] - closed[ring[7:4:-1], 1]).max() < 0.5
    from facemime.animate.expressions import NAMES

    assert tuple(head.units) == NAMES


def test_unknown_unit_is_named(head):
    with pytest.raises(ValueError, match="unknown deformation unit 'smile'"):
        head.deform({"smile": 1})


def model_doc():
    from importlib import resources

    return json.loads(resources.files("facemime.head").joinpath("data/generic_head.json").read_text())


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda d: d.update(format="other/1"), "expected format 'facemime.head/1'"),
        (lambda d: d.pop("vertices"), "missing field 'vertices'"),
        (lambda d: d["triangles"].append([0, 1, 999]), "uses vertex 999, but there are 120 vertices"),
        (lambda d: d["triangles"].append([0, 0, 1]), "is degenerate"),
        (lambda d: d["groups"].pop("brow_left_upper"), "missing vertex groups brow_left_upper"),
        (lambda d: d["vertices"][3].__setitem__(0, "x"), "malformed model"),
        (lambda d: d["deformation_units"]["jawOpen"]["displacements"].append([500, 0, 0, 0]), "names vertex 500"),
        # indices are integers, never rounded into another vertex
        (lambda d: d["triangles"][0].__setitem__(2, 2.5), "triangles must list vertex indices as integers"),
        (lambda d: d["triangles"][0].__setitem__(2, "2"), "triangles must list vertex indices as integers"),
        (lambda d: d["groups"]["nose"].__setitem__(0, 3.0), "group 'nose' must list vertex indices as integers"),
        # the lips are drawn and sealed pair by pair, corner to corner
        (
            lambda d: d["groups"]["mouth_inner_lower"].insert(1, d["groups"]["mouth_inner_upper"].pop(1)),
            "mouth_inner_upper and mouth_inner_lower must have the same number of vertices, got 10 and 12",
        ),
    ],
)
def test_bad_model_files_are_refused_with_a_message(tmp_path, edit, message):
    doc = model_doc()
    edit(doc)
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(doc))
    with pytest.raises(ModelFormatError, match=message):
        load_head(path)


def test_model_file_round_trips_and_bad_json_is_reported(tmp_path):
    path = tmp_path / "head.json"
    path.write_text(json.dumps(model_doc()))
    loaded = load_head(path)
    np.testing.assert_array_equal(loaded.vertices, generic_head().vertices)
    assert model_doc()["format"] == HEAD_FORMAT
    path.write_text("{not json")
    with pytest.raises(ModelFormatError, match="not valid JSON"):
        load_head(path)
    with pytest.raises(InputFileError, match="no such model file"):
        load_head(tmp_path / "missing.json")
