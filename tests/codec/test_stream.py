"""A real video's motion through the stream: closed loop, live pieces, loss, the actor carried
or named, the rate settings, and looks (format version 2) carried with the motion."""

import copy
from dataclasses import replace

import numpy as np
import pytest

from facemime import _core
from facemime.codec.clip import analyse, encode_clip
from facemime.codec.decoder import MotionDecoder
from facemime.codec.params import LOOK_KINDS, Basis, pose_vector, topology_id
from facemime.codec.stream import LOOK_STEPS, MotionEncoder, Settings, StreamError
from facemime.errors import InvalidInputError
from facemime.io.actor_file import actor_bytes, actor_from_bytes, actor_id
from facemime.types.look import Look


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
    # a stream without looks is version 1 and decodes to neutral looks
    assert data[0][9] == 1 and dec.info.extras == () and not dec.info.has_look
    assert all(np.all(f.look.vector() == 0) and np.all(e.look.vector() == 0) for f, e in zip(frames, recon))
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
        frames += dec.push(stream[k : k + 37])
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
            good = [g for g in frames[: f.index] if not g.concealed]
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
    enc = _core.StreamEncoder(
        (25, 1),
        clip.size,
        b"othermdl",
        5,
        5,
        Settings().steps(4),
        [0] * 10,
        [6] * 10,
        basis.raw,
        actor_id(clip.actor),
        False,
        0.3,
    )
    with pytest.raises(StreamError, match="another head model"):
        MotionDecoder(clip.actor).push(enc.header_chunk())


