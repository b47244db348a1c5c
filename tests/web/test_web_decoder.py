"""The browser receiver's decoder (``web/src/stream``, TypeScript, run under Node) against the Rust
one as :class:`~facemime.codec.decoder.MotionDecoder` presents it: streams from the real encoder,
whole and damaged in many ways, fed in pieces of several sizes, must give the same frames (index,
face, lost features, concealment and every value bit for bit), the same appearance updates in the
same places, and the same stats.

Needs Node and ``web/node_modules`` (``cd web && npm install``): skipped without them, failed
when the environment variable CI is set."""

import json
import shutil
import subprocess
import zlib
from pathlib import Path

import numpy as np
import pytest

from facemime import _core
from facemime.codec.decoder import MotionDecoder
from facemime.codec.params import Basis, look_from_extras, pose_from_vector
from facemime.codec.stream import MotionEncoder, Settings
from facemime.fit.actor import generic_actor
from facemime.types.contours import FEATURES
from facemime.types.look import Look
from facemime.types.pose import Pose

ROOT = Path(__file__).resolve().parents[2]
WEB = ROOT / "web"
CLI = WEB / ".test-build" / "decode-cli.mjs"
FPS = 25.0


@pytest.fixture(scope="session")
def cli(node) -> list[str]:
    """The command that runs the Node decoder (built once per session)."""
    subprocess.run([shutil.which("npm"), "run", "--silent", "build-tests"], cwd=WEB, check=True)
    return [node, str(CLI)]


@pytest.fixture(scope="module")
def actor():
    return generic_actor((640, 480))


class Recorder:
    """Stands in for MotionDecoder's native decoder and keeps what each call returned, with the
    header in force after it."""

    def __init__(self, core):
        self.core, self.calls = core, []

    def push(self, data):
        out = self.core.push(data)
        self.calls.append((out, self.core.header()))
        return out

    def finish(self):
        out = self.core.finish()
        self.calls.append((out, self.core.header()))
        return out

    def __getattr__(self, name):
        return getattr(self.core, name)


