"""The bitstream at the level of the native encoder and decoder: the golden stream, and
hostile bytes (hypothesis)."""

import json

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from facemime import _core

from . import golden


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
@given(st.lists(st.tuples(st.integers(0, 10**6), st.integers(0, 255), st.sampled_from("flip drop insert cut")),
                min_size=1, max_size=10),
       st.integers(1, 50), st.booleans())
def test_mutated_streams_decode_only_true_frames(edits, piece, from_start):
    truth = {f["index"]: f["values"] for f in json.loads(golden.EXPECTED.read_text())["frames"] if f["face"]}
    data = bytearray(golden.STREAM.read_bytes())
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
    outs = [dec.push(bytes(data[k:k + piece])) for k in range(0, len(data), piece)] + [dec.finish()]
    for index, face, _, values, concealed in outs:
        for i, f, v in zip(index, face, values):
            if f:
                assert v.tolist() == truth[int(i)]
        assert np.all(concealed[:, 1] >= 1) if len(concealed) else True


def test_a_decoder_written_from_the_specification_reads_the_golden_stream():
    from .reference_decoder import decode as reference

    expected = json.loads(golden.EXPECTED.read_text())["frames"]
    frames = reference(golden.STREAM.read_bytes())
    flags = lambda fs: [(f["index"], f["face"], f["lost"]) for f in fs]  # noqa: E731
    assert flags(frames) == flags(expected)
    assert [f["values"] for f in frames if f["face"]] == [f["values"] for f in expected if f["face"]]
