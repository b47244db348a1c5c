"""The bitstream at the level of the native encoder and decoder: the golden streams (version 1,
and version 2 with looks), headers of either version, and hostile bytes (hypothesis)."""

import json
import re
import struct
import zlib

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from facemime import _core
from facemime.codec.decoder import MotionDecoder
from facemime.codec.stream import StreamError

from . import golden
from .reference_decoder import chunks as reference_chunks
from .reference_decoder import decode as reference


def decode(data: bytes, from_start: bool = True):
    dec = _core.StreamDecoder(from_start)
    parts = [dec.push(data), dec.finish()]
    return dec, [np.concatenate([p[k] for p in parts]) for k in range(5)]


def test_the_golden_stream_decodes_to_its_checked_in_parameters():
    expected = json.loads(golden.EXPECTED.read_text())["frames"]
    dec, (index, face, lost, values, concealed) = decode(golden.STREAM.read_bytes())
    assert index.tolist() == [f["index"] for f in expected] == list(range(golden.FRAMES))
    assert face.tolist() == [f["face"] for f in expected]
    assert lost.tolist() == [f["lost"] for f in expected]
    assert values.tolist() == [f["values"] for f in expected]  # exactly, bit for bit
    assert len(concealed) == 0
    h = dec.header()
    facts = (h["fps"], h["size"], h["topology"], h["packet_frames"], h["keyframe_packets"])
    assert facts == ((25, 1), (320, 240), b"golden!!", 5, 4)
    # and the parameters are the input's, quantised: within half a step plus the hysteresis
    for (has_face, _, v), out in zip(golden.frames(), values):
        if has_face:
            assert np.all(np.abs(v - out) <= 0.8 * np.array(golden.STEPS) + 1e-6)


def test_the_encoder_still_writes_the_golden_stream_byte_for_byte():
    assert golden.encode() == golden.STREAM.read_bytes()


def test_frames_without_a_face_and_lost_features_are_flagged():
    _, (index, face, lost, _, _) = decode(golden.STREAM.read_bytes())
    assert index[~face].tolist() == [17, 18, 19]
    assert index[lost > 0].tolist() == [30] and lost[30] == 8


@settings(max_examples=300, deadline=None)
@given(st.binary(max_size=3000))
def test_random_bytes_are_never_decoded(data):
    dec, (index, *_rest, concealed) = decode(data)
    assert len(index) == 0 and len(concealed) == 0
    assert dec.header() is None


@settings(max_examples=300, deadline=None)
@given(
    st.lists(
        st.tuples(st.integers(0, 10**6), st.integers(0, 255), st.sampled_from("flip drop insert cut")),
        min_size=1,
        max_size=10,
    ),
    st.integers(1, 50),
    st.booleans(),
    st.sampled_from([1, 2]),
)
def test_mutated_streams_decode_only_true_frames(edits, piece, from_start, version):
    stream, expected = (golden.STREAM, golden.EXPECTED) if version == 1 else (golden.STREAM_V2, golden.EXPECTED_V2)
    truth = {f["index"]: f["values"] for f in json.loads(expected.read_text())["frames"] if f["face"]}
    data, updates = bytearray(stream.read_bytes()), []
    if version == 2:  # with appearance updates between packets
        data, updates = with_appearance(bytes(data))
        data = bytearray(data)
    for at, value, how in edits:
        if not data:
            break
        i = at % len(data)
        if how == "flip":
            data[i] ^= value | 1
        elif how == "drop":
            del data[i]
        elif how == "insert":
            data.insert(i, value)
        else:
            del data[i:]
    dec = _core.StreamDecoder(from_start)
    outs = [dec.push(bytes(data[k : k + piece])) for k in range(0, len(data), piece)] + [dec.finish()]
    for index, face, _, values, concealed, appearance in outs:
        for i, f, v in zip(index, face, values):
            if f:
                assert v.tolist() == truth[int(i)]
        assert np.all(concealed[:, 1] >= 1) if len(concealed) else True
        assert all(bytes(p) in [u for _, u in updates] for _, p in appearance)  # whole and true


