"""Appearance updates: the blend the spec gives, the payload's round trip, and a sender that
sends a changed face, within its budget."""

from dataclasses import replace

import numpy as np
import pytest

from facemime import _core
from facemime.animate.deform import Deformer
from facemime.animate.synth import Puppet
from facemime.codec.appearance import BLEND, CHECK, WINDOW, Appearance, AppearanceSender, Update, parse, paste
from facemime.fit.actor import generic_actor
from facemime.shared_constants import EYES
from facemime.types.head import model_iod
from facemime.types.look import Look
from facemime.types.pose import project


def test_an_update_inside_the_texture_fades_in_over_its_edges():
    texture = np.zeros((64, 64, 3), np.uint8)
    assert paste(texture, Update(0, 10, 20, np.full((30, 40, 3), 240, np.uint8)))
    assert (texture[35, 30] == 240).all()  # 15 texels from the nearest edge: all the update
    assert (texture[20, 30] == round(240 / BLEND)).all()  # on its top edge: weight 1/B
    assert (texture[22, 30] == round(240 * 3 / BLEND)).all()
    assert not texture[19, 30].any() and not texture[35, 9].any()  # beside it: untouched


def test_an_update_at_the_texture_border_does_not_fade_there_and_one_outside_is_refused():
    texture = np.zeros((32, 32, 3), np.uint8)
    assert paste(texture, Update(0, 0, 0, np.full((16, 16, 3), 200, np.uint8)))
    assert (texture[0, 0] == 200).all() and (texture[8, 0] == 200).all()
    assert (texture[15, 3] == round(200 / BLEND)).all()  # its inner edges fade
    texture[:] = 7
    assert not paste(texture, Update(0, 40, 0, np.full((8, 8, 3), 200, np.uint8)))
    assert (texture == 7).all()
    assert paste(texture, Update(0, 28, 28, np.full((8, 8, 3), 200, np.uint8)))  # half outside: its inside
    assert texture[31, 31, 0] > 7


def test_the_payload_round_trips_and_garbage_is_refused():
    yy, xx = np.mgrid[0:24, 0:40]
    image = np.dstack([40 + 4 * xx, 60 + 6 * yy, np.full_like(xx, 120)]).astype(np.uint8)  # smooth: WebP keeps it
    back = parse(Update(123456, 17, 9, image).payload(quality=95))
    assert (back.frame, back.x, back.y) == (123456, 17, 9)
    assert np.abs(back.image.astype(int) - image).mean() < 3
    assert parse(b"\x01\x00\x00\x00\x02\x00\x03\x00not a webp") is None
    assert parse(b"short") is None
    late = Update(2, 0, 0, image[:8, :8]).payload()  # for frame 2, read after 9 frames were out
    receiver = Appearance(
        np.zeros((32, 32, 3), np.uint8), [b"short", Update(5, 0, 0, image[:8, :8]).payload(), late], [0, 0, 9]
    )
    assert receiver.refused == 1 and not receiver.due(4) and receiver.due(5) and receiver.applied == 1
    assert not receiver.due(8) and receiver.due(9) and receiver.applied == 2


@pytest.fixture(scope="module")
def tinted():
    """The generic actor, and its frame as the receiver would draw it but with the left cheek
    (image right) 60 levels redder than the texture the receiver holds."""
    actor = generic_actor((512, 512))
    changed = actor.texture.copy()
    changed[300:380, 300:380, 0] = np.minimum(255, changed[300:380, 300:380, 0].astype(int) + 60)
    puppet = Puppet(actor, Deformer(actor.model).feature_sizes(), model_iod(actor.model), mask_only=True)
    puppet.retexture(changed)
    frame = puppet.render(actor.pose, np.zeros((60, 2)), (512, 512), look=Look()).copy()
    return actor, changed, frame


def test_a_changed_cheek_is_sent_and_nothing_else(tinted):
    actor, _changed, frame = tinted
    sender = AppearanceSender(actor.model, actor.texture, budget=200.0, fps=25.0)
    for i in range(1, CHECK):  # the bucket fills; the face is looked at every CHECK frames only
        assert sender.update(i, frame, actor.model.vertices, actor.pose) is None
    payload = sender.update(CHECK, frame, actor.model.vertices, actor.pose)
    assert payload is not None and parse(payload).frame == CHECK
    red = sender.texture[310:370, 310:370, 0].astype(int) - actor.texture[310:370, 310:370, 0]
    assert red.mean() > 45
    # the eyes are never sent again (their look moves them), and far from the cheek nothing moved
    h, w = actor.texture.shape[:2]
    for e in EYES:
        x, y = (actor.model.uv[actor.model.groups[e]] * [w, h]).mean(axis=0).astype(int)
        assert np.array_equal(sender.texture[y - 3 : y + 4, x - 3 : x + 4], actor.texture[y - 3 : y + 4, x - 3 : x + 4])
    assert sender.update(2 * CHECK, frame, actor.model.vertices, actor.pose) is None  # nothing left to send


def test_the_sender_keeps_to_its_budget(tinted):
    actor, _, frame = tinted
    budget, fps, frames = 2.0, 25.0, 200
    sender = AppearanceSender(actor.model, actor.texture, budget=budget, fps=fps)
    sent = [sender.update(i, frame, actor.model.vertices, actor.pose) for i in range(1, frames + 1)]
    total = sum(len(_core.appearance_chunk(p)) for p in sent if p)  # the chunks, framing and all
    assert 0 < total * 8 <= budget * 1000 * frames / fps
    assert sender.updates == sum(p is not None for p in sent)
    assert WINDOW * budget * 1000 / 8 < 2000  # (a 2 kbit/s bucket holds less than a whole cheek at once)


