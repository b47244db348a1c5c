"""`facemime call`: a video analysed live and streamed over a WebSocket on 127.0.0.1; what a
client gets (hello, header, actor, frames and packets), intra requests, bad clients closed
without stopping the sender, the page's host checks, the recording, and one-line errors."""

import http.client
import itertools
import json
import re
import signal
import socket
import struct
import subprocess
import sys
import threading
import time

import pytest
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect

from cli.test_cli import run
from facemime.app.call import Call
from facemime.call.sender import Sender, SenderStats
from facemime.call.server import MAX_MESSAGE
from facemime.codec.decoder import MotionDecoder
from facemime.io.live_source import FileSource

HEADER, ACTOR, INTRA, INTER = 1, 2, 3, 4
PAGE = b"<!doctype html><title>stand-in</title>"
SCRIPT = b"// stand-in receiver"


def kind(chunk: bytes) -> int:
    return chunk[0] >> 5


@pytest.fixture(scope="module")
def video(shared):
    return shared / "video" / "lp_d0.mp4"  # 78 frames at 25 frames/s: 50 of warm-up, 28 streamed


@pytest.fixture(scope="module")
def live(video, tmp_path_factory):
    """A call on lp_d0 played again and again, its page's files stand-ins."""
    web = tmp_path_factory.mktemp("web")
    (web / "index.html").write_bytes(PAGE)
    (web / "receiver.js").write_bytes(SCRIPT)
    call = Call(video, port=0, loop=True, web=web)
    call.start()
    yield call
    call.close()
    assert call.sender.finished.is_set() and call.sender.error is None


def client(call, **kwargs):
    return connect(f"ws://127.0.0.1:{call.port}/stream", open_timeout=5, **kwargs)


def until_packets(ws, count, timeout=10.0):
    """Messages received until ``count`` packets have come (hello, header and actor included)."""
    messages, packets, deadline = [], 0, time.monotonic() + timeout
    while packets < count:
        m = ws.recv(timeout=max(0.01, deadline - time.monotonic()))
        messages.append(m)
        packets += isinstance(m, bytes) and kind(m) in (INTRA, INTER)
    return messages


def test_the_server_listens_on_this_machine_only(live):
    assert live.server.socket.getsockname()[0] == "127.0.0.1"
    probe = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        probe.connect(("192.0.2.1", 9))  # no packet is sent: this picks the outgoing interface's address
        address = probe.getsockname()[0]
    except OSError:
        address = None
    finally:
        probe.close()
    if address is None or address.startswith("127."):
        pytest.skip("this machine has no address but loopback")
    with pytest.raises(OSError):
        socket.create_connection((address, live.port), timeout=2).close()


def get(call, path, headers=None):
    c = http.client.HTTPConnection("127.0.0.1", call.port, timeout=5)
    try:
        c.request("GET", path, headers=headers or {})
        r = c.getresponse()
        return r.status, dict(r.getheaders()), r.read()
    finally:
        c.close()


def test_the_page_and_script_are_served_and_nothing_else(live):
    status, headers, body = get(live, "/")
    assert (status, body) == (200, PAGE)
    assert headers["Content-Type"] == "text/html; charset=utf-8" and headers["Cache-Control"] == "no-store"
    status, headers, body = get(live, "/receiver.js?v=1", {"Origin": f"http://localhost:{live.port}"})
    assert (status, body) == (200, SCRIPT) and headers["Content-Type"].startswith("text/javascript")
    assert get(live, "/index.html")[0] == 404 and get(live, "/../x")[0] == 404


@pytest.mark.parametrize(
    "headers",
    [
        {"Host": "evil.example"},
        {"Host": "evil.example:{port}"},
        {"Host": "127.0.0.1:1"},
        {"Origin": "http://evil.example"},
        {"Origin": "http://127.0.0.1:1"},
    ],
)
def test_requests_not_addressed_to_this_machine_are_forbidden(live, headers):
    headers = {k: v.format(port=live.port) for k, v in headers.items()}
    assert get(live, "/", headers)[0] == 403
    assert get(live, "/stream", headers)[0] == 403
    with pytest.raises(Exception, match="403"):
        client(live, origin=headers.get("Origin", f"http://{headers.get('Host')}")).close()