def test_a_decoder_written_from_the_specification_reads_the_golden_stream():
    expected = json.loads(golden.EXPECTED.read_text())["frames"]
    frames = reference(golden.STREAM.read_bytes())
    flags = lambda fs: [(f["index"], f["face"], f["lost"]) for f in fs]  # noqa: E731
    assert flags(frames) == flags(expected)
    assert [f["values"] for f in frames if f["face"]] == [f["values"] for f in expected if f["face"]]


def test_the_version_2_golden_stream_decodes_to_its_checked_in_parameters_and_looks():
    expected = json.loads(golden.EXPECTED_V2.read_text())
    data = golden.STREAM_V2.read_bytes()
    dec, (index, face, lost, values, concealed) = decode(data)
    assert data[9] == 2  # the header's version byte (after tag, seq, a two-byte length, magic)
    assert dec.header()["extras"] == expected["extras"] == list(range(1, 7))
    assert dec.header()["basis"].shape == (2, 6)
    assert index.tolist() == [f["index"] for f in expected["frames"]] == list(range(golden.FRAMES_V2))
    assert face.tolist() == [f["face"] for f in expected["frames"]]
    assert lost.tolist() == [f["lost"] for f in expected["frames"]]
    assert values.tolist() == [f["values"] for f in expected["frames"]]  # exactly, bit for bit
    assert len(concealed) == 0
    assert index[~face].tolist() == [14, 15] and index[lost > 0].tolist() == [7]
    for (has_face, _, v), out in zip(golden.frames_v2(), values):
        if has_face:
            assert np.all(np.abs(v - out) <= 0.8 * np.array(golden.STEPS_V2) + 1e-6)
    closure = values[:, 6 + 2 : 6 + 4]
    assert closure[9].tolist() == [1.0, 1.0] and closure[8].tolist() == [0.0, 0.0]  # the blink, in one frame
    assert closure[21, 0] < -0.3 and closure[21, 1] == 0.0  # the right eye opened wide


def test_the_encoder_still_writes_the_version_2_golden_stream_byte_for_byte():
    assert golden.encode(2) == golden.STREAM_V2.read_bytes()


def test_a_decoder_written_from_the_specification_reads_the_version_2_golden_stream():
    expected = json.loads(golden.EXPECTED_V2.read_text())["frames"]
    frames = reference(golden.STREAM_V2.read_bytes())
    flags = lambda fs: [(f["index"], f["face"], f["lost"]) for f in fs]  # noqa: E731
    assert flags(frames) == flags(expected)
    assert [f["values"] for f in frames if f["face"]] == [f["values"] for f in expected if f["face"]]
    assert [f["look"] for f in frames if f["face"]] == [f["values"][-6:] for f in expected if f["face"]]


@pytest.mark.parametrize("kinds", [(1, 2, 3, 4, 5, 6), (6, 200, 1, 7), (255,)])
def test_the_specification_and_the_rust_decoder_agree_on_version_2_streams(kinds):
    """A longer stream with random-walk looks (escapes, blinks), kinds in any order, unknown ones
    among them: the reference decoder's values are the Rust decoder's, bit for bit."""
    rng = np.random.default_rng(sum(kinds))
    x, m, frames = len(kinds), 3, 400
    steps = [0.5, 0.5, 0.5, 0.004, 0.5, 0.5] + [2.0] * m + list(rng.uniform(0.01, 0.1, x))
    enc = _core.StreamEncoder(
        (24, 1),
        (640, 360),
        b"spec-rs!",
        7,
        5,
        steps,
        [0, 0, 0, 200, 320, 180] + [3] * (m + x),
        list(rng.integers(0, 16, 6 + m + x)),
        rng.integers(-30000, 30000, (m, 10), np.int16),
        bytes(32),
        True,
        0.3,
        list(kinds),
    )
    walk = np.cumsum(rng.normal(0, 1.5, (frames, 6 + m + x)) * steps, axis=0) + np.array(steps) * 3
    walk[::37, 6 + m :] += 1.0  # blinks: jumps of 10-100 steps
    data = [enc.header_chunk()]
    for t in range(frames):
        data.append(enc.push(t % 50 < 47, t % 3, walk[t])[1] or b"")
    data.append(enc.finish() or b"")
    _, (index, face, lost, values, _) = decode(b"".join(data))
    frames_ = reference(b"".join(data))
    assert [(f["index"], f["face"], f["lost"]) for f in frames_] == list(
        zip(index.tolist(), face.tolist(), lost.tolist())
    )
    assert [f["values"] for f in frames_ if f["face"]] == values[face].tolist()
    known = [(i, k) for i, k in enumerate(kinds) if k <= 6]
    for f, v in zip([f for f in frames_ if f["face"]], values[face]):
        assert [f["look"][k - 1] for _, k in known] == [v[6 + m + i] for i, _ in known]


