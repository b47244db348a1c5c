"""A real video's motion through the stream: closed loop, live pieces, loss, the actor carried
or named, the rate settings."""

import numpy as np
import pytest

from facemime.codec.files import analyse, encode_clip
from facemime.codec.params import Basis
from facemime.codec.stream import MotionDecoder, MotionEncoder, Settings, StreamError
from facemime.io.actor_file import actor_bytes, actor_from_bytes


@pytest.fixture(scope="module")
def clip(shared):
    return analyse(shared / "video" / "lp_d0.mp4")


def encoded(clip, settings=Settings(), carry=True):
    """(stream bytes, the encoder's reconstruction per frame as (pose vector, offsets))."""
    faces = np.array([m.offsets for m in clip.motion])
    enc = MotionEncoder(clip.actor, clip.fps, clip.size, Basis.learn(faces, settings.basis_size), settings, carry)
    data, recon = [enc.start()], []
    for m in clip.motion:
        e = enc.push(m.face, m.lost, m.pose, m.offsets)
        recon.append(e)
        data.append(e.data)
    data.append(enc.finish())
    return data, recon


def same(frame, e):
    return frame.pose == e.pose and np.array_equal(frame.offsets, e.offsets)


def test_the_decoder_outputs_the_encoders_reconstruction_over_a_whole_video(clip):
    data, recon = encoded(clip)
    dec = MotionDecoder()
    frames = dec.push(b"".join(data)) + dec.finish()
    assert [f.index for f in frames] == list(range(len(clip.motion)))
    assert all(same(f, e) for f, e in zip(frames, recon))
    assert not any(f.concealed for f in frames)
    # the reconstruction is close to what was measured: pose within a step, offsets within the
    # basis's reach (the clip's own basis of 16 directions) plus the quantiser
    tx = np.array([m.pose.tx for m in clip.motion]) - [e.pose.tx for e in recon]
    assert np.abs(tx).max() <= 0.8
    err = np.array([np.abs(m.offsets - e.offsets).max() for m, e in zip(clip.motion, recon)])
    assert np.median(err) < 1.5  # model units (mm); the mouth moves by up to 12 mm here
    assert dec.actor is not None and dec.actor.texture.shape == clip.actor.texture.shape


def test_a_live_receiver_fed_small_pieces_sees_the_same_frames(clip):
    data, recon = encoded(clip)
    stream = b"".join(data)
    dec = MotionDecoder(from_start=False)
    frames = []
    for k in range(0, len(stream), 37):
        frames += dec.push(stream[k:k + 37])
    frames += dec.finish()
    assert len(frames) == len(recon) and all(same(f, recon[f.index]) for f in frames)


def test_lost_packets_are_concealed_and_the_next_intra_packet_resynchronises(clip):
    data, recon = encoded(clip, Settings(packet=0.2, keyframe=1.0))
    header, packets = data[0], [d for d in data[1:] if d]
    dropped = {3, 4, 9}
    dec = MotionDecoder()
    frames = dec.push(header + b"".join(p for i, p in enumerate(packets) if i not in dropped)) + dec.finish()
    assert [f.index for f in frames] == list(range(len(clip.motion)))
    concealed = [f for f in frames if f.concealed]
    assert dec.stats["lost_packets"] == 3 and len(concealed) == dec.stats["concealed"] >= 15
    for f in frames:
        if f.concealed:  # the last good frame, held
            good = [g for g in frames[:f.index] if not g.concealed]
            assert f.pose == good[-1].pose if good else True
        else:
            assert same(f, recon[f.index])


def test_a_stream_that_names_its_actor_needs_that_actor(clip, actor):
    data, _ = encoded(clip, carry=False)
    stream = b"".join(data)
    with pytest.raises(StreamError, match="does not carry its actor"):
        MotionDecoder().push(stream)
    with pytest.raises(StreamError, match="another actor"):
        MotionDecoder(actor).push(stream)
    dec = MotionDecoder(clip.actor)
    assert len(dec.push(stream) + dec.finish()) == len(clip.motion)


def test_the_actor_travels_with_a_webp_texture(clip):
    data = actor_bytes(clip.actor, "webp", 80)
    assert len(data) < len(actor_bytes(clip.actor)) / 3
    back = actor_from_bytes(data, "the stream's actor")
    assert np.array_equal(back.model.vertices, clip.actor.model.vertices)
    assert np.abs(back.texture.astype(int) - clip.actor.texture).mean() < 6


def test_coarser_quality_costs_fewer_bytes(clip):
    sizes = [sum(map(len, encode_clip(clip, Settings(quality=q), False)[2])) for q in (0, 5, 10)]
    assert sizes[0] < sizes[1] < sizes[2]


def test_a_stream_whose_sequence_numbers_run_far_ahead_is_refused_as_a_file(clip):
    data, _ = encoded(clip, Settings(packet=0.2))
    header, first = data[0], next(d for d in data[1:] if d)
    assert first[3] < 128  # a one-byte length: the payload follows at byte 4
    tag, payload = first[0], first[4:-4]  # the first (intra) packet's
    forged = b"".join(forge(tag, seq, payload) for seq in range(0, 65536, 250))
    dec = MotionDecoder(max_concealed=10)
    with pytest.raises(StreamError, match="too damaged"):
        dec.push(header + forged)
        dec.finish()
    live = MotionDecoder()  # a live receiver conceals, within bounds
    assert len(live.push(header + forged[:2000])) < 300 * 256 * 5


def forge(tag: int, seq: int, payload: bytes) -> bytes:
    import zlib

    """A well-framed packet: ``tag``, sequence number ``seq``, ``payload`` (under 128 bytes)."""
    body = bytes([tag]) + seq.to_bytes(2, "little") + bytes([len(payload)]) + payload
    return body + zlib.crc32(body).to_bytes(4, "little")


def test_a_stream_for_another_head_model_is_refused(clip):
    from facemime import _core
    from facemime.io.actor_file import actor_id

    basis = Basis.learn(np.array([m.offsets for m in clip.motion]), 4)
    enc = _core.StreamEncoder((25, 1), clip.size, b"othermdl", 5, 5, Settings().steps(4), [0] * 10, [6] * 10,
                              basis.raw, actor_id(clip.actor), False, 0.3)
    with pytest.raises(StreamError, match="another head model"):
        MotionDecoder(clip.actor).push(enc.header_chunk())