def test_a_client_gets_hello_header_actor_then_frames_and_packets_that_decode(live):
    with client(live) as ws:
        hello = json.loads(ws.recv(timeout=10))
        assert hello == {"type": "hello", "source": "lp_d0.mp4", "fps": 25.0, "width": 512, "height": 512}
        header, actor = ws.recv(timeout=10), ws.recv(timeout=10)
        assert (kind(header), kind(actor)) == (HEADER, ACTOR)
        ws.send(json.dumps({"type": "intra"}))  # joining mid-stream: the next packet is intra
        messages = until_packets(ws, 12)
    texts = [json.loads(m) for m in messages if isinstance(m, str)]
    packets = [m for m in messages if isinstance(m, bytes)]
    assert len(texts) == len(packets) == 12 and all(isinstance(m, str) for m in messages[::2])
    assert INTRA in [kind(p) for p in packets[:2]]
    firsts = [t["first"] for t in texts]
    assert all(t["type"] == "frames" and len(t["arrived"]) == 2 for t in texts)
    assert firsts == list(range(firsts[0], firsts[0] + 24, 2))  # P = 2; no packet skipped
    arrived = [a for t in texts for a in t["arrived"]]
    gaps = [b - a for a, b in itertools.pairwise(arrived)]
    assert 30 < sum(gaps) / len(gaps) < 50  # the video's pace: 40 ms a frame
    # ms since the epoch on this machine's clock (not seconds, not a monotonic clock): within 10 s of now even
    # on a loaded machine, where the sender can fall a second behind (latency is benchmarks/call.py's)
    assert abs(arrived[-1] - time.time() * 1000) < 10_000
    decoder = MotionDecoder(from_start=False)
    frames = decoder.push(header + actor + b"".join(packets)) + decoder.finish()
    decoded = [f for f in frames if not f.concealed]
    assert len(decoded) >= 20 and sum(f.face for f in decoded) >= 18
    assert decoder.info.packet_frames == 2 and decoder.info.has_look


