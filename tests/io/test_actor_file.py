"""``.actor`` files round-trip exactly and refuse anything corrupt, foreign or hostile."""

import json
import pickle
import zipfile

import numpy as np
import pytest

from facemime.errors import InputFileError
from facemime.io.actor_file import ActorFileError, load_actor, save_actor
from facemime.io.outputs import OutputExistsError


def test_round_trip_is_exact(tmp_path, actor):
    path = save_actor(tmp_path / "a.actor", actor)
    back = load_actor(path)
    for a, b in (
        (back.model.vertices, actor.model.vertices),
        (back.model.uv, actor.model.uv),
        (back.model.triangles, actor.model.triangles),
        (back.texture, actor.texture),
    ):
        np.testing.assert_array_equal(a, b)
        assert a.dtype == b.dtype
    assert back.pose == actor.pose and back.source == actor.source
    assert back.model.groups.keys() == actor.model.groups.keys()
    assert all(np.array_equal(back.model.units[k], actor.model.units[k]) for k in actor.model.units)
    assert all(np.array_equal(back.points[k], actor.points[k]) for k in actor.points)


def test_an_existing_file_is_not_overwritten(tmp_path, actor):
    path = save_actor(tmp_path / "a.actor", actor)
    before = path.read_bytes()
    with pytest.raises(OutputExistsError, match="use --force"):
        save_actor(path, actor)
    assert path.read_bytes() == before
    save_actor(path, actor, force=True)


def write(path, data):
    path.write_bytes(data)
    return path


def rewrite(src, dst, change):
    """Copy an actor file, passing (name, bytes) of each member through ``change``."""
    with zipfile.ZipFile(src) as z, zipfile.ZipFile(dst, "w") as out:
        for info in z.infolist():
            item = change(info.filename, z.read(info))
            if item is not None:
                out.writestr(*item)
    return dst


def edit_json(edit):
    def change(name, data):
        if name != "actor.json":
            return name, data
        doc = json.loads(data)
        edit(doc)
        return name, json.dumps(doc)

    return change


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda p, d: write(d, p.read_bytes()[: len(p.read_bytes()) // 2]), "not a facemime actor file, or truncated"),
        (lambda p, d: write(d, b"hello"), "not a facemime actor file"),
        (lambda p, d: write(d, pickle.dumps({"x": 1})), "not a facemime actor file"),
        (lambda p, d: rewrite(p, d, lambda n, b: None if n == "texture.png" else (n, b)), "no texture.png inside"),
        (
            lambda p, d: rewrite(p, d, edit_json(lambda doc: doc.update(format="facemime.actor/9"))),
            "a newer facemime wrote it",
        ),
        (
            lambda p, d: rewrite(p, d, edit_json(lambda doc: doc.update(format="something else"))),
            "expected format 'facemime.actor/1'",
        ),
        (lambda p, d: rewrite(p, d, edit_json(lambda doc: doc["model"]["uv"].pop())), r"uv must have shape \(120, 2\)"),
        (
            lambda p, d: rewrite(p, d, edit_json(lambda doc: doc["model"]["triangles"][0].__setitem__(0, 999))),
            "uses vertex 999",
        ),
        (lambda p, d: rewrite(p, d, edit_json(lambda doc: doc["texture"].update(width=3))), "but actor.json says"),
        (lambda p, d: rewrite(p, d, edit_json(lambda doc: doc["pose"].update(scale=-1))), "malformed actor"),
        (
            lambda p, d: rewrite(p, d, lambda n, b: (n, b"not a png") if n == "texture.png" else (n, b)),
            "texture.png is not a PNG",
        ),
        (
            lambda p, d: rewrite(p, d, lambda n, b: (n, b"{]") if n == "actor.json" else (n, b)),
            "actor.json is not valid JSON",
        ),
    ],
)
def test_bad_files_are_refused_with_a_message(tmp_path, actor, make, message):
    good = save_actor(tmp_path / "good.actor", actor)
    bad = make(good, tmp_path / "bad.actor")
    with pytest.raises(ActorFileError, match=message):
        load_actor(bad)


def test_oversized_members_are_refused_before_reading(tmp_path, monkeypatch, actor):
    import facemime.io.actor_file as actor_file

    path = save_actor(tmp_path / "a.actor", actor)
    monkeypatch.setattr(actor_file, "MAX_TEXTURE_BYTES", 1000)
    with pytest.raises(ActorFileError, match=r"texture.png is .* bytes, more than the 1000 allowed"):
        load_actor(path)


def test_missing_file(tmp_path):
    with pytest.raises(InputFileError, match=r"actor file .*nope.actor does not exist"):
        load_actor(tmp_path / "nope.actor")