def leb128(n: int) -> bytes:
    out = b""
    while True:
        out += bytes([(n & 0x7F) | (0x80 if n >> 7 else 0)])
        n >>= 7
        if not n:
            return out


def any_chunk(kind: int, payload: bytes, frames: int = 0, seq: int = 0) -> bytes:
    """A chunk of ``kind`` around ``payload`` (``docs/bitstream.md``, "Chunks"); ``frames`` goes
    in the tag as frames - 1 (0: none)."""
    body = bytes([kind << 5 | max(frames - 1, 0)]) + struct.pack("<H", seq) + leb128(len(payload)) + payload
    return body + struct.pack("<I", zlib.crc32(body))


def header_chunk(payload: bytes) -> bytes:
    """A header chunk (kind 1) around ``payload``."""
    return any_chunk(1, payload)


def golden_v2_header() -> tuple[bytearray, int]:
    """The version-2 golden stream's header payload, and where its X byte is."""
    data = golden.STREAM_V2.read_bytes()
    length = (data[3] & 0x7F) | (data[4] << 7)  # a two-byte LEB128 length
    payload = bytearray(data[5 : 5 + length])
    assert header_chunk(bytes(payload)) == data[: 5 + length + 4]
    return payload, 29 + 9 * payload[28]


@pytest.mark.parametrize(
    "edit, reason",
    [
        ("many", "9 extra parameters do not fit in 14 parameters per frame (at most 8 after the pose)"),
        ("twice", "extra parameter kind 3 appears twice"),
        ("zero", "extra parameter 4 has kind 0; kinds are 1-255"),
        ("version 3", "stream format version 3; this decoder reads versions 1 and 2"),
        ("version 0", "stream format version 0; this decoder reads versions 1 and 2"),
    ],
)
def test_bad_version_2_headers_are_refused_with_their_reason(edit, reason):
    payload, x = golden_v2_header()
    assert payload[4] == 2 and payload[x : x + 7] == bytes([6, *range(1, 7)])
    if edit == "many":  # nine extras where only eight parameters follow the pose
        payload[x] = 9
        payload[x + 7 : x + 7] = bytes([7, 8, 9])
    elif edit == "twice":
        payload[x + 2] = 3
    elif edit == "zero":
        payload[x + 5] = 0
    else:
        payload[4] = int(edit[-1])
    dec = _core.StreamDecoder(True)
    dec.push(header_chunk(bytes(payload)) + golden.STREAM_V2.read_bytes()[len(header_chunk(golden_v2_header()[0])) :])
    assert dec.header() is None and dec.header_error() == reason
    receiver = MotionDecoder()
    receiver.push(header_chunk(bytes(payload)))
    with pytest.raises(StreamError, match=f"^the stream: {re.escape(reason)}$"):
        receiver.finish()


def test_a_version_2_header_read_as_version_1_is_refused_not_misread():
    payload, _ = golden_v2_header()
    payload[4] = 1  # the extras' bytes are then read as the basis: the length no longer fits
    dec = _core.StreamDecoder(True)
    dec.push(header_chunk(bytes(payload)))
    assert dec.header() is None and dec.header_error() == "the stream header is cut short"


