"""The interactive viewer: keys change the added motion, frames follow it, the web page serves
frames and keys."""

import http.client
import itertools
import json
import signal
import socket
import subprocess
import sys
import threading
import time
import urllib.error
import urllib.request

import av
import cv2
import numpy as np
import pytest

from facemime.app.run import run_video
from facemime.app.view import HELP, Viewer
from facemime.app.view_server import make_server
from facemime.errors import InvalidInputError
from facemime.io.video import VideoReader
from facemime.shared_constants import BACKGROUND

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


def test_a_video_plays_in_its_scene_or_with_mask_only_the_face_alone(recorded):
    first = next(iter(VideoReader(recorded[0])))
    corners = (slice(0, 24), slice(-24, None))
    for mask_only in (False, True):
        with Viewer(recorded[0], mask_only=mask_only) as viewer:
            synth = viewer.frame()[:, 512:].astype(int)
        for ys, xs in itertools.product(corners, corners):
            expected = np.array(BACKGROUND) if mask_only else first[ys, xs]
            assert np.abs(synth[ys, xs] - expected).mean() < 4


def test_a_track_without_motion_is_refused(tmp_path):
    (tmp_path / "t.json").write_text(json.dumps({"format": "facemime.track/1", "frames": []}))
    with pytest.raises(Exception, match="no head motion"):
        Viewer(tmp_path / "t.json")


@pytest.mark.parametrize(
    ("args", "message"), [(["missing.mp4"], "missing.mp4 does not exist"), (["BAD"], "not valid JSON")]
)
def test_view_bad_input_gives_one_line(tmp_path, capsys, monkeypatch, args, message):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "bad.json").write_text("{")
    code, _, err = run(capsys, "view", "--no-browser", *["bad.json" if a == "BAD" else a for a in args])
    assert code == 1 and message in err and "Traceback" not in err and err.count("\n") == 1


# Hostile input and hard stops (issue 54).


@pytest.fixture
def serve(recorded):
    """Start a viewer's server on a free port in a thread: ``serve(source=track, **make_server
    options)`` gives its port; stopped, with its viewer, after the test."""
    started = []

    def start(source=None, **options):
        viewer = Viewer(source or recorded[1])
        server = make_server(viewer, port=0, **options)
        threading.Thread(target=server.serve_forever, args=(0.05,), daemon=True).start()
        started.append((server, viewer))
        return server.server_address[1]

    start.started = started

    yield start
    for server, viewer in started:
        server.shutdown()
        server.server_close()
        viewer.close()


def get(port, path="/", headers=None, body=None):
    """(status, body) of one request."""
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    try:
        c.request("GET", path, body=body, headers=headers or {})
        r = c.getresponse()
        return r.status, r.read()
    finally:
        c.close()


def parts(response):
    """(headers, body) of each part of an MJPEG stream, until it ends."""
    while (line := response.readline()) == b"--frame\r\n":
        headers = dict(h.decode().split(": ", 1) for h in iter(lambda: response.readline().rstrip(b"\r\n"), b""))
        body = response.read(int(headers["Content-Length"]))
        assert response.readline() == b"\r\n"
        yield headers, body
    assert line in (b"--frame--\r\n", b"")


def stream(port):
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    c.request("GET", "/stream")
    return c, c.getresponse()


def test_a_port_outside_0_to_65535_is_one_clear_error(recorded, capsys):
    with Viewer(recorded[1]) as viewer:
        for port in (70000, -1):
            with pytest.raises(InvalidInputError, match="port must be a whole number from 0 to 65535"):
                make_server(viewer, port=port)
    code, _, err = run(capsys, "view", "--no-browser", "--port", "70000", str(recorded[1]))
    assert code == 1 and err.startswith("facemime: error: port must be") and err.count("\n") == 1, err


