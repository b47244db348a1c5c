"""``facemime live``: a real video sent over VMC to a receiver of our own on 127.0.0.1 (every
frame's messages, in order, with all 52 names), stopping on a signal, and one-line errors."""

import signal
import socket
import subprocess
import sys
import threading
import time

import av
import numpy as np
import pytest
from pythonosc.osc_bundle import OscBundle

from cli.test_cli import run
from facemime.animate.arkit import NAMES
from facemime.io.photo import read_photo


class Receiver:
    """A VMC receiver on 127.0.0.1: every datagram, as it came."""

    def __init__(self):
        self.socket = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        self.socket.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 22)
        self.socket.bind(("127.0.0.1", 0))
        self.socket.settimeout(0.2)
        self.port = self.socket.getsockname()[1]
        self.datagrams, self._stop = [], threading.Event()
        self._thread = threading.Thread(target=self._receive, daemon=True)
        self._thread.start()

    def _receive(self):
        while not self._stop.is_set():
            try:
                self.datagrams.append(self.socket.recvfrom(65536)[0])
            except TimeoutError:
                continue

    def close(self):
        time.sleep(0.3)  # the last datagrams in flight
        self._stop.set()
        self._thread.join()
        self.socket.close()


@pytest.fixture
def receiver():
    r = Receiver()
    yield r
    r.close()


def test_every_frame_reaches_a_vmc_receiver_in_order_with_all_52_names(shared, receiver, capsys):
    code, out, err = run(capsys, "live", str(shared / "video" / "lp_d0.mp4"), "--vmc", f"127.0.0.1:{receiver.port}")
    assert code == 0 and out == "", err
    receiver.close()
    assert "sent 78 frames" in err and "face found in 78" in err and "latency" in err
    frames = [[(m.address, m.params) for m in OscBundle(d)] for d in receiver.datagrams]
    assert len(frames) == 78  # one bundle a frame, every frame of the video
    times, smile, yaw = [], [], []
    for messages in frames:
        addresses = [a for a, _ in messages]
        assert addresses[:4] == ["/VMC/Ext/OK", "/VMC/Ext/T", "/VMC/Ext/Root/Pos", "/VMC/Ext/Bone/Pos"]
        assert addresses[-1] == "/VMC/Ext/Blend/Apply"
        blends = dict(p for a, p in messages if a == "/VMC/Ext/Blend/Val")
        assert list(blends) == list(NAMES) and all(0.0 <= v <= 1.0 for v in blends.values())
        times.append(messages[1][1][0])
        smile.append(min(blends["mouthSmileLeft"], blends["mouthSmileRight"]))
        x, y, z, w = messages[3][1][4:]
        yaw.append(np.degrees(np.arctan2(2 * (w * y + x * z), 1 - 2 * (y * y + x * x))))
    assert np.all(np.diff(times) > 0)  # in order
    # lp_d0 grins widely in most of its frames (measured: both smiles over 0.1 in 82%); the head
    # stays nearly still
    assert np.mean(np.array(smile) > 0.1) > 0.6 and np.ptp(yaw) < 15


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["{video}", "--vmc", "127.0.0.1"], "the VMC address must be HOST:PORT"),
        (["{video}", "--vmc", "127.0.0.1:70000"], "the VMC address must be HOST:PORT"),
        (["{video}", "--vmc", "nowhere.invalid:39539"], "cannot be found"),
        (["missing.mp4"], "video missing.mp4 does not exist"),
        (["NOTVIDEO"], "cannot read video NOTVIDEO"),
        (["dog.mp4"], "no face found"),
        (["²"], "video ² does not exist"),
        (["99999999999999999999"], "camera 99999999999999999999 cannot be opened (camera numbers are 0-9999)"),
    ],
)
def test_bad_input_gives_one_line(shared, tmp_path, capsys, monkeypatch, args, message):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "NOTVIDEO").write_text("hello")
    dog = read_photo(shared / "photos" / "lp_s25.jpg")
    with av.open(str(tmp_path / "dog.mp4"), "w") as c:
        s = c.add_stream("libx264", rate=25)
        s.width, s.height, s.pix_fmt = dog.shape[1] // 2 * 2, dog.shape[0] // 2 * 2, "yuv420p"
        frame = av.VideoFrame.from_ndarray(np.ascontiguousarray(dog[: s.height, : s.width]), format="rgb24")
        for _ in range(5):
            for p in s.encode(frame):
                c.mux(p)
        for p in s.encode():
            c.mux(p)
    video = shared / "video" / "lp_d0.mp4"
    code, out, err = run(capsys, "live", *[a.format(video=video) for a in args])
    assert code == 1 and out == "" and err.count("\n") == 1 and err.startswith("facemime: error:"), err
    assert message in err


def test_a_live_run_stops_within_a_frame_when_asked_from_another_thread(shared, receiver):
    from facemime.app.live import Live

    with Live(str(shared / "video" / "lp_d0.mp4"), f"127.0.0.1:{receiver.port}", loop=True) as live:
        threading.Timer(1.0, live.stop).start()
        t0 = time.monotonic()
        stats = live.run()
        assert time.monotonic() - t0 < 1.5  # the pace is 25 frames/s: stopped within a frame or two
    assert 10 < stats.frames < 40 and stats.face_frames == stats.frames
    assert 20 < stats.fps < 30 and 0 < stats.latency(50) < 100


@pytest.mark.parametrize("presses", [1, 2])
def test_live_stops_cleanly_on_ctrl_c(shared, receiver, presses):
    """Ctrl-C stops it in one line; pressed again while it stops (here at once), it exits at once,
    in one line too, with no trace of the first's unwinding."""
    proc = subprocess.Popen(
        [sys.executable, "-m", "facemime", "live", str(shared / "video" / "lp_d0.mp4"), "--loop"]
        + ["--vmc", f"127.0.0.1:{receiver.port}"],
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        deadline = time.monotonic() + 30
        while len(receiver.datagrams) < 10 and time.monotonic() < deadline:
            time.sleep(0.05)
        assert len(receiver.datagrams) >= 10  # sending
        t0 = time.monotonic()
        for _ in range(presses):
            proc.send_signal(signal.SIGINT)
        _, err = proc.communicate(timeout=10)
        assert time.monotonic() - t0 < 3
    finally:
        proc.kill()
    # 130; or, where a second press lands while the interpreter finalises (it puts the default
    # handler back), killed by that SIGINT at once: a shell reports that as 130 too
    assert proc.returncode in ((130,) if presses == 1 else (130, -signal.SIGINT)), (proc.returncode, err)
    assert "Traceback" not in err and "Exception ignored" not in err, err
    assert err.strip().splitlines()[-1] == "facemime: interrupted"
