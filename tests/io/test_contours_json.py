"""facemime.init/1 and facemime.track/1 files: round trip and one-line errors."""

import json

import numpy as np
import pytest

from facemime.animate.motion_file import read_motion
from facemime.errors import InputFileError
from facemime.io.contours_json import (
    ContourFileError,
    TrackWriter,
    init_document,
    read_init,
    read_track,
    track_document,
    track_entry,
    write_json,
)
from facemime.io.outputs import OutputFileError
from facemime.track.synthetic import band_face
from facemime.types.contours import CONTOUR_NAMES
from facemime.types.look import Look


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


def test_the_streaming_writer_writes_what_track_document_makes(tmp_path):
    _, contours = band_face(shift=(0.123456, -7.5))
    frames = [
        {"index": i, "contours": contours, "pose": {"yaw": 0.1 * i}, "offsets": np.full((3, 2), 0.5 * i)}
        for i in range(3)
    ]
    video = {"width": 256, "height": 256, "fps": 25.0, "frames": 3, "path": "not kept"}
    timing, model = {"fps": 10.0}, {"unit": "mm", "knots": [1, 2, 3]}
    for count in (0, 1, 3):
        with TrackWriter(tmp_path / "w.json") as writer:
            for f in frames[:count]:
                writer.append(f)
            writer.close(video, timing, model, extra={"note": 1})
        assert writer.frames == count
        expected = {**track_document(video, frames[:count], timing, model), "note": 1}
        assert expected["timing"] == timing and expected["model"] == model
        assert json.loads((tmp_path / "w.json").read_text()) == json.loads(json.dumps(expected))
    with pytest.raises(OutputFileError, match=f"cannot write {tmp_path}"):
        TrackWriter(tmp_path)


def test_a_track_entry_keeps_every_field_under_its_name_rounded_as_the_format_says():
    line = np.array([[1.23456, 2.0], [3.0, 4.98765]])
    entry = track_entry(
        {
            "index": np.int64(4),
            "contours": {"mouth_outer_upper": line},
            "confidence": {"mouth": np.float64(0.123456)},
            "lost": ("brow_left",),
            "redetected": 1,
            "face": 0,
            "pose": {"yaw": 0.123456},
            "offsets": line,
            "look": {"eye_left_closure": 0.987654},
            "weights": {"smile": 0.333333},
            "scene_departure": 0.55556,
            "scene_departs": 1,
        }
    )
    rounded = [[1.235, 2.0], [3.0, 4.988]]
    assert json.loads(json.dumps(entry)) == {
        "index": 4,
        "contours": {"mouth_outer_upper": rounded},
        "confidence": {"mouth": 0.1235},
        "lost": ["brow_left"],
        "redetected": True,
        "face": False,
        "pose": {"yaw": 0.1235},
        "offsets": rounded,
        "look": {"eye_left_closure": 0.9877},
        "weights": {"smile": 0.3333},
        "scene_departure": 0.5556,
        "scene_departs": True,
    }
    assert init_document(2, dict.fromkeys(CONTOUR_NAMES, line))["contours"]["brow_left_lower"] == rounded


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
        ('{"format": "facemime.track/1"}', "expected format 'facemime.init/1', found 'facemime.track/1'"),
        ('{"format": "facemime.init/1", "frame": -1, "contours": {}}', "'frame' must be a non-negative integer"),
        ('{"format": "facemime.init/1", "contours": []}', "'contours' must be an object"),
        ("INCOMPLETE", "missing contour brow_left_lower, brow_right_lower"),
        ("OUTSIDE", "point (300, 5) is outside the 256x256 image"),
        ("SHORT", "must have at least 2 [x, y] points"),
        ("TRIPLES", "must have at least 2 [x, y] points"),
        ("WORDS", "contour brow_left_upper must be a list of [x, y] numbers"),
        ("INFINITE", "contour brow_left_upper has a non-finite coordinate"),
        ('{"format": "facemime.init/1", "frame": true, "contours": {}}', "'frame' must be a non-negative integer"),
        ("[1, 2]", "expected format 'facemime.init/1', found 'list'"),
        (b"\xff\xfe{}", "is not a JSON text file"),
        ("[" * 50_000 + "]" * 50_000, "is nested too deeply"),
    ],
)
def test_bad_init_files_give_one_line(tmp_path, text, message):
    _, contours = band_face()
    doc = init_document(0, contours)
    if text == "INCOMPLETE":
        del doc["contours"]["brow_right_lower"], doc["contours"]["brow_left_lower"]
    elif text == "OUTSIDE":
        doc["contours"]["mouth_outer_lower"][3] = [300, 5]
    elif text == "SHORT":
        doc["contours"]["brow_left_upper"] = [[1, 2]]
    elif text == "TRIPLES":
        doc["contours"]["brow_left_upper"] = [[1, 2, 3], [4, 5, 6]]
    elif text == "WORDS":
        doc["contours"]["brow_left_upper"] = [["a", "b"], ["c", "d"]]
    elif text == "INFINITE":
        doc["contours"]["brow_left_upper"][1] = [1e999, 5]
    path = tmp_path / "bad.json"
    if isinstance(text, bytes):
        path.write_bytes(text)
    else:
        path.write_text(json.dumps(doc) if text.isupper() else text)
    with pytest.raises(ContourFileError, match=None) as err:
        read_init(path, size=(256, 256))
    # One line, naming the file (the message is all the user sees).
    assert message in str(err.value) and str(path) in str(err.value) and "\n" not in str(err.value)