def test_a_face_whose_cheek_reddens_is_sent_again_through_the_stream(tmp_path):
    """End to end: a video of the astronaut whose cheek is redder than in her actor file is
    encoded for a receiver holding that file, with appearance updates; the decoded video's
    cheek reddens, and without updates it does not."""
    from importlib import resources

    import cv2

    from facemime.animate.synth import key_frame, scene_mesh, synthesize
    from facemime.app.coding import decode_stream, encode_video
    from facemime.codec.decoder import MotionDecoder
    from facemime.fit.actor import fit_actor
    from facemime.io.actor_file import save_actor
    from facemime.io.video import VideoReader, VideoWriter

    data = resources.files("facemime.data").joinpath("astronaut.jpg").read_bytes()
    photo = cv2.cvtColor(cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_COLOR), cv2.COLOR_BGR2RGB)
    photo = cv2.resize(photo[10:250, 105:345], (256, 256), interpolation=cv2.INTER_AREA)
    actor = fit_actor(photo, "astronaut.jpg")[0]
    save_actor(tmp_path / "a.actor", actor)
    h, w = actor.texture.shape[:2]
    g = actor.model.groups
    # the cheek: the model vertex nearest the middle of the right eye and the mouth's corner
    middle = (actor.model.uv[g["eye_right"]].mean(axis=0) + actor.model.uv[g["mouth_outer_upper"][0]]) / 2
    taken = np.concatenate([g[n] for n in ("eye_right", "nose", "mouth_outer_upper", "mouth_outer_lower")])
    free = np.setdiff1d(np.arange(len(actor.model.uv)), taken)
    cheek = free[np.argmin(np.linalg.norm(actor.model.uv[free] - middle, axis=1))]
    tx, ty = np.round(actor.model.uv[cheek] * [w, h]).astype(int)
    x0, x1, y0, y1 = tx - 16, tx + 17, ty - 16, ty + 17  # a patch of light, larger than the smoothing
    red = actor.texture.copy()
    red[y0:y1, x0:x1, 1:] = np.maximum(0, red[y0:y1, x0:x1, 1:].astype(int) - 60)  # redder, not brighter
    tinted = replace(actor, texture=red)
    scene = scene_mesh(actor)
    key = key_frame(actor, scene)
    with VideoWriter(tmp_path / "v.mp4", 25.0) as writer:
        writer.write(synthesize(actor, actor.model.vertices, actor.pose, (256, 256), scene=scene, key=key))
        for _ in range(39):
            writer.write(synthesize(tinted, actor.model.vertices, actor.pose, (256, 256), scene=scene, key=key))
    still = np.round(project(actor.model.vertices[[cheek]], actor.pose)[0][0]).astype(int)

    def drawn_cheek(stream):
        """Where the receiver draws the cheek on frames 1 and -1: the motion measured on the
        video moves it a little (the actor's own mouth, closed in its mesh, is tracked there)."""
        decoder = MotionDecoder(actor=actor)
        frames = decoder.push(stream.read_bytes()) + decoder.finish()
        model = decoder.actor.model
        puppet = Puppet(decoder.actor, Deformer(model).feature_sizes(), model_iod(model), decoder.reference())
        spots = []
        for f in (frames[1], frames[-1]):
            puppet.render(f.pose, f.offsets, decoder.info.size)
            vertices, pose = puppet.shown
            spots.append(np.round(project(vertices[[cheek]], pose)[0][0]).astype(int))
        return spots

    def redness(video, spots):
        frames = list(VideoReader(video))
        return [
            float((f[cy - 3 : cy + 4, cx - 3 : cx + 4].astype(float) @ [1.0, -0.5, -0.5]).mean())
            for f, (cx, cy) in zip((frames[1], frames[-1]), spots)
        ]

    source = redness(tmp_path / "v.mp4", [still, still])
    for budget, name in ((16.0, "with"), (0.0, "without")):
        result = encode_video(
            tmp_path / "v.mp4", tmp_path / f"{name}.fmstream", tmp_path / "a.actor", appearance=budget
        )
        assert (result.appearance_updates > 0) == (budget > 0)
        assert result.appearance_kbit_s <= budget + 1e-9
        decoded = decode_stream(tmp_path / f"{name}.fmstream", tmp_path / f"{name}.mp4", tmp_path / "a.actor")
        assert decoded.appearance_updates == result.appearance_updates and decoded.appearance_refused == 0
    spots = drawn_cheek(tmp_path / "without.fmstream")
    with_, without = redness(tmp_path / "with.mp4", spots), redness(tmp_path / "without.mp4", spots)
    assert source[1] > without[1] + 30  # the held texture's cheek is not as red as the video's
    assert with_[0] < without[0] + 10  # no update before frame 5 (the first one looked at)
    # sent again, it reddens: measured 0.60 of the source's redness (0.75 before the actor's mesh
    # closed her open smile with her own teeth, fit.actor.mouth_cap: the video then showed drawn
    # ones, on whose edges the tracked mouth, and with it the cheek, moved less)
    assert with_[1] - without[1] > 0.5 * (source[1] - without[1])
