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
    for a, b in ((back.model.vertices, actor.model.vertices), (back.model.uv, actor.model.uv),
                 (back.model.triangles, actor.model.triangles), (back.texture, actor.texture)):
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


@pytest.mark.parametrize(("make", "message"), [
    (lambda p, d: write(d, p.read_bytes()[: len(p.read_bytes()) // 2]), "not a facemime actor file, or truncated"),
    (lambda p, d: write(d, b"hello"), "not a facemime actor file"),
    (lambda p, d: write(d, pickle.dumps({"x": 1})), "not a facemime actor file"),
    (lambda p, d: rewrite(p, d, lambda n, b: None if n == "texture.png" else (n, b)), "no texture.png inside"),
    (lambda p, d: rewrite(p, d, edit_json(lambda doc: doc.update(format="facemime.actor/9"))), "a newer facemime wrote it"),
    (lambda p, d: rewrite(p, d, edit_json(lambda doc: doc.update(format="something else"))), "expected format 'facemime.actor/1'"),
    (lambda p, d: rewrite(p, d, edit_json(lambda doc: doc["model"]["uv"].pop())), r"uv must have shape \(120, 2\)"),
    (lambda p, d: rewrite(p, d, edit_json(lambda doc: doc["model"]["triangles"][0].__setitem__(0, 999))), "uses vertex 999"),
    (lambda p, d: rewrite(p, d, edit_json(lambda doc: doc["texture"].update(width=3))), "but actor.json says"),
    (lambda p, d: rewrite(p, d, edit_json(lambda doc: doc["pose"].update(scale=-1))), "malformed actor"),
    (lambda p, d: rewrite(p, d, lambda n, b: (n, b"not a png") if n == "texture.png" else (n, b)), "texture.png is not a PNG"),
    (lambda p, d: rewrite(p, d, lambda n, b: (n, b"{]") if n == "actor.json" else (n, b)), "actor.json is not valid JSON"),
])
def test_bad_files_are_refused_with_a_message(tmp_path, actor, make, message):
    good = save_actor(tmp_path / "good.actor", actor)
    bad = make(good, tmp_path / "bad.actor")
    with pytest.raises(ActorFileError, match=message):
        load_actor(bad)


def test_oversized_members_are_refused_before_reading(tmp_path, monkeypatch, actor):
    import facemime.io.actor_file as actor_file

    path = save_actor(tmp_path / "a.actor", actor)
    monkeypatch.setattr(actor_file, "MAX_TEXTURE_BYTES", 1000)
    with pytest.raises(ActorFileError, match="texture.png is .* bytes, more than the 1000 allowed"):
        load_actor(path)


def test_missing_file(tmp_path):
    with pytest.raises(InputFileError, match="actor file .*nope.actor does not exist"):
        load_actor(tmp_path / "nope.actor")