def test_the_scene_round_trips_and_is_the_whole_source_picture(tmp_path, actor, lp_d0):
    frame = lp_d0[0]
    np.testing.assert_array_equal(actor.scene, frame)
    back = load_actor(save_actor(tmp_path / "a.actor", actor))
    assert back.scene.shape == actor.scene.shape == (512, 512, 3) and back.scene.dtype == np.uint8
    np.testing.assert_array_equal(back.scene, actor.scene)
    with zipfile.ZipFile(tmp_path / "a.actor") as z:
        assert sorted(z.namelist()) == ["actor.json", "scene.png", "texture.png"]
        assert json.loads(z.read("actor.json"))["scene"] == {"width": 512, "height": 512}


def test_a_file_without_a_scene_loads_and_shows_the_face_alone(tmp_path, actor):
    from dataclasses import replace

    from facemime.animate.synth import Puppet
    from facemime.shared_constants import BACKGROUND
    from facemime.types.head import model_iod

    path = save_actor(tmp_path / "old.actor", replace(actor, scene=None))
    with zipfile.ZipFile(path) as z:
        assert sorted(z.namelist()) == ["actor.json", "texture.png"]
        assert "scene" not in json.loads(z.read("actor.json"))
    old = load_actor(path)
    assert old.scene is None
    sizes = Puppet(actor, np.ones(60), 1.0).deformer.feature_sizes()
    frames = {}
    for name, who in (("old", old), ("scene", actor)):
        puppet = Puppet(who, sizes, model_iod(actor.model), actor.pose)
        frames[name] = puppet.render(actor.pose, np.zeros((60, 2)), (512, 512))
    corners = (slice(0, 40), slice(0, 40)), (slice(0, 40), slice(-40, None)), (slice(-40, None), slice(0, 40))
    for corner in corners:
        assert (frames["old"][corner] == BACKGROUND).all()
        np.testing.assert_array_equal(frames["scene"][corner], actor.scene[corner])
    face = (slice(200, 300), slice(200, 300))
    assert np.abs(frames["old"][face].astype(int) - frames["scene"][face]).mean() < 2


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda n, b: None if n == "scene.png" else (n, b), "disagree on whether it has a scene"),
        (edit_json(lambda doc: doc.pop("scene")), "disagree on whether it has a scene"),
        (edit_json(lambda doc: doc["scene"].update(height=500)), "scene is 512x512, but actor.json says"),
        (lambda n, b: (n, b"not a png") if n == "scene.png" else (n, b), "scene.png is not a PNG"),
    ],
)
def test_a_file_whose_scene_and_actor_json_disagree_is_refused(tmp_path, actor, change, message):
    bad = rewrite(save_actor(tmp_path / "good.actor", actor), tmp_path / "bad.actor", change)
    with pytest.raises(ActorFileError, match=message) as e:
        load_actor(bad)
    assert "\n" not in str(e.value) and str(bad) in str(e.value)


@pytest.mark.parametrize(
    "source, message",
    [
        ({"width": 10**6, "height": 10**6}, "more than 100000000 pixels"),
        ({"width": 512, "height": 900}, "not its source picture"),
        ({"width": 256, "height": 256}, "not its source picture"),
        ({"width": "512", "height": 512}, "needs its source picture's width and height"),
    ],
)
def test_a_scene_whose_source_picture_is_huge_or_of_another_shape_is_refused(actor, tmp_path, source, message):
    """The scene is drawn at its source picture's size: a forged size would make it allocate
    without bound, or stretch it out of shape."""
    import io

    from facemime.io.actor_file import actor_bytes

    path = tmp_path / "forged.actor"
    with zipfile.ZipFile(io.BytesIO(actor_bytes(actor))) as z, zipfile.ZipFile(path, "w") as out:
        for name in z.namelist():
            data = z.read(name)
            if name == "actor.json":
                doc = json.loads(data)
                doc["source"].update(source)
                data = json.dumps(doc).encode()
            out.writestr(name, data)
    with pytest.raises(ActorFileError, match=message) as e:
        load_actor(path)
    assert "\n" not in str(e.value) and str(path) in str(e.value)


def test_the_same_actor_gives_the_same_bytes_whenever_it_is_written(monkeypatch):
    # An actor embedded in a stream is part of its bytes: encoding a video twice gives one file.
    import time

    from facemime.fit.actor import generic_actor
    from facemime.io.actor_file import actor_bytes

    actor = generic_actor((64, 64))
    monkeypatch.setattr(time, "time", lambda: 1.0e9)
    first = actor_bytes(actor)
    monkeypatch.setattr(time, "time", lambda: 1.7e9)
    assert actor_bytes(actor) == first