def looks(n: int, seed: int = 0) -> list[Look]:
    """Made-up looks of ``n`` frames at 25 fps: a blink every 3 s (shut in one frame, open again
    over three), the irises jumping between a few places and drifting between jumps (noise of a
    tracker included)."""
    rng = np.random.default_rng(seed)
    closure = np.zeros(n)
    for start in range(20, n, 75):
        closure[start : start + 4] = [1.0, 0.8, 0.4, 0.1][: len(closure[start : start + 4])]
    jumps = np.repeat(rng.uniform(-0.15, 0.15, (n // 20 + 1, 2)), 20, axis=0)[:n]
    iris = jumps + rng.normal(0, 0.005, (n, 2))
    out = []
    for i in range(n):
        c = [closure[i], closure[i] * 0.95]
        out.append(Look(np.array(c), np.array([iris[i], iris[i] + [0.01, 0.0]])))
    return out


def with_looks(clip, given):
    """The clip with each frame's look set (FrameMotion's ``look``)."""
    motion = []
    for m, look in zip(clip.motion, given):
        m = copy.copy(m)
        m.look = look
        motion.append(m)
    return replace(clip, motion=motion)


def test_looks_round_trip_exactly_and_within_half_a_step(clip):
    settings = Settings(hysteresis=0.0)
    given = looks(len(clip.motion))
    enc = MotionEncoder(
        clip.actor,
        clip.fps,
        clip.size,
        Basis.learn(np.array([m.offsets for m in clip.motion]), 16),
        settings,
        True,
        look=True,
    )
    data, recon = [enc.start()], []
    for m, look in zip(clip.motion, given):
        recon.append(enc.push(m.face, m.lost, m.pose, m.offsets, look))
        data.append(recon[-1].data)
    data.append(enc.finish())
    dec = MotionDecoder()
    frames = dec.push(b"".join(data)) + dec.finish()
    assert data[0][9] == 2 and dec.info.extras == LOOK_KINDS and dec.info.has_look
    assert len(frames) == len(clip.motion) and not any(f.concealed for f in frames)
    assert all(same(f, e) and np.array_equal(f.look.vector(), e.look.vector()) for f, e in zip(frames, recon))
    steps = np.array(LOOK_STEPS)  # quality 5: factor 1
    for m, look, f in zip(clip.motion, given, frames):
        if m.face:
            assert np.all(np.abs(f.look.vector() - look.vector()) <= steps / 2 + 1e-9)
    blinks = [f.index for f in frames if f.look.closure[0] == 1.0]
    assert blinks and blinks[0] == 20


def test_a_lost_packet_repeats_the_last_good_look(clip):
    given = looks(len(clip.motion), 1)
    enc = MotionEncoder(
        clip.actor,
        clip.fps,
        clip.size,
        Basis.learn(np.array([m.offsets for m in clip.motion]), 8),
        Settings(packet=0.2),
        False,
        look=True,
    )
    packets = [enc.push(m.face, m.lost, m.pose, m.offsets, look).data for m, look in zip(clip.motion, given)]
    packets = [p for p in packets + [enc.finish()] if p]
    dec = MotionDecoder(clip.actor)
    frames = dec.push(enc.header + b"".join(packets[:4] + packets[5:])) + dec.finish()
    concealed = [f for f in frames if f.concealed]
    assert concealed and all(f.look is frames[concealed[0].index - 1].look for f in concealed)
    assert np.any(frames[concealed[0].index - 1].look.vector() != 0)


def test_an_encoder_without_looks_refuses_one_and_writes_version_1(clip):
    basis = Basis.learn(np.array([m.offsets for m in clip.motion]), 4)
    enc = MotionEncoder(clip.actor, clip.fps, clip.size, basis, Settings(), False)
    m = clip.motion[0]
    with pytest.raises(InvalidInputError, match="carries no look: make it with look=True"):
        enc.push(m.face, m.lost, m.pose, m.offsets, Look(closure=np.array([0.5, 0.5])))
    assert np.all(enc.push(m.face, m.lost, m.pose, m.offsets, Look()).look.vector() == 0)
    looking = MotionEncoder(clip.actor, clip.fps, clip.size, basis, Settings(), False, look=True)
    with pytest.raises(InvalidInputError, match="the look's values must be finite"):
        looking.push(m.face, m.lost, m.pose, m.offsets, Look(iris=np.array([[0, np.nan], [0, 0]])))
    with pytest.raises(InvalidInputError, match=r"classes must have one entry per parameter \(16\), got 10"):
        MotionEncoder(clip.actor, clip.fps, clip.size, basis, Settings(), False, [6] * 10, look=True)


def test_encode_clip_sends_looks_only_when_one_is_not_neutral(clip):
    plain = encode_clip(with_looks(clip, [Look()] * len(clip.motion)), Settings(), False)
    assert plain[0][9] == 1  # version 1
    given = looks(len(clip.motion), 2)
    header, _, packets = encode_clip(with_looks(clip, given), Settings(), False)
    assert header[9] == 2
    dec = MotionDecoder(clip.actor)
    frames = dec.push(header + b"".join(packets)) + dec.finish()
    assert dec.info.extras == LOOK_KINDS
    faces = [(f, look) for f, look, m in zip(frames, given, clip.motion) if m.face]
    err = np.array([np.abs(f.look.vector() - look.vector()) for f, look in faces])
    assert np.all(err <= 0.8 * np.array(LOOK_STEPS) + 1e-9)  # half a step and the hysteresis
    # the motion is coded as before: the same poses and offsets as the version-1 stream's
    dec1 = MotionDecoder(clip.actor)
    frames1 = dec1.push(plain[0] + b"".join(plain[2])) + dec1.finish()
    assert all(a.pose == b.pose and np.array_equal(a.offsets, b.offsets) for a, b in zip(frames, frames1))
    # the look's classes are chosen from the clip's looks (each parameter's class depends on its
    # own values only), not left at the default
    classes = list(dec._core.header()["classes"])
    alone = _core.choose_classes(list(LOOK_STEPS), 0.3, np.array([look.vector() for (_, look) in faces]))
    assert len(classes) == 6 + 16 + 6 and classes[-6:] == list(alone) and set(alone) != {6}
    # one non-neutral look is enough
    one = [Look()] * len(clip.motion)
    one[5] = Look(iris=np.array([[0.05, 0], [0, 0]]))
    assert encode_clip(with_looks(clip, one), Settings(), False)[0][9] == 2


def test_kinds_the_decoder_does_not_know_are_decoded_and_ignored(clip):
    basis = Basis.learn(np.array([m.offsets for m in clip.motion]), 2)
    steps = Settings().steps(2) + [1 / 64, 0.5, 1 / 16, 0.5]
    enc = _core.StreamEncoder(
        (25, 1),
        clip.size,
        topology_id(clip.actor.model),
        5,
        5,
        steps,
        [0] * 12,
        [6] * 12,
        basis.raw,
        actor_id(clip.actor),
        False,
        0.3,
        [5, 200, 2, 7],
    )
    m = clip.motion[0]
    values = np.concatenate([pose_vector(m.pose), basis.coefficients(m.offsets), [0.25, 40.0, 0.5, 3.0]])
    data = enc.header_chunk() + (enc.push(True, 0, values)[1] or b"") + (enc.finish() or b"")
    dec = MotionDecoder(clip.actor)
    (frame,) = dec.push(data) + dec.finish()
    assert dec.info.extras == (5, 200, 2, 7) and dec.info.has_look
    assert frame.look.vector().tolist() == [0, 0.5, 0, 0, 0.25, 0]
    assert np.array_equal(frame.offsets, basis.offsets(np.round(basis.coefficients(m.offsets) / 3.0) * 3.0))


def test_the_decoder_collects_appearance_payloads_in_order_and_where_they_fall(clip):
    data, _recon = encoded(clip)
    plain = MotionDecoder()
    expected = plain.push(b"".join(data)) + plain.finish()
    # an update before every third packet, for that packet's first frame (payloads not parsed
    # here); data[t + 1] is what frame t completed: a packet of the frames up to t, or nothing
    mixed, payloads, after, frames = [data[0]], [], [], 0
    for t, d in enumerate(data[1:]):
        if not d:
            continue
        if len(mixed) % 3 == 1:
            p = frames.to_bytes(4, "little") + bytes([t % 256, 0, 7, 0]) + b"RIFF" + bytes(t % 50)
            mixed.append(_core.appearance_chunk(p))
            payloads.append(p)
            after.append(frames)
        mixed.append(d)
        frames = min(t + 1, len(clip.motion))
    stream = b"".join(mixed)
    assert len(payloads) >= 3
    dec = MotionDecoder()
    got = [f for k in range(0, len(stream), 37) for f in dec.push(stream[k : k + 37])] + dec.finish()
    assert [(f.index, f.face, f.lost, f.pose, f.concealed) for f in got] == [
        (f.index, f.face, f.lost, f.pose, f.concealed) for f in expected
    ]
    assert all(np.array_equal(f.offsets, e.offsets) for f, e in zip(got, expected))
    assert dec.appearance == payloads and dec.appearance_after == after
    assert dec.stats["appearance"] == len(payloads) and dec.stats["undecodable"] == 0
    assert plain.appearance == [] and plain.appearance_after == []


@pytest.mark.parametrize("whole", [True, False])
def test_two_streams_one_after_the_other_decode_each_with_its_own_header(clip, whole):
    # a second stream of another quality (other steps, another number of coefficients) follows
    # the first in the same bytes: its frames restart at 0 and are read with its own basis, and
    # none of the first's is lost, whether the bytes come in one piece or two
    first, recon1 = encoded(clip)
    second, recon2 = encoded(clip, Settings(quality=2))
    dec = MotionDecoder()
    if whole:
        frames = dec.push(b"".join(first + second)) + dec.finish()
    else:
        frames = dec.push(b"".join(first)) + dec.push(b"".join(second)) + dec.finish()
    n = len(clip.motion)
    assert [f.index for f in frames] == list(range(n)) * 2
    assert all(same(f, e) for f, e in zip(frames, recon1 + recon2))
    assert len(dec.info.basis.raw) == Settings(quality=2).basis_size


def test_sample_choices_round_trip_exactly(clip):
    rng = np.random.default_rng(3)
    given = [
        tuple(None if k < 0 else int(k) for k in rng.integers(-1, 16, 2)) if i % 7 else (None, None)
        for i in range(len(clip.motion))
    ]
    for hysteresis in (0.0, 0.49):  # under half a step: a change of one sample is always sent
        enc = MotionEncoder(
            clip.actor,
            clip.fps,
            clip.size,
            Basis.learn(np.array([m.offsets for m in clip.motion]), 8),
            Settings(hysteresis=hysteresis),
            False,
            look=True,
            samples=True,
        )
        recon = [enc.push(m.face, m.lost, m.pose, m.offsets, None, s) for m, s in zip(clip.motion, given)]
        dec = MotionDecoder(clip.actor)
        frames = dec.push(enc.header + b"".join(r.data for r in recon) + enc.finish()) + dec.finish()
        assert dec.info.extras == LOOK_KINDS + (7, 8)
        faces = [(f.samples, s, r.samples) for f, s, r, m in zip(frames, given, recon, clip.motion) if m.face]
        assert faces and all(f == s == r for f, s, r in faces)


def test_a_stream_without_sample_choices_decodes_none_and_an_encoder_without_them_refuses_one(clip):
    basis = Basis.learn(np.array([m.offsets for m in clip.motion]), 8)
    enc = MotionEncoder(clip.actor, clip.fps, clip.size, basis, Settings(), False, look=True)
    m = clip.motion[0]
    with pytest.raises(InvalidInputError, match="no sample choice"):
        enc.push(m.face, m.lost, m.pose, m.offsets, None, (1, None))
    recon = [enc.push(m.face, m.lost, m.pose, m.offsets, None, (None, None)) for m in clip.motion]
    frames = MotionDecoder(clip.actor).push(enc.header + b"".join(r.data for r in recon) + enc.finish())
    assert frames and all(f.samples is None for f in frames)


def test_an_encoder_whose_hysteresis_would_hold_a_sample_choice_back_refuses_to_send_them(clip):
    basis = Basis.learn(np.array([m.offsets for m in clip.motion]), 8)
    with pytest.raises(InvalidInputError, match=r"hysteresis under 0\.5"):
        MotionEncoder(clip.actor, clip.fps, clip.size, basis, Settings(hysteresis=0.5), False, samples=True)
