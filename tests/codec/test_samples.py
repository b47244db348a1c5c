"""The sample library a stream carries: chosen from the clip, within its budget, drawn where the
frame's shape is the sample's, and stored in actor files compatibly."""

import zipfile
from dataclasses import replace

import cv2
import numpy as np
import pytest

from facemime.animate.deform import Deformer
from facemime.animate.samples import SamplePainter, mouth_knots
from facemime.animate.synth import Puppet
from facemime.app.coding import encode_video
from facemime.codec.decoder import MotionDecoder
from facemime.io.actor_file import ActorFileError, actor_bytes, actor_from_bytes, actor_id
from facemime.io.video import VideoReader
from facemime.types.head import model_iod


@pytest.fixture(scope="module")
def coded(shared, tmp_path_factory):
    """lp_d0 encoded with and without samples: (result, decoder, frames) each."""
    out = {}
    for samples in (True, False):
        path = tmp_path_factory.mktemp("samples") / "lp_d0.fmstream"
        result = encode_video(shared / "video" / "lp_d0.mp4", path, samples=samples)
        decoder = MotionDecoder()
        frames = decoder.push(path.read_bytes()) + decoder.finish()
        out[samples] = (result, decoder, frames)
    return out


def test_the_stream_carries_a_library_of_both_groups_within_30_kB(coded):
    result, decoder, _ = coded[True]
    library = decoder.actor.samples
    assert [g.name for g in library.groups] == ["eyes", "mouth"]
    assert any(i is not None for i in library.group("mouth").interiors)  # she talks: open mouths
    assert 0 < result.samples_bytes <= 30_000
    assert coded[False][1].actor.samples is None and coded[False][0].samples_bytes == 0


def test_a_frame_whose_shape_is_a_samples_draws_that_sample(coded):
    _, decoder, frames = coded[True]
    actor = decoder.actor
    painter = SamplePainter(actor.samples, actor.model.groups, Deformer(actor.model).knots)
    for group in actor.samples.groups:
        for k, index in enumerate(group.frames):
            f = frames[int(index)]
            chosen = painter.choose(f.offsets, f.look)[group.name]
            assert chosen is not None
            assert np.allclose(group.keys[chosen], group.keys[k])  # that sample, or one of the same shape


def _face_psnr(decoder, frames, video, shared):
    actor = decoder.actor
    puppet = Puppet(actor, Deformer(actor.model).feature_sizes(), model_iod(actor.model), decoder.reference())
    w, h = decoder.info.size
    ref = np.load(shared / "video" / "lp_d0.landmarks.npz")
    errors = []
    with VideoReader(video) as reader:
        for i, (real, f) in enumerate(zip(reader, frames)):
            if i % 4 or not ref["valid"][i]:
                continue
            image = puppet.render(f.pose, f.offsets, (w, h), look=f.look, samples=f.samples).astype(np.float64)
            x0, y0 = ref["landmarks"][i][:, :2].min(axis=0).astype(int)
            x1, y1 = ref["landmarks"][i][:, :2].max(axis=0).astype(int)
            errors.append(((image[y0:y1, x0:x1] - real[y0:y1, x0:x1]) ** 2).mean())
    return 10 * np.log10(255.0**2 / np.mean(errors))


def test_the_samples_bring_the_decoded_face_closer_to_the_real_one(coded, shared):
    video = shared / "video" / "lp_d0.mp4"
    with_samples = _face_psnr(coded[True][1], coded[True][2], video, shared)
    without = _face_psnr(coded[False][1], coded[False][2], video, shared)
    assert with_samples > without + 0.5, (with_samples, without)


def test_an_actor_file_keeps_its_samples_and_its_id(coded):
    actor = coded[True][1].actor
    again = actor_from_bytes(actor_bytes(actor), "again")
    for a, b in zip(actor.samples.groups, again.samples.groups):
        assert a.name == b.name and (a.boxes == b.boxes).all() and np.allclose(a.keys, b.keys, atol=1e-6)
        assert all((x == y).all() for s, t in zip(a.images, b.images) for x, y in zip(s, t))  # PNG: lossless
        assert [i is None for i in a.interiors or []] == [i is None for i in b.interiors or []]
        assert all((x == y).all() for x, y in zip(a.interiors or [], b.interiors or []) if x is not None)
    assert actor_id(actor) == actor_id(replace(actor, samples=None))
    assert actor_from_bytes(actor_bytes(replace(actor, samples=None)), "plain").samples is None


def _edited(actor, name, data):
    import io

    src = zipfile.ZipFile(io.BytesIO(actor_bytes(actor)))
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w") as z:
        for info in src.infolist():
            if info.filename != name:
                z.writestr(info, src.read(info))
        if isinstance(data, np.ndarray):
            data = cv2.imencode(".png", data)[1].tobytes()
        if data is not None:
            z.writestr(name, data)
    return buf.getvalue()


@pytest.mark.parametrize(
    ("name", "data", "message"),
    [
        ("samples.json", b"{not json", "samples.json is not valid JSON"),
        ("samples.json", b'{"format": "facemime.samples/9", "groups": []}', "not a 'facemime.samples/1'"),
        ("samples.json", b'{"format": "facemime.samples/1", "groups": [null]}', "an object with its name"),
        (
            "samples.json",
            b'{"format": "facemime.samples/1", "groups": [{"name": "eyes", "boxes": [[0, 0, 4, 4]],'
            b' "samples": [{"frame": 0, "key": [0, 0, 0, 0, 0, 0]}, {"frame": 1, "key": [0]}]}]}',
            "keys differ in length",
        ),
        (
            "samples.json",
            b'{"format": "facemime.samples/1", "groups": [{"name": "eyes", "boxes": [[0, 0, 0, 4]],'
            b' "samples": [{"frame": 0, "key": [0, 0, 0, 0, 0, 0]}]}]}',
            "width and height",
        ),
        ("samples/eyes/0.png", None, "has no image of box 0"),
        ("samples/eyes/0.png", b"not a picture", "is not a PNG image"),
        ("samples/eyes/0.png", b"", "is not a PNG image"),
        ("samples/mouth/interior.png", None, "has no image of its interiors"),
        ("samples/mouth/0.png", np.zeros((7, 5, 3), np.uint8), "is 5x7, not [0-9]+ images of"),
    ],
)
def test_a_damaged_library_is_refused_in_one_line(coded, name, data, message):
    with pytest.raises(ActorFileError, match=message) as e:
        actor_from_bytes(_edited(coded[True][1].actor, name, data), "damaged.actor")
    assert "\n" not in str(e.value) and "damaged.actor" in str(e.value)


def test_the_mouth_is_keyed_by_the_lips_knots_only(actor):
    knots = Deformer(actor.model).knots
    on_lips = mouth_knots(actor.model.groups, knots)
    assert 0 < on_lips.sum() < len(knots)
    assert set(knots[on_lips]) <= set(
        np.concatenate([actor.model.groups[g] for g in actor.model.groups if g.startswith("mouth")])
    )


def test_the_stream_sends_which_sample_each_frame_draws(coded):
    _, decoder, frames = coded[True]
    assert decoder.info.extras[-2:] == (7, 8)
    chosen = [f.samples for f in frames if f.face]
    assert all(c is not None and len(c) == 2 for c in chosen)
    for g, group in enumerate(decoder.actor.samples.groups):
        assert any(c[g] is not None for c in chosen)  # each group's samples are drawn somewhere
        assert all(c[g] is None or c[g] < len(group.keys) for c in chosen)
    assert all(f.samples is None for f in coded[False][2])
