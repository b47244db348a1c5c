import numpy as np
import pytest

from facemime.errors import InputFileError, ModelFormatError
from facemime.io.wfm import load_wfm


def test_candide3_loads_completely(candide_path):
    m = load_wfm(candide_path)
    assert (len(m.vertices), len(m.triangles), len(m.units), len(m.shape_units)) == (113, 184, 14, 38)
    assert m.uv.shape == (113, 2) and (m.uv >= 0).all() and (m.uv <= 1).all()
    assert "Jaw drop" in m.units and "Head height" in m.shape_units


def test_candide3_is_converted_to_facemime_axes(candide_path):
    m = load_wfm(candide_path)
    v, t = m.vertices, m.triangles
    # Texture u grows with model x: x points to the image's right (the subject's left).
    textured = m.uv.any(axis=1)  # a few CANDIDE vertices have no texture coordinates (0, 0)
    assert np.corrcoef(v[textured, 0], m.uv[textured, 0])[0, 1] > 0.95
    normals = np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]])
    assert (normals[:, 2] > 0).mean() > 0.9, "triangles face outwards (towards +z)"
    jaw = m.units["Jaw drop"]
    assert jaw[:, 1].min() < 0 and jaw[:, 1].max() <= 0  # the jaw goes down
    # The x-push unit moves the jaw towards the subject's right after mirroring.
    assert m.units["Jaw x-push"][:, 0].min() < 0


def test_deforming_candide_with_units_and_shape(candide_path):
    m = load_wfm(candide_path)
    moved = m.deform({"Jaw drop": 1.0}, shape={"Head height": 0.5})
    assert moved.shape == (113, 3) and not np.allclose(moved, m.vertices)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("hello", "no '# VERTEX LIST:' section"),
        ("# VERTEX LIST:\n3\n0 0 0\n1 0 0\n# FACE LIST:\n0\n", "VERTEX LIST, line 4: section ends early"),
        ("# VERTEX LIST:\n3\n0 0 0\n1 0 0\n0 1 0\n# FACE LIST:\n1\n0 1 7\n", "uses vertex 7, but there are 3 vertices"),
        ("# VERTEX LIST:\n3\n0 0 0\n1 0 x\n0 1 0\n# FACE LIST:\n1\n0 1 2\n", "line 4: expected 3 numbers, got '1 0 x'"),
        ("# VERTEX LIST:\n3\n0 0 0\n1 0 0\n2 0 0\n# FACE LIST:\n1\n0 1 2\n", "degenerate"),
        (
            "# VERTEX LIST:\n3\n0 0 0\n1 0 0\n0 1 0\n# FACE LIST:\n1\n0 1 2\n"
            "# ANIMATION UNITS LIST:\n1\n# up\n1\n9 0 1 0\n",
            "unit 'up' names vertex 9",
        ),
    ],
)
def test_malformed_wfm_is_refused_with_file_and_line(tmp_path, text, message):
    path = tmp_path / "bad.wfm"
    path.write_text(text)
    with pytest.raises(ModelFormatError, match=message):
        load_wfm(path)


def test_truncated_candide_is_refused(tmp_path, candide_path):
    path = tmp_path / "cut.wfm"
    lines = candide_path.read_text().splitlines()
    path.write_text("\n".join(lines[:200]))  # ends inside the face list
    with pytest.raises(ModelFormatError, match="FACE LIST, line 200: section ends early"):
        load_wfm(path)
    path.write_text(candide_path.read_text()[:3000])  # ends inside a line
    with pytest.raises(ModelFormatError, match="expected 3 integers, got '20 27'"):
        load_wfm(path)
    with pytest.raises(InputFileError):
        load_wfm(tmp_path / "none.wfm")
