"""The interactive viewer: keys change the added motion, frames follow it, the web page serves
frames and keys."""

import json
import threading
import urllib.error
import urllib.request

import cv2
import numpy as np
import pytest

from facemime.animate.run import run_video
from facemime.errors import InvalidInputError
from facemime.viewer import HELP, Viewer, make_server

from .test_cli import first_frames, run


@pytest.fixture(scope="module")
def recorded(shared, tmp_path_factory):
    folder = tmp_path_factory.mktemp("view")
    clip = first_frames(shared / "video" / "lp_d0.mp4", 12, folder / "clip.mp4")
    run_video(clip, folder / "run.mp4")
    return clip, folder / "run.json"


def test_keys_turn_zoom_and_exaggerate_the_replayed_face(recorded):
    viewer = Viewer(recorded[1])
    assert viewer.key(" ")["paused"]
    still = viewer.frame()
    assert still.shape == (512, 512, 3) and np.array_equal(viewer.frame(), still)  # paused: same moment
    state = viewer.key("ArrowRight")
    assert state["yaw"] == 5.0
    turned = viewer.frame()
    assert np.abs(turned.astype(int) - still).mean() > 1.0
    assert viewer.key("+")["zoom"] == pytest.approx(1.1) and viewer.key("x")["exaggerate"] == pytest.approx(1.25)
    assert viewer.key("r") == {"yaw": 0.0, "pitch": 0.0, "roll": 0.0, "zoom": 1.0, "exaggerate": 1.0, "paused": True}
    assert np.array_equal(viewer.frame(), still)
    with pytest.raises(InvalidInputError, match="unknown key"):
        viewer.key("F13")


def test_a_video_plays_side_by_side_with_live_analysis_and_closing_stops_its_decoder(recorded):
    decoding = lambda: [t for t in threading.enumerate() if t.name == f"decoder {recorded[0].name}"]  # noqa: E731
    with Viewer(recorded[0]) as viewer:
        frames = [viewer.frame() for _ in range(14)]  # past the end: it loops
        assert decoding(), "the video is decoded beside the viewer's work"
    assert all(f.shape == (512, 1024, 3) for f in frames)
    assert decoding() == []


def test_the_web_page_serves_frames_and_takes_keys(recorded):
    server = make_server(Viewer(recorded[1]), port=0)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    base = f"http://127.0.0.1:{server.server_address[1]}"
    try:
        page = urllib.request.urlopen(base + "/").read().decode()
        assert HELP in page and "/stream" in page
        jpg = urllib.request.urlopen(base + "/frame.jpg").read()
        assert cv2.imdecode(np.frombuffer(jpg, np.uint8), cv2.IMREAD_COLOR).shape == (512, 512, 3)
        assert json.loads(urllib.request.urlopen(base + "/key?k=ArrowUp").read())["pitch"] == -5.0
        with pytest.raises(urllib.error.HTTPError) as e:
            urllib.request.urlopen(base + "/key?k=nope")
        assert e.value.code == 400
        with urllib.request.urlopen(base + "/stream") as stream:
            assert stream.headers["Content-Type"].startswith("multipart/x-mixed-replace")
            assert stream.read(64).startswith(b"--frame")
    finally:
        server.shutdown()
        server.server_close()


def test_a_track_without_motion_is_refused(tmp_path):
    (tmp_path / "t.json").write_text(json.dumps({"format": "facemime.track/1", "frames": []}))
    with pytest.raises(Exception, match="no head motion"):
        Viewer(tmp_path / "t.json")


@pytest.mark.parametrize(("args", "message"), [(["missing.mp4"], "missing.mp4 does not exist"),
                                               (["BAD"], "not valid JSON")])
def test_view_bad_input_gives_one_line(tmp_path, capsys, monkeypatch, args, message):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "bad.json").write_text("{")
    code, _, err = run(capsys, "view", "--no-browser", *["bad.json" if a == "BAD" else a for a in args])
    assert code == 1 and message in err and "Traceback" not in err and err.count("\n") == 1