def walk(rng, frames: int, look: bool):
    """(face, lost names, pose, (60, 2) offsets, look) per frame: a head drifting and turning, the
    mouth and brows moving, jumps that escape the tables, faceless frames and lost features."""
    t = np.arange(frames, dtype=np.float64)
    yaw = 12 * np.sin(t / 7) + np.cumsum(rng.normal(0, 0.3, frames))
    tx = 320 + 40 * np.sin(t / 11) + np.where(t % 61 == 30, 150.0, 0.0)  # a jump now and then
    modes = rng.normal(0, 1, (4, 60, 2))
    amps = np.column_stack([6 * np.sin(t / 3), 3 * np.cos(t / 5), rng.normal(0, 1, frames), np.sin(t / 2) ** 3 * 9])
    names = list(FEATURES)
    out = []
    for i in range(frames):
        pose = Pose(
            yaw=yaw[i],
            pitch=4 * np.cos(t[i] / 9),
            roll=t[i] / 40,
            scale=2.0 * np.exp(t[i] / 3000),
            tx=tx[i],
            ty=240 - t[i] / 4,
        )
        closure = 1.0 if i % 47 == 20 else 0.2 * np.sin(t[i] / 6)
        lk = Look(
            np.array([closure, closure - (0.4 if 60 <= i % 100 < 64 else 0.0)]),
            np.array([[0.1 * np.sin(t[i] / 5), 0.03], [0.1 * np.sin(t[i] / 5), -0.02 * np.cos(t[i] / 4)]]),
        )
        lost = [names[(i // 13) % 4]] if i % 13 == 5 else []
        out.append((i % 50 not in (17, 18, 19), lost, pose, np.tensordot(amps[i], modes, 1), lk if look else None))
    return out


def stream(actor, seed: int, frames: int, look: bool, carry: bool, settings: Settings, intra_at=()) -> list[bytes]:
    """The chunks of a stream from MotionEncoder: the header, the actor when carried, then one
    per packet; ``intra_at``: frames at which the sender is asked for an intra packet."""
    rng = np.random.default_rng(seed)
    motion = walk(rng, frames, look)
    basis = Basis.learn(np.array([m[3] for m in motion]), settings.basis_size)
    n = 6 + len(basis.raw) + (6 if look else 0)
    enc = MotionEncoder(actor, FPS, (640, 480), basis, settings, carry, classes=list(rng.integers(0, 16, n)), look=look)
    chunks = [enc.header] + ([_core.actor_chunk(enc.actor_data)] if carry else [])
    for i, (face, lost, pose, offsets, lk) in enumerate(motion):
        if i in intra_at:
            enc.request_intra()
        data = enc.push(face, lost, pose, offsets, lk).data
        if data:
            chunks.append(data)
    chunks.append(enc.finish())
    return [c for c in chunks if c]


def kind(chunk: bytes) -> int:
    return chunk[0] >> 5


def appearance(frame: int, k: int) -> bytes:
    payload = frame.to_bytes(4, "little") + (16 * k).to_bytes(2, "little") + (8 * k).to_bytes(2, "little")
    return _core.appearance_chunk(payload + b"RIFF" + bytes([k % 256]) * (3 + 5 * k))


def with_appearance(chunks: list[bytes], every: int = 3) -> list[bytes]:
    """An appearance chunk before every ``every``-th packet, for its first frame."""
    out, frames, packets = [], 0, 0
    for c in chunks:
        if kind(c) in (3, 4):
            if packets % every == 1:
                out.append(appearance(frames, packets))
            packets += 1
            frames += (c[0] & 31) + 1
        out.append(c)
    return out


def flip(data: bytes, rng, count: int, start: int) -> bytes:
    b = bytearray(data)
    for i in rng.integers(start, len(b), count):
        b[i] ^= int(rng.integers(1, 256))
    return bytes(b)


def mutate(data: bytes, rng, edits: int, start: int) -> bytes:
    """Random flips, dropped bytes, inserted bytes and a cut, after ``start``."""
    b = bytearray(data)
    for _ in range(edits):
        i = int(rng.integers(start, len(b)))
        how = rng.choice(["flip", "drop", "insert", "insert", "cut"], p=[0.4, 0.25, 0.15, 0.15, 0.05])
        if how == "flip":
            b[i] ^= int(rng.integers(1, 256))
        elif how == "drop":
            del b[i : i + int(rng.integers(1, 40))]
        elif how == "insert":
            b[i:i] = bytes(rng.integers(0, 256, int(rng.integers(1, 30))).astype(np.uint8))
        else:
            del b[max(i, len(b) - 200) :]
    return bytes(b)


def python_decode(data: bytes, piece: int, from_start: bool, actor):
    dec = MotionDecoder(actor, from_start=from_start)
    rec = Recorder(dec._core)
    dec._core = rec
    frames = []
    step = piece or max(len(data), 1)
    for at in range(0, len(data), step):
        frames += dec.push(data[at : at + step])
    frames += dec.finish()
    return dec, rec, frames


def node_decode(cli: list[str], data: bytes, piece: int, from_start: bool) -> list[dict]:
    args = cli + (["--live"] if not from_start else []) + ["--piece", str(piece), "-"]
    run = subprocess.run(args, input=data, capture_output=True, check=True)
    return [json.loads(line) for line in run.stdout.splitlines()]


def expected_values(calls) -> list[tuple[int, bool, int, list[float], bool]]:
    """(index, face, lost, values, concealed) per frame as MotionDecoder puts the native
    decoder's output in order (each call's frames sorted by index, decoded ones first on a tie)
    and conceals (the last decoded frame, or the header's reference pose before any), in raw
    values instead of poses and offsets."""
    out, last = [], None
    for (index, face, lost, values, concealed, _), h in calls:
        runs = [(int(i), (bool(f), int(b), v.tolist()), 1) for i, f, b, v in zip(index, face, lost, values)]
        runs += [(int(first), None, int(count)) for first, count in concealed]
        for first, frame, count in sorted(runs, key=lambda r: r[0]):
            if frame is not None:
                out.append((first, *frame, False))
                last = frame
                continue
            for k in range(count):
                if last is None:
                    pose = [r * s for r, s in zip(h["references"][:6], h["steps"][:6])]
                    out.append((first + k, False, 15, pose + [0.0] * (len(h["steps"]) - 6), True))
                else:
                    out.append((first + k, *last, True))
    return out


def lost_bits(names) -> int:
    return sum(1 << i for i, n in enumerate(FEATURES) if n in names)


def compare(cli, actor, data: bytes, piece: int = 0, from_start: bool = True, one_header: bool = True) -> dict:
    """Decodes ``data`` both ways and asserts they agree; returns the stats."""
    dec, rec, frames = python_decode(data, piece, from_start, actor)
    lines = node_decode(cli, data, piece, from_start)
    got = [(f["index"], f["face"], f["lost"], f["values"], f["concealed"]) for f in lines if f["kind"] == "frame"]
    want = expected_values(rec.calls)
    # the replica of MotionDecoder's ordering and concealment is MotionDecoder's
    assert [(f.index, f.face, lost_bits(f.lost), f.concealed) for f in frames] == [
        (w[0], w[1], w[2], w[4]) for w in want
    ]
    assert all(pose_from_vector(np.array(w[3][:6])) == f.pose for f, w in zip(frames, want))
    if one_header and dec.info is not None:
        m = len(dec.info.basis.raw)
        for f, w in zip(frames, want):
            assert np.array_equal(dec.info.basis.offsets(np.array(w[3][6 : 6 + m])), f.offsets)
            look = look_from_extras(dec.info.extras, np.array(w[3][6 + m :])) if dec.info.extras else Look()
            assert np.array_equal(look.vector(), f.look.vector())
    # and the web decoder's frames are those, every value bit for bit
    assert len(got) == len(want)
    for g, w in zip(got, want):
        assert g == w, f"frame {w[0]}"
    updates = [(u["after"], u["length"], u["crc"]) for u in lines if u["kind"] == "appearance"]
    assert updates == [(a, len(p), zlib.crc32(p)) for a, p in zip(dec.appearance_after, dec.appearance)]
    stats = {k: v for k, v in lines[-1].items() if k not in ("kind", "header_error")}
    assert lines[-1]["kind"] == "stats" and stats == dec.stats
    assert lines[-1]["header_error"] == dec._core.header_error()
    return stats


@pytest.fixture(scope="module")
def streams(actor):
    """Version 1 with the actor carried (P = 5, K = 4); version 2 with looks, the actor named (P
    = 3, K = 7) and intra packets asked for off the keyframe grid; a coarser version 2 (other N)."""
    v1 = stream(actor, 1, 300, False, True, Settings(quality=5, packet=0.2, keyframe=0.8))
    v2 = stream(actor, 2, 300, True, False, Settings(quality=3, packet=0.12, keyframe=0.84), intra_at=(40, 41, 200))
    v2b = stream(actor, 3, 120, True, False, Settings(quality=0, packet=0.16, keyframe=0.64))
    assert v1[0][9] == 1 and v2[0][9] == 2 and v2b[0][9] == 2  # the header's version byte
    assert kind(v1[1]) == 2 and kind(v2[1]) == 3
    assert v2[0][3] & 0x80 and not v2[0][4] & 0x80  # a two-byte length: the payload starts at 5
    k = int.from_bytes(v2[0][5 + 26 : 5 + 28], "little")  # the header's K
    off_grid = [int.from_bytes(c[1:3], "little") for c in v2 if kind(c) == 3 and int.from_bytes(c[1:3], "little") % k]
    assert len(off_grid) >= 2  # intra packets the sender was asked for
    return {"v1": v1, "v2": v2, "v2b": v2b}


PIECES = [0, 1, 7, 1000]


@pytest.mark.parametrize("name", ["v1", "v2", "v2b"])
@pytest.mark.parametrize("piece", PIECES)
def test_whole_streams_decode_the_same(cli, actor, streams, name, piece):
    if name == "v1" and piece == 1:
        piece = 3  # the carried actor makes a byte at a time slow in Python
    stats = compare(cli, actor, b"".join(streams[name]), piece)
    assert stats["concealed"] == 0 and stats["frames"] > 100


@pytest.mark.parametrize("name", ["v1", "v2"])
@pytest.mark.parametrize("piece", [0, 13])
def test_appearance_chunks_come_out_in_the_same_places(cli, actor, streams, name, piece):
    chunks = with_appearance(streams[name])
    assert compare(cli, actor, b"".join(chunks), piece)["appearance"] > 10
    # one damaged, one too short, one before the header: not passed on, counted
    damaged = list(chunks)
    at = next(i for i, c in enumerate(chunks) if kind(c) == 5)
    damaged[at] = flip(damaged[at], np.random.default_rng(0), 1, 9)
    damaged.insert(at + 3, bytes([5 << 5, 0, 0, 7]) + bytes(7))  # a bad CRC anyway
    short = b"\xa0\x00\x00\x07" + bytes(7)
    short += zlib.crc32(short).to_bytes(4, "little")
    stats = compare(cli, actor, appearance(0, 1) + b"".join(damaged[: at + 5] + [short] + damaged[at + 5 :]), piece)
    assert stats["undecodable"] == 2 and stats["damaged_runs"] >= 2


@pytest.mark.parametrize("name", ["v1", "v2"])
@pytest.mark.parametrize("piece", [0, 1, 50])
def test_lost_packets(cli, actor, streams, name, piece):
    chunks = streams[name]
    first = 2 if name == "v1" else 1
    drop = {first, first + 1, first + 9, first + 20, first + 21, first + 22, first + 23, first + 24, len(chunks) - 1}
    stats = compare(cli, actor, b"".join(c for i, c in enumerate(chunks) if i not in drop), piece or 1000)
    assert stats["lost_packets"] == len(drop) - 1 and stats["concealed"] > 0
    # the first packets lost: the reference pose until the first intra packet
    stats = compare(cli, actor, b"".join(chunks[:first] + chunks[first + 3 :]), piece)
    assert stats["concealed"] > 0


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("name", ["v1", "v2"])
def test_flipped_bytes(cli, actor, streams, name, seed):
    chunks = streams[name]
    start = len(b"".join(chunks[: 2 if name == "v1" else 1]))
    data = flip(b"".join(chunks), np.random.default_rng(seed), 1 + 3 * seed, start)
    stats = compare(cli, actor, data, [0, 1, 5, 64, 333, 4096][seed])
    assert stats["damaged_runs"] > 0


@pytest.mark.parametrize("name", ["v1", "v2"])
def test_truncated_streams(cli, actor, streams, name):
    data = b"".join(streams[name])
    for cut in (len(data) - 1, len(data) - 5, len(data) * 3 // 4, len(data) // 2 + 3):
        compare(cli, actor, data[:cut], 0)
        compare(cli, actor, data[:cut], 97)


@pytest.mark.parametrize("name", ["v1", "v2"])
@pytest.mark.parametrize("piece", [0, 11])
def test_duplicated_and_reordered_packets(cli, actor, streams, name, piece):
    chunks = list(streams[name])
    k = 2 if name == "v1" else 1
    chunks[k + 5], chunks[k + 6] = chunks[k + 6], chunks[k + 5]
    chunks.insert(k + 10, chunks[k + 8])
    chunks.insert(k + 20, chunks[k + 2])
    chunks.insert(k + 30, chunks[k + 30])
    stats = compare(cli, actor, b"".join(chunks), piece)
    assert stats["late_packets"] >= 3 and stats["lost_packets"] >= 1


@pytest.mark.parametrize("name", ["v1", "v2"])
@pytest.mark.parametrize("piece", [0, 1, 29])
def test_joining_a_live_stream(cli, actor, streams, name, piece):
    chunks = streams[name]
    head = chunks[: 2 if name == "v1" else 1]
    for start in (len(head) + 5, len(head) + 8, len(head) + 13):
        # a packet or two before the header (the receiver cannot decode them), then the
        # header repeated, as a live sender does, and the stream from there on
        data = b"".join(chunks[start - 2 : start] + head + chunks[start:])
        stats = compare(cli, actor, data, piece, from_start=False)
        assert stats["undecodable"] == 2 and stats["frames"] > 0


@pytest.mark.parametrize("piece", [0, 1, 37])
def test_a_second_different_header_starts_a_new_stream(cli, actor, streams, piece):
    v1, v2, v2b = streams["v1"], streams["v2"], streams["v2b"]
    # the same header again, between packets: ignored
    compare(cli, actor, b"".join(v2[:10] + v2[:1] + v2[10:]), piece)
    # a version-2 header after a version-1 stream, with as many parameters
    compare(cli, actor, b"".join(v1[:25] + v2), piece, one_header=False)
    # another header with as many parameters (other classes): frames start again at 0
    other = stream(actor, 4, 60, True, False, Settings(quality=3, packet=0.12, keyframe=0.84))
    assert other[0] != v2[0] and len(other[0]) == len(v2[0])
    compare(cli, actor, b"".join(v2[:30] + other), piece, one_header=False)
    compare(cli, actor, b"".join(v2[:30] + other), piece, from_start=False, one_header=False)
    # a refused header (another version) before the first: the reason is the same
    bad = bytearray(v2b[0])
    bad[9] = 3
    body = bytes(bad[:-4])
    compare(cli, actor, body + zlib.crc32(body).to_bytes(4, "little") + b"".join(v2b), piece)


def test_a_second_header_with_another_parameter_count(cli, actor, streams):
    # in one piece and pushed apart: each part is read with its own header, none of the first
    # stream's frames lost (the Python binding stops a call before a header that starts a stream)
    v2, v2b = streams["v2"], streams["v2b"]
    first = b"".join(v2[:40])
    for second in (b"".join(v2b), b"".join(v2b[:1] + v2b[6:])):
        for from_start in (True, False):
            for piece in (0, len(first)):
                compare(cli, actor, first + second, piece, from_start, one_header=False)


def renumber(chunk: bytes, shift: int) -> bytes:
    """A packet chunk with its sequence number moved by ``shift`` (modulo 2^16)."""
    seq = (int.from_bytes(chunk[1:3], "little") + shift) % (1 << 16)
    body = chunk[:1] + seq.to_bytes(2, "little") + chunk[3:-4]
    return body + zlib.crc32(body).to_bytes(4, "little")


@pytest.mark.parametrize("shift", [255, 256, 257, 300, 32767, 40000])
def test_sequence_numbers_that_jump_ahead(cli, actor, streams, shift):
    # a jump of up to 256 packets is concealed, a longer one is a new start, one of 2^15 or
    # more is from the past; the numbers wrap around 2^16 on the way
    chunks = streams["v2"]
    moved = chunks[:20] + [renumber(c, shift) for c in chunks[20:]]
    stats = compare(cli, actor, b"".join(moved), 0)
    assert stats["lost_packets"] == (shift if shift < 1 << 15 else 0)
    wrapped = chunks[:1] + [renumber(c, 65500) for c in chunks[1:]]
    compare(cli, actor, b"".join(wrapped), 0, from_start=False)
    compare(cli, actor, b"".join(wrapped[:30] + [renumber(c, shift) for c in wrapped[30:]]), 5, from_start=False)


@pytest.mark.parametrize("seed", range(12))
def test_random_damage(cli, actor, streams, seed):
    rng = np.random.default_rng(100 + seed)
    name = ["v1", "v2"][seed % 2]
    chunks = with_appearance(streams[name], 4) if seed % 3 == 0 else streams[name]
    start = len(b"".join(chunks[: 2 if name == "v1" else 1]))
    data = mutate(b"".join(chunks), rng, int(rng.integers(1, 25)), start)
    compare(cli, actor, data, int(rng.choice([0, 1, 3, 17, 256])), from_start=bool(seed % 4 != 1))
