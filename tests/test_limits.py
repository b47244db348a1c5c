"""The input policy for models: vertex, triangle and file-size limits, lowered here through the
environment variables so that the files stay small."""

import json

import numpy as np
import pytest

from cli.test_cli import run
from facemime.errors import InvalidInputError, ModelFormatError
from facemime.head import generic_head
from facemime.io.head_file import head_document, head_from_document, load_head
from facemime.io.wfm import load_wfm


def grid_wfm(path, side):
    """A valid CANDIDE-format grid of ``side`` x ``side`` vertices and 2 (side - 1)^2 triangles."""
    x, y = np.meshgrid(np.linspace(-1, 1, side), np.linspace(-1, 1, side))
    idx = np.arange(side * side).reshape(side, side)
    a, b, c, d = idx[:-1, :-1].ravel(), idx[:-1, 1:].ravel(), idx[1:, :-1].ravel(), idx[1:, 1:].ravel()
    faces = np.concatenate([np.stack([a, d, b], 1), np.stack([a, c, d], 1)])  # CANDIDE's order (x mirrored)
    vertices = [f"{u:.4f} {v:.4f} {0.1 * u * v:.4f}" for u, v in zip(x.ravel(), y.ravel())]
    lines = ["# VERTEX LIST:", str(side * side)] + vertices
    lines += ["# FACE LIST:", str(len(faces))] + [" ".join(map(str, f)) for f in faces] + ["# END OF FILE:", ""]
    path.write_text("\n".join(lines))
    return path


def test_wfm_just_over_the_vertex_limit_is_refused(tmp_path, monkeypatch):
    path = grid_wfm(tmp_path / "grid.wfm", 4)  # 16 vertices, 18 triangles
    monkeypatch.setenv("FACEMIME_MAX_VERTICES", "16")
    assert len(load_wfm(path).vertices) == 16
    monkeypatch.setenv("FACEMIME_MAX_VERTICES", "15")
    message = "grid.wfm: VERTEX LIST, line 2: the model has 16 vertices, more than the limit of 15; "
    with pytest.raises(ModelFormatError, match=message + "set FACEMIME_MAX_VERTICES to allow more$"):
        load_wfm(path)


def test_wfm_count_is_checked_before_the_lines_are_parsed(tmp_path, monkeypatch):
    monkeypatch.setenv("FACEMIME_MAX_VERTICES", "1000")
    path = tmp_path / "huge.wfm"
    path.write_text("# VERTEX LIST:\n5000000\nnot a vertex\n")  # the 5 million lines never come
    with pytest.raises(ModelFormatError, match="5000000 vertices, more than the limit of 1000"):
        load_wfm(path)


def test_wfm_just_over_the_triangle_limit_is_refused(tmp_path, monkeypatch):
    path = grid_wfm(tmp_path / "grid.wfm", 4)
    monkeypatch.setenv("FACEMIME_MAX_TRIANGLES", "17")
    with pytest.raises(
        ModelFormatError,
        match="FACE LIST, line 20: the model has 18 triangles, more than the limit of 17; set FACEMIME_MAX_TRIANGLES",
    ):
        load_wfm(path)


def test_model_files_over_the_byte_limit_are_refused_unread(tmp_path, monkeypatch):
    wfm = grid_wfm(tmp_path / "grid.wfm", 4)
    head = tmp_path / "head.json"
    head.write_text(json.dumps(head_document(generic_head())))
    for path, load in ((wfm, load_wfm), (head, load_head)):
        size = path.stat().st_size
        monkeypatch.setenv("FACEMIME_MAX_MODEL_BYTES", str(size))
        load(path)
        monkeypatch.setenv("FACEMIME_MAX_MODEL_BYTES", str(size - 1))
        with pytest.raises(
            ModelFormatError,
            match=f"has {size} bytes, more than the limit of {size - 1} bytes; set FACEMIME_MAX_MODEL_BYTES",
        ):
            load(path)