def test_the_encoder_refuses_bad_extras():
    basis = np.zeros((2, 6), np.int16)
    args = ((30, 1), (160, 120), b"golden02", 4, 3, golden.STEPS_V2, [0] * 14, [6] * 14, basis, bytes(32), False, 0.3)
    with pytest.raises(ValueError, match=r"^extra parameter kind 2 appears twice$"):
        _core.StreamEncoder(*args, [1, 2, 3, 4, 5, 2])
    with pytest.raises(ValueError, match=r"^extra parameter 0 has kind 0; kinds are 1-255$"):
        _core.StreamEncoder(*args, [0, 2, 3, 4, 5, 6])
    with pytest.raises(ValueError, match=r"^the basis holds 12 entries, not 3 x 6$"):
        _core.StreamEncoder(*args, [1, 2, 3, 4, 5])


def split_chunks(data: bytes) -> list[bytes]:
    """The bytes of each chunk of an undamaged stream."""
    out = [
        any_chunk(kind, payload, count if kind in (3, 4) else 0, seq)
        for kind, count, seq, payload in reference_chunks(data)
    ]
    assert b"".join(out) == data
    return out


def appearance_payload(frame: int, x: int, y: int, image: bytes) -> bytes:
    return struct.pack("<IHH", frame, x, y) + image


def with_appearance(data: bytes) -> tuple[bytes, list[tuple[int, bytes]]]:
    """The version-2 golden stream with an appearance chunk before every other packet (for that
    packet's first frame, P = 4), and (frames before it, payload) of each."""
    chunks, updates, out, frames = split_chunks(data), [], [], 0
    for c in chunks:
        kind, count = c[0] >> 5, (c[0] & 31) + 1
        if kind in (3, 4):
            if len(updates) < 4 and frames % 8 == 4:
                p = appearance_payload(frames, 16 * len(updates), 3, b"RIFF" + bytes([len(updates)]) * (5 + frames))
                updates.append((frames, p))
                out.append(_core.appearance_chunk(p))
            frames += count
        out.append(c)
    return b"".join(out), updates


def decode_all(data: bytes):
    """(decoder, the five frame arrays, (frames before it, payload) per appearance update) of
    ``data`` pushed at once, then finished (damage may hold bytes back until then)."""
    dec = _core.StreamDecoder(True)
    parts, updates, seen = [dec.push(data), dec.finish()], [], 0
    for index, *_, concealed, appearance in parts:
        updates += [(seen + int(at), bytes(p)) for at, p in appearance]
        seen += len(index) + int(concealed[:, 1].sum())
    return dec, [np.concatenate([p[k] for p in parts]) for k in range(5)], updates


def same_arrays(a, b) -> bool:
    return all(np.array_equal(x, y) for x, y in zip(a, b))


def test_appearance_chunks_between_packets_change_no_frame_and_come_out_in_order():
    data = golden.STREAM_V2.read_bytes()
    plain, plain_frames, none = decode_all(data)
    assert none == [] and plain.stats()["appearance"] == 0
    mixed, updates = with_appearance(data)
    assert [at for at, _ in updates] == [4, 12, 20, 28]
    dec, frames, got = decode_all(mixed)
    assert same_arrays(frames, plain_frames)
    assert got == updates  # in stream order, each before its packet's frames
    # nothing else is counted: no damage, no undecodable chunk, the same packets and frames
    assert dec.stats() == {**plain.stats(), "appearance": 4}
    # the decoder written from the specification agrees, and takes them as chunks, not damage
    found = []
    assert reference(mixed, found) == reference(data)
    assert found == updates
    # fed a byte at a time: each update comes out in the call that completes its chunk
    dec, seen, got = _core.StreamDecoder(True), 0, []
    for i in range(len(mixed)):
        index, _, _, _, concealed, app = dec.push(mixed[i : i + 1])
        got += [(seen + int(at), bytes(p)) for at, p in app]
        seen += len(index) + int(concealed[:, 1].sum())
    assert got == updates and seen == golden.FRAMES_V2