def test_an_intra_request_makes_the_next_packet_intra_once(live):
    keyframe = live.sender.keyframe_packets
    with client(live) as ws:
        last = until_packets(ws, 2)[-1]
        # asked after an inter packet, the next one not the schedule's intra (just after an intra
        # packet, a request is not honoured: that packet is on its way)
        while kind(last) == INTRA or (live.sender.stats.packets % keyframe) in (0, keyframe - 1):
            last = until_packets(ws, 1)[-1]
        asked, honoured = live.sender.stats.intra_asked, live.sender.stats.intra_honoured
        ws.send('{"type": "intra"}')
        ws.send('{"type": "intra"}')  # while the next packet is intra already: nothing more
        messages = until_packets(ws, 3)
    packets = [(json.loads(t)["first"] // 2, p) for t, p in zip(messages[::2], messages[1::2])]
    intra = [s for s, p in packets if kind(p) == INTRA]
    assert intra and intra[0] <= packets[1][0] and intra[0] % keyframe != 0  # not the schedule's
    assert live.sender.stats.intra_asked == asked + 2 and live.sender.stats.intra_honoured == honoured + 1


def test_a_request_just_after_an_intra_packet_is_answered_by_it():
    """A receiver out of sync asks every 250 ms; one request may come after the intra packet it
    asked for was made, before it arrived: that packet answers it, and no second intra follows.
    After one more packet a request is honoured again (the intra may have been lost)."""
    sender = Sender.__new__(Sender)  # the request's bookkeeping alone, without a source
    sender._lock, sender.stats, sender.encoder = threading.Lock(), SenderStats(), object()
    sender.keyframe_packets, sender._forced, sender._packets_made, sender._last_intra = 25, False, 7, False
    assert sender.request_intra() and sender._forced  # packet 7 will be intra
    sender._packets_made, sender._forced, sender._last_intra = 8, False, True  # it was made
    assert not sender.request_intra() and not sender._forced
    sender._packets_made, sender._last_intra = 9, False  # and an inter packet after it
    assert sender.request_intra() and sender._forced
    assert (sender.stats.intra_asked, sender.stats.intra_honoured) == (3, 2)


@pytest.mark.parametrize(
    ("message", "code"),
    [
        (b"\x01\x02", 1003),
        ("not json", 1003),
        ('{"type": "pause"}', 1003),
        ('["intra"]', 1003),
        ("x" * (MAX_MESSAGE + 1), 1009),
    ],
)
def test_a_bad_message_closes_that_client_and_the_others_go_on(live, message, code):
    with client(live) as watcher, client(live) as bad:
        until_packets(bad, 1)
        bad.send(message)
        with pytest.raises(ConnectionClosed):
            while True:
                bad.recv(timeout=5)
        assert bad.close_code == code
        until_packets(watcher, 4)


def raw_stream(port: int) -> socket.socket:
    """A stream connection by hand: the handshake, then the first bytes read."""
    s = socket.create_connection(("127.0.0.1", port), timeout=5)
    s.sendall(
        b"GET /stream HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
        b"Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n" % port
    )
    assert s.recv(4096).startswith(b"HTTP/1.1 101")
    return s


def test_clients_that_vanish_do_not_stop_the_sender(live):
    with client(live) as watcher:
        until_packets(watcher, 1)
        before = live.hub.served
        reset, half = raw_stream(live.port), raw_stream(live.port)
        time.sleep(0.3)
        reset.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
        reset.close()  # a reset, no close frame
        half.close()  # a FIN, no close frame
        sent = live.sender.stats.packets
        messages = until_packets(watcher, 16)  # those queued before, and new ones
        assert json.loads(messages[-2])["first"] // 2 >= sent + 8
        deadline = time.monotonic() + 5
        while len(live.hub) > 1 and time.monotonic() < deadline:
            until_packets(watcher, 1)
        assert len(live.hub) == 1 and live.hub.served == before + 2


def test_a_client_that_comes_back_gets_header_and_actor_again(live):
    for _ in range(2):
        with client(live) as ws:
            assert json.loads(ws.recv(timeout=10))["type"] == "hello"
            assert [kind(ws.recv(timeout=10)) for _ in range(2)] == [HEADER, ACTOR]
            until_packets(ws, 1)


def start_call(*args, sigint_ignored=False):
    """A ``facemime call`` process and its port; ``sigint_ignored``: started with SIGINT ignored, as
    a shell script's background job is."""
    command = [sys.executable, "-m", "facemime", "call", "--port", "0", "--no-browser", *map(str, args)]
    proc = subprocess.Popen(
        ["sh", "-c", 'trap "" INT; exec "$@"', "sh", *command] if sigint_ignored else command,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    url = proc.stdout.readline().strip()
    match = re.fullmatch(r"http://127\.0\.0\.1:(\d+)/", url)
    if match is None:
        proc.kill()
        raise AssertionError(f"no address on stdout: {url!r} {proc.communicate()[1]}")
    return proc, int(match[1])


def test_a_call_streams_a_video_to_its_end_and_records_what_it_sent(video, tmp_path):
    record = tmp_path / "call.fmstream"
    proc, port = start_call(video, "--record", record)
    try:
        messages = []
        with connect(f"ws://127.0.0.1:{port}/stream", open_timeout=5) as ws:  # during the warm-up
            with pytest.raises(ConnectionClosed):
                while True:
                    messages.append(ws.recv(timeout=15))
            assert ws.close_code == 1000
        out, err = proc.communicate(timeout=10)
    finally:
        proc.kill()
    assert proc.returncode == 0, err
    assert out.splitlines() == [str(record)]  # after the address, read by start_call
    assert "Traceback" not in err
    assert messages[-1] == '{"type": "end"}'
    chunks = [m for m in messages if isinstance(m, bytes)]
    assert [kind(c) for c in chunks[:3]] == [HEADER, ACTOR, INTRA] and set(map(kind, chunks[3:])) == {INTER}
    data = record.read_bytes()
    assert data == b"".join(chunks)
    frames = MotionDecoder().push(data)
    live = MotionDecoder(from_start=False).push(b"".join(chunks))
    assert len(frames) == 28 and all(f.face and not f.concealed for f in frames)
    assert [(f.index, f.pose) for f in live] == [(f.index, f.pose) for f in frames]
    rate = float(re.search(r"motion ([0-9.]+) kbit/s", err)[1])
    assert 0.5 < rate < 4 and "sent 28 frames" in err and "1 clients served" in err
    print(f"lp_d0 live: {err.strip().splitlines()[-1]}")
    code, _, err = run_cli(video, "--record", record)
    assert code == 1 and err.count("\n") == 1 and "--force" in err


@pytest.mark.parametrize(
    ("sig", "code", "line", "sigint_ignored"),
    [
        (signal.SIGINT, 130, "facemime: interrupted", False),
        (signal.SIGINT, 130, "facemime: interrupted", True),
        (signal.SIGTERM, 143, "facemime: terminated", False),
    ],
)
def test_a_call_stops_cleanly_on_a_signal(video, sig, code, line, sigint_ignored):
    proc, port = start_call(video, "--loop", sigint_ignored=sigint_ignored)
    try:
        with connect(f"ws://127.0.0.1:{port}/stream", open_timeout=5) as ws:
            if sig == signal.SIGINT:
                until_packets(ws, 1)  # streaming
            t0 = time.monotonic()
            proc.send_signal(sig)
            with pytest.raises(ConnectionClosed):
                while time.monotonic() - t0 < 10:  # a call that goes on streaming fails, not hangs
                    ws.recv(timeout=5)
            assert ws.close_code == 1001
        _, err = proc.communicate(timeout=5)
        assert time.monotonic() - t0 < 3
    finally:
        proc.kill()
    assert proc.returncode == code and err.strip().splitlines()[-1] == line and "Traceback" not in err


def run_cli(*args):
    proc = subprocess.run(
        [sys.executable, "-m", "facemime", "call", "--port", "0", "--no-browser", *map(str, args)],
        capture_output=True,
        text=True,
        timeout=30,
    )
    return proc.returncode, proc.stdout, proc.stderr


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["missing.mp4"], "video missing.mp4 does not exist"),
        (["NOTVIDEO"], "cannot read video NOTVIDEO"),
        (["{video}", "--actor", "BAD"], "BAD"),
        (["{video}", "--actor", "missing.actor"], "actor file missing.actor does not exist"),
        (["{video}", "--record", "out.mp4"], "must end in .fmstream"),
    ],
)
def test_bad_input_gives_one_line(video, tmp_path, capsys, monkeypatch, args, message):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "NOTVIDEO").write_text("hello")
    (tmp_path / "BAD").write_bytes(b"PK\x03\x04 not an actor")
    code, out, err = run(capsys, "call", "--no-browser", "--port", "0", *[a.format(video=video) for a in args])
    assert code == 1 and out == "" and err.count("\n") == 1 and err.startswith("facemime: error:"), err
    assert message in err


class Started:
    """A sink that notes when the stream starts (or the source ends)."""

    def __init__(self):
        self.event = threading.Event()

    def start_stream(self, header, actor):
        self.event.set()

    def packet(self, first, arrived, data):
        pass

    def end(self, error):
        self.event.set()


@pytest.mark.parametrize(("rate", "quality"), [(0.05, 0), (100.0, 10)])
def test_without_a_quality_the_warm_up_chooses_the_finest_that_fits_the_rate(video, rate, quality):
    sink = Started()
    sender = Sender(FileSource(video), sink, warmup=0.6, rate=rate)
    sender.start()
    try:
        assert sink.event.wait(30)
    finally:
        sender.stop()
        sender.finished.wait(5)
    assert sender.settings.quality == quality  # none fits 0.05 kbit/s: the coarsest; all fit 100
