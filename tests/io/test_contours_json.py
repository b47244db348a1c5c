"""facemime.init/1 and facemime.track/1 files: round trip and one-line errors."""

import json

import numpy as np
import pytest

from facemime.animate.look import Look
from facemime.errors import InputFileError
from facemime.io.contours_json import (
    ContourFileError,
    init_document,
    read_init,
    read_motion,
    read_track,
    track_document,
    write_json,
)
from facemime.track.synthetic import band_face


def test_track_json_round_trips(tmp_path):
    _, contours = band_face(shift=(0.123456, -7.5))
    frames = [
        {"index": i, "contours": contours, "confidence": {"mouth_outer": 0.5}, "lost": ["brow_left"] if i else []}
        for i in range(3)
    ]
    path = write_json(
        tmp_path / "t.json", track_document({"width": 256, "height": 256, "fps": 25.0, "frames": 3}, frames)
    )
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


def _motion_file(tmp_path, look):
    frame = {
        "index": 0,
        "pose": {"yaw": 0, "pitch": 0, "roll": 0, "scale": 2.0, "tx": 100, "ty": 90},
        "offsets": [[0.0, 0.0]] * 3,
    }
    if look is not None:
        frame["look"] = look
    doc = {
        "format": "facemime.track/1",
        "video": {},
        "frames": [frame],
        "model": {"unit": "mm", "knots": [1, 2, 3], "feature_sizes": [1, 1, 1], "iod": 90},
    }
    path = tmp_path / "m.json"
    path.write_text(json.dumps(doc))
    return path


def test_the_look_is_read_back_and_a_file_without_it_plays_neutral(tmp_path):
    look = Look([1.0, 0.25], [[0.1, -0.02], [0.08, 0.0]])
    assert read_motion(_motion_file(tmp_path, look.as_dict()))[2][0]["look"].as_dict() == look.as_dict()
    assert not read_motion(_motion_file(tmp_path, None))[2][0]["look"].vector().any()
    partial = read_motion(_motion_file(tmp_path, {"eye_left_closure": 0.5}))[2][0]["look"]
    assert partial.vector().tolist() == [0.0, 0.5, 0.0, 0.0, 0.0, 0.0]


@pytest.mark.parametrize(
    "look, message",
    [
        ({"eye_right_closure": "shut"}, "malformed 'look'"),
        ([0.5, 0.5], "malformed 'look'"),
        ({"iris_left_u": 1e9}, "beyond"),
        ({"iris_left_v": float("nan")}, "beyond"),
    ],
)
def test_a_bad_look_is_refused_in_one_line(tmp_path, look, message):
    with pytest.raises(ContourFileError, match=message):
        read_motion(_motion_file(tmp_path, look))