def test_points_on_the_image_edge_are_inside_and_beyond_it_outside(tmp_path):
    # Pixel centres run 0..w-1, so the image spans [-0.5, w - 0.5] x [-0.5, h - 0.5].
    _, contours = band_face()
    doc = init_document(0, contours)
    path = tmp_path / "i.json"
    for corner in ([-0.5, -0.5], [255.5, 255.5]):
        doc["contours"]["mouth_outer_lower"][3] = corner
        path.write_text(json.dumps(doc))
        read_init(path, size=(256, 256))
    for point in ([-0.6, 5], [255.6, 5], [5, -0.6], [5, 255.6]):
        doc["contours"]["mouth_outer_lower"][3] = point
        path.write_text(json.dumps(doc))
        with pytest.raises(ContourFileError, match="is outside the 256x256 image"):
            read_init(path, size=(256, 256))


def test_init_frame_defaults_to_zero_and_two_points_make_a_contour(tmp_path):
    _, contours = band_face()
    doc = init_document(3, contours)
    del doc["frame"]
    doc["contours"]["brow_left_upper"] = [[10, 20], [30, 20]]
    path = tmp_path / "i.json"
    path.write_text(json.dumps(doc))
    frame, back = read_init(path)
    assert frame == 0 and back["brow_left_upper"].shape == (2, 2)


def test_a_track_frame_may_hold_some_contours_and_the_video_may_be_absent(tmp_path):
    path = tmp_path / "t.json"
    path.write_text(
        json.dumps({"format": "facemime.track/1", "frames": [{"index": 5, "contours": {"x": [[1, 2]] * 2}}]})
    )
    video, frames = read_track(path)
    assert video == {} and list(frames) == [5] and list(frames[5]) == ["x"]


@pytest.mark.parametrize(
    ("frames", "message"),
    [
        ({}, "'frames' must be a list"),
        ([[1]], "frame entry 0 must be an object with an integer 'index'"),
        ([{"index": 0, "contours": {}}, {"index": "1"}], "frame entry 1 must be an object with an integer 'index'"),
        ([{"index": 7, "contours": {"x": [[1, 2]]}}], "frame 7: contour x must have at least 2 [x, y] points"),
    ],
)
def test_bad_track_files_give_one_line_naming_the_file(tmp_path, frames, message):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps({"format": "facemime.track/1", "frames": frames}))
    with pytest.raises(ContourFileError) as err:
        read_track(path)
    assert str(err.value).startswith(str(path)) and message in str(err.value) and "\n" not in str(err.value)


def test_a_missing_file_is_named_with_its_kind(tmp_path):
    for read, kind in ((read_init, "init"), (read_track, "track"), (read_motion, "track")):
        with pytest.raises(InputFileError) as err:
            read(tmp_path / "nope.json")
        assert str(err.value) == f"{kind} file {tmp_path / 'nope.json'} does not exist"


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


def test_motion_frames_default_their_index_face_and_lost(tmp_path):
    path = _motion_file(tmp_path, None)
    doc = json.loads(path.read_text())
    del doc["video"]
    doc["frames"].append({k: v for k, v in doc["frames"][0].items() if k != "index"})
    doc["frames"][0].update(index=5, face=False, lost=["mouth"])
    doc["frames"][1]["pose"] = {**doc["frames"][1]["pose"], "scale": 0.5}
    path.write_text(json.dumps(doc))
    video, model, frames = read_motion(path)
    assert video == {} and model["knots"] == [1, 2, 3]
    assert [(f["index"], f["face"], f["lost"]) for f in frames] == [(5, False, ["mouth"]), (1, True, [])]
    assert frames[1]["pose"]["scale"] == 0.5 and frames[0]["offsets"].shape == (3, 2)


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"model": None}, "has no head motion"),
        ({"model": {"knots": 3, "feature_sizes": [1, 1, 1]}}, "has no head motion"),
        ({"model": {"knots": [1, 2, 3]}}, "has no head motion"),
        ({"frames": []}, "'frames' must be a non-empty list"),
        ({"frames": {}}, "'frames' must be a non-empty list"),
        ({"frames": [[1]]}, "frame entry 0 needs a 'pose'"),
        ({"pose": {"yaw": 0}}, "frame entry 0 needs a 'pose' with yaw, pitch, roll, scale, tx, ty and 'offsets'"),
        ({"offsets": [[0.0, 0.0]] * 2}, "frame entry 0 has malformed 'offsets'"),
        ({"offsets": [[0.0, 0.0], [0.0, 1e999], [0.0, 0.0]]}, "frame entry 0 has malformed 'offsets'"),
        ({"offsets": [[0.0, 0.0], [0.0, 1e300], [0.0, 0.0]]}, "frame entry 0 has malformed 'offsets'"),
        ({"scale": 0.0}, "frame entry 0 has a pose out of range"),
        ({"scale": 1e300}, "frame entry 0 has a pose out of range"),
        ({"tx": -1e300}, "frame entry 0 has a pose out of range"),
        ({"yaw": 1e999}, "frame entry 0 has a pose out of range"),
        ({"lost": "mouth"}, "frame entry 0: 'lost' must be a list of feature names"),
        ({"lost": [1]}, "frame entry 0: 'lost' must be a list of feature names"),
    ],
)
def test_bad_motion_files_give_one_line_naming_the_file(tmp_path, change, message):
    path = _motion_file(tmp_path, None)
    doc = json.loads(path.read_text())
    frame = doc["frames"][0]
    for key, value in change.items():
        if key in ("model", "frames"):
            doc[key] = value
        elif key in ("scale", "yaw", "tx"):
            frame["pose"][key] = value
        else:
            frame[key] = value
    path.write_text(json.dumps(doc))
    with pytest.raises(ContourFileError) as err:
        read_motion(path)
    assert str(err.value).startswith(f"{path}: ") and message in str(err.value) and "\n" not in str(err.value)