@pytest.mark.parametrize(
    ("variable", "what", "count"),
    [("FACEMIME_MAX_VERTICES", "vertices", 120), ("FACEMIME_MAX_TRIANGLES", "triangles", None)],
)
def test_head_documents_over_a_limit_are_refused(tmp_path, monkeypatch, variable, what, count):
    doc = head_document(generic_head())
    count = count or len(doc["triangles"])
    assert len(doc[what]) == count
    monkeypatch.setenv(variable, str(count - 1))
    path = tmp_path / "head.json"
    path.write_text(json.dumps(doc))
    message = f"the model has {count} {what}, more than the limit of {count - 1}; set {variable} to allow more"
    with pytest.raises(ModelFormatError, match=message):
        load_head(path)
    with pytest.raises(ModelFormatError, match=f"^x.actor: model: {message}"):  # the model inside an actor file
        head_from_document(doc, "x.actor: model")


@pytest.mark.parametrize("value", ["0", "-5", "lots", ""])
def test_a_bad_limit_setting_is_named(tmp_path, monkeypatch, value):
    monkeypatch.setenv("FACEMIME_MAX_TRIANGLES", value)
    with pytest.raises(InvalidInputError, match=f"FACEMIME_MAX_TRIANGLES must be a positive integer, got {value!r}"):
        load_wfm(grid_wfm(tmp_path / "grid.wfm", 3))


def test_default_limits_accept_the_real_models(candide_path):
    assert len(load_wfm(candide_path).vertices) == 113
    assert len(generic_head().vertices) == 120


def test_model_preview_refuses_a_model_over_the_limit_in_one_line(tmp_path, capsys, monkeypatch):
    big = grid_wfm(tmp_path / "BIG.wfm", 5)
    monkeypatch.setenv("FACEMIME_MAX_VERTICES", "24")
    code, out, err = run(capsys, "model-preview", str(big), "--out", str(tmp_path / "x.png"))
    assert code == 1 and out == "" and err.count("\n") == 1
    assert err.startswith(f"facemime: error: {big}: VERTEX LIST, line 2: the model has 25 vertices")
    assert "FACEMIME_MAX_VERTICES" in err and "Traceback" not in err
    assert not (tmp_path / "x.png").exists()


def test_table_parsing_keeps_the_line_by_line_checks(tmp_path):
    path = tmp_path / "four.wfm"
    path.write_text("# VERTEX LIST:\n3\n0 0 0 1\n1 0 0 1\n0 1 0 1\n# FACE LIST:\n1\n0 1 2\n")  # 4 columns throughout
    with pytest.raises(ModelFormatError, match="VERTEX LIST, line 3: expected 3 numbers, got '0 0 0 1'"):
        load_wfm(path)
    path.write_text("# VERTEX LIST:\n3\n0 0 0\n1 0 0\n0 1 0\n# FACE LIST:\n1\n0 1 2.0\n")
    with pytest.raises(ModelFormatError, match=r"FACE LIST, line 8: expected 3 integers, got '0 1 2.0'"):
        load_wfm(path)


def test_many_deformation_units_on_many_vertices_are_refused(tmp_path, monkeypatch):
    doc = head_document(generic_head())
    doc["deformation_units"] = {f"u{k}": {"description": "", "displacements": []} for k in range(50)}
    monkeypatch.setenv("FACEMIME_MAX_UNIT_VALUES", str(50 * len(doc["vertices"]) - 1))
    with pytest.raises(ModelFormatError, match=r"deformation unit values .* more than the limit"):
        head_from_document(doc, "many units")
    grid = (
        grid_wfm(tmp_path / "grid.wfm", 4)
        .read_text()
        .replace("# END OF FILE:", "# ANIMATION UNITS LIST:\n3\n# a\n0\n# b\n0\n# c\n0\n# END OF FILE:")
    )
    (tmp_path / "units.wfm").write_text(grid)
    monkeypatch.setenv("FACEMIME_MAX_UNIT_VALUES", "47")
    with pytest.raises(ModelFormatError, match="48 deformation unit values"):
        load_wfm(tmp_path / "units.wfm")


@pytest.mark.parametrize("index", [9.223372036854776e18, 10**30, 2**63])
def test_indices_too_large_for_an_integer_are_refused(index):
    doc = head_document(generic_head())
    doc["triangles"][5][0] = index
    with pytest.raises(ModelFormatError, match=r"as integers|uses vertex"):
        head_from_document(doc, "huge index")