def test_appearance_chunks_come_out_in_a_version_1_stream_too():
    data = golden.STREAM.read_bytes()
    chunks = split_chunks(data)
    p = appearance_payload(5, 0, 0, b"RIFF....WEBP")
    mixed = b"".join(chunks[:2] + [_core.appearance_chunk(p)] + chunks[2:])
    _dec, frames, got = decode_all(mixed)
    assert same_arrays(frames, decode_all(data)[1]) and got == [(5, p)]


def test_a_damaged_appearance_chunk_is_skipped_as_damage_and_the_rest_decodes():
    data = golden.STREAM_V2.read_bytes()
    _, plain_frames, _ = decode_all(data)
    mixed, updates = with_appearance(data)
    at = mixed.index(updates[1][1]) + 10  # a byte of the second update's image
    damaged = bytearray(mixed)
    damaged[at] ^= 0x20
    dec, frames, got = decode_all(bytes(damaged))
    assert same_arrays(frames, plain_frames)
    assert got == updates[:1] + updates[2:]
    stats = dec.stats()
    assert (stats["damaged_runs"], stats["undecodable"], stats["appearance"]) == (1, 0, 3)
    assert stats["damaged_bytes"] == len(_core.appearance_chunk(updates[1][1]))


def test_an_appearance_payload_too_short_for_its_frame_and_place_is_undecodable():
    data = golden.STREAM_V2.read_bytes()
    chunks = split_chunks(data)
    short = any_chunk(5, b"\x04\x00\x00\x00\x00\x00\x00")  # 7 bytes: no room for y
    good = appearance_payload(0, 0, 0, b"")  # 8 bytes: an update with an empty image is passed on
    dec, frames, got = decode_all(b"".join(chunks[:1] + [short, _core.appearance_chunk(good)] + chunks[1:]))
    assert same_arrays(frames, decode_all(data)[1]) and got == [(0, good)]
    assert (dec.stats()["undecodable"], dec.stats()["damaged_runs"]) == (1, 0)
    found = []
    reference(b"".join(chunks[:1] + [short] + chunks[1:]), found)
    assert found == []
    with pytest.raises(ValueError, match=r"^an appearance payload must hold at least 8 bytes \(frame, x, y\), got 7$"):
        _core.appearance_chunk(b"1234567")
    with pytest.raises(ValueError, match=r"^an appearance payload must hold at most 1048576 bytes, got 1048577$"):
        _core.appearance_chunk(bytes(8 + (1 << 20) - 7))
    assert len(_core.appearance_chunk(bytes(1 << 20))) == 3 + 3 + (1 << 20) + 4


def test_an_appearance_chunk_before_any_header_is_undecodable():
    data = golden.STREAM_V2.read_bytes()
    dec, frames, got = decode_all(_core.appearance_chunk(appearance_payload(0, 0, 0, b"x")) + data)
    assert same_arrays(frames, decode_all(data)[1]) and got == []
    assert (dec.stats()["undecodable"], dec.stats()["damaged_runs"]) == (1, 0)


@pytest.mark.parametrize("bad", ["length", "frames"])
def test_an_appearance_chunk_over_its_limit_or_with_frame_bits_is_not_a_chunk(bad):
    data = golden.STREAM_V2.read_bytes()
    chunks = split_chunks(data)
    if bad == "length":  # a declared length of 2^20 + 1, then the next packet
        fake = bytes([5 << 5, 0, 0]) + leb128((1 << 20) + 1)
    else:  # a good CRC, but a tag with frame bits
        fake = any_chunk(5, appearance_payload(4, 0, 0, b"RIFF"), frames=2)
    dec, frames, got = decode_all(b"".join(chunks[:2] + [fake] + chunks[2:]))
    assert same_arrays(frames, decode_all(data)[1]) and got == []
    stats = dec.stats()
    assert (stats["damaged_runs"], stats["damaged_bytes"], stats["undecodable"]) == (1, len(fake), 0)
    with pytest.raises(AssertionError):  # the reference decoder takes no damage
        reference(b"".join(chunks[:2] + [fake] + chunks[2:]))
