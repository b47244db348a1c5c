"""facemime.init/1 and facemime.track/1 files: round trip and one-line errors."""

import json

import numpy as np
import pytest

from facemime.errors import InputFileError
from facemime.io.contours_json import ContourFileError, init_document, read_init, read_track, track_document, write_json
from facemime.track.synthetic import band_face


def test_track_json_round_trips(tmp_path):
    _, contours = band_face(shift=(0.123456, -7.5))
    frames = [{"index": i, "contours": contours, "confidence": {"mouth_outer": 0.5}, "lost": ["brow_left"] if i else []}
              for i in range(3)]
    path = write_json(tmp_path / "t.json", track_document({"width": 256, "height": 256, "fps": 25.0, "frames": 3}, frames))
    video, back = read_track(path)
    assert video == {"width": 256, "height": 256, "fps": 25.0, "frames": 3}
    assert sorted(back) == [0, 1, 2]
    for name, pts in contours.items():
        np.testing.assert_allclose(back[2][name], pts, atol=5e-4)
    doc = json.loads(path.read_text())
    assert doc["frames"][1]["lost"] == ["brow_left"] and doc["frames"][1]["confidence"] == {"mouth_outer": 0.5}


def test_init_json_round_trips(tmp_path):
    _, contours = band_face()
    path = write_json(tmp_path / "i.json", init_document(4, contours))
    frame, back = read_init(path, size=(256, 256))
    assert frame == 4 and set(back) == set(contours)
    np.testing.assert_allclose(back["brow_left_upper"], contours["brow_left_upper"], atol=5e-4)


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("{", "not valid JSON: Expecting property name"),
        ('{"format": "facemime.track/1"}', "expected format 'facemime.init/1'"),
        ('{"format": "facemime.init/1", "frame": -1, "contours": {}}', "'frame' must be a non-negative integer"),
        ('{"format": "facemime.init/1", "contours": []}', "'contours' must be an object"),
        ("INCOMPLETE", "missing contour brow_right_lower"),
        ("OUTSIDE", "point (300, 5) is outside the 256x256 image"),
        ("SHORT", "must have at least 2 [x, y] points"),
    ],
)
def test_bad_init_files_give_one_line(tmp_path, text, message):
    _, contours = band_face()
    doc = init_document(0, contours)
    if text == "INCOMPLETE":
        del doc["contours"]["brow_right_lower"]
    elif text == "OUTSIDE":
        doc["contours"]["mouth_outer_lower"][3] = [300, 5]
    elif text == "SHORT":
        doc["contours"]["brow_left_upper"] = [[1, 2]]
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(doc) if text in ("INCOMPLETE", "OUTSIDE", "SHORT") else text)
    with pytest.raises(ContourFileError, match=None) as err:
        read_init(path, size=(256, 256))
    assert message in str(err.value) and "\n" not in str(err.value)


def test_missing_init_file(tmp_path):
    with pytest.raises(InputFileError, match="does not exist"):
        read_init(tmp_path / "nope.json")