@pytest.mark.parametrize(
    ("block", "field", "value"),
    [
        ("video", None, [1, 2]),
        ("video", "width", "wide"),
        ("video", "width", 0),
        ("video", "height", -4),
        ("video", "width", 100000),
        ("video", "width", 512.5),
        ("video", "fps", 0),
        ("video", "fps", "fast"),
        ("video", "fps", 1e300),
        ("model", "iod", "abc"),
        ("model", "iod", -1),
        ("model", "iod", True),
        ("model", "feature_sizes", ["a"]),
    ],
)
def test_a_track_with_wrong_fields_gives_one_line(recorded, tmp_path, capsys, monkeypatch, block, field, value):
    def serving(*args, **kwargs):
        raise AssertionError("the track was taken")  # refused at start, not served

    monkeypatch.setattr("facemime.app.view_server.make_server", serving)
    doc = json.loads(recorded[1].read_text())
    if field is None:
        doc[block] = value
    else:
        doc[block][field] = value
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(doc))
    code, _, err = run(capsys, "view", "--no-browser", "--port", "0", str(bad))
    assert code == 1 and err.startswith(f"facemime: error: {bad}: '{field or block}' must be"), err
    assert err.count("\n") == 1 and "Traceback" not in err


@pytest.mark.parametrize(
    ("headers", "status"),
    [
        ({}, 200),
        ({"Host": "localhost"}, 200),
        ({"Host": "LOCALHOST:{port}"}, 200),
        ({"Origin": "http://127.0.0.1:{port}"}, 200),
        ({"Host": "localhost:1"}, 403),  # another port: a server of its own
        ({"Host": "[::1]:{port}"}, 403),  # the viewer listens on 127.0.0.1 only
        ({"Host": "evil.example"}, 403),
        ({"Host": "evil.example:{port}"}, 403),
        ({"Host": "127.0.0.1.evil.example"}, 403),
        ({"Origin": "http://evil.example"}, 403),
        ({"Origin": "http://localhost:1"}, 403),  # a page served on another port of this machine
        ({"Origin": "https://127.0.0.1:{port}"}, 403),
        ({"Origin": "null"}, 403),
        ({"X-Pad": "a" * 9000}, 431),
    ],
)
def test_requests_not_addressed_to_this_machine_are_forbidden(serve, headers, status):
    port = serve()
    assert get(port, "/", {k: v.format(port=port) for k, v in headers.items()})[0] == status


def test_oversized_requests_and_bodies_are_refused(serve):
    port = serve()
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    c.putrequest("GET", "/", skip_host=True)  # no Host at all
    c.endheaders()
    assert c.getresponse().status == 403
    assert get(port, "/" + "a" * 9000)[0] == 431
    assert get(port, "/", body=b"hello")[0] == 413
    assert get(port, "/", {"X-Pad": "a" * 4000})[0] == 200


def test_every_stream_client_sees_every_frame(serve):
    port = serve()
    seen = [[], []]

    def watch(into):
        c, response = stream(port)
        into.extend(itertools.islice(parts(response), 10))
        c.close()

    threads = [threading.Thread(target=watch, args=(into,)) for into in seen]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    numbers = [[int(h["X-Frame"]) for h, _ in into] for into in seen]
    assert all(n == list(range(n[0], n[0] + 10)) for n in numbers), numbers
    both = set(numbers[0]) & set(numbers[1])
    assert both, numbers
    frames = [{int(h["X-Frame"]): body for h, body in into} for into in seen]
    assert all(frames[0][n] == frames[1][n] for n in both)


def test_idle_clients_are_dropped_and_clients_are_bounded(serve):
    port = serve(timeout=1, max_clients=2)
    idle = [socket.create_connection(("127.0.0.1", port), timeout=5) for _ in range(2)]
    time.sleep(0.3)  # both taken
    status, body = get(port)
    assert status == 503 and b"too many clients" in body
    start = time.monotonic()
    assert [s.recv(1) for s in idle] == [b"", b""]  # closed by the server
    assert time.monotonic() - start < 3
    deadline = time.monotonic() + 3
    while (status := get(port)[0]) != 200 and time.monotonic() < deadline:
        time.sleep(0.05)
    assert status == 200


def size_changing_video(source, path):
    """An MPEG-TS video of ``source``'s first frames, at 512x512 and then at 256x256."""
    with av.open(str(source)) as c:
        frames = [f.to_ndarray(format="rgb24") for _, f in zip(range(6), c.decode(video=0))]
    data = b""
    for part in (frames[:3], [cv2.resize(f, (256, 256)) for f in frames[3:]]):
        with av.open(str(path), "w", format="mpegts") as out:
            s = out.add_stream("libx264", rate=25)
            s.width, s.height, s.pix_fmt = part[0].shape[1], part[0].shape[0], "yuv420p"
            for f in part:
                out.mux(s.encode(av.VideoFrame.from_ndarray(f, format="rgb24")))
            out.mux(s.encode())
        data += path.read_bytes()
    path.write_bytes(data)
    return path


def test_an_error_of_the_source_ends_every_stream_with_its_message(serve, shared, tmp_path, capsys):
    port = serve(size_changing_video(shared / "video" / "lp_d0.mp4", tmp_path / "v.ts"))
    c, response = stream(port)
    got = list(parts(response))
    c.close()
    assert all("X-Frame" in h for h, _ in got[:-1]) and "changes its frame size" in got[-1][0]["X-Error"]
    assert cv2.imdecode(np.frombuffer(got[-1][1], np.uint8), cv2.IMREAD_COLOR) is not None
    c, response = stream(port)  # a later client: the message only
    assert [h["X-Error"] for h, _ in parts(response)] == [got[-1][0]["X-Error"]]
    c.close()
    status, body = get(port, "/frame.jpg")
    assert status == 503 and b"changes its frame size" in body
    err = capsys.readouterr().err
    assert err.startswith("facemime: error: video ") and err.count("\n") == 1 and "Traceback" not in err, err


def test_stopping_the_server_ends_its_streams_cleanly(serve, capsys):
    port = serve()
    c, response = stream(port)
    assert len(list(itertools.islice(parts(response), 3))) == 3
    server, viewer = serve.started[0]
    server.server_close()  # as facemime view does on Ctrl-C
    viewer.close()
    start = time.monotonic()
    rest = list(parts(response))  # the stream ends
    c.close()
    assert time.monotonic() - start < 5 and all("X-Frame" in h for h, _ in rest)
    assert capsys.readouterr().err == ""


def test_closing_the_server_cuts_stalled_clients_and_leaves_no_thread_of_its_own(serve):
    port = serve(timeout=30.0)
    c, response = stream(port)  # reads three frames, then nothing more
    assert len(list(itertools.islice(parts(response), 3))) == 3
    silent = socket.create_connection(("127.0.0.1", port))  # sends nothing
    time.sleep(0.3)  # the stream's thread blocks on the client's full socket, the other on the request
    server, _ = serve.started[0]
    start = time.monotonic()
    server.server_close()
    assert time.monotonic() - start < 5  # not the 30 s timeout of either client
    alive = [t.name for t in threading.enumerate() if "process_request" in t.name or t.name == "viewer player"]
    assert alive == []
    c.close()
    silent.close()


@pytest.mark.parametrize("trap", ["-", '""'], ids=["SIGINT as from a terminal", "SIGINT ignored"])
def test_ctrl_c_stops_a_streaming_view_cleanly(recorded, trap):
    # a shell script's background job starts with SIGINT ignored (and so does a test run started
    # as one, whose children inherit it): facemime must stop on it all the same
    command = [sys.executable, "-m", "facemime", "view", "--no-browser", "--port", "0", str(recorded[1])]
    proc = subprocess.Popen(
        ["sh", "-c", f'trap {trap} INT; exec "$@"', "sh", *command],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        port = int(proc.stdout.readline().strip().rstrip("/").rsplit(":", 1)[1])
        streams = [stream(port) for _ in range(2)]
        for _, response in streams:
            assert len(list(itertools.islice(parts(response), 3))) == 3
        proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=30)
    finally:
        proc.kill()
    assert proc.returncode == 130 and "Traceback" not in err and err.splitlines()[-1] == "facemime: interrupted", err
