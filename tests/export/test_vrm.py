"""``facemime export --out NAME.vrm``: a VRM 1.0 avatar of the actor's head.

The file's JSON has ``VRMC_vrm`` 1.0 with every humanoid bone VRM requires (in the specification's
parent order, the T-pose at rest), the meta, 52 custom expressions bound to their own morph
targets and the four presets; its mesh, texture and targets are the ``.glb``'s; the Khronos glTF
Validator finds no error or warning in it; and three-vrm (npm ``@pixiv/three-vrm``, in headless
Chromium, ``web/test/vrm-page.mjs``) loads it without a warning, knows the 52 names, moves the
mouth as the jawOpen field says and turns the head as a VMC frame of ``facemime live`` says
(a yaw to the subject's left moves the nose to the picture's right).
"""

import base64

import cv2
import numpy as np
import pytest

from cli.test_cli import run
from facemime.animate.arkit import NAMES as ARKIT
from facemime.app.export import export_track
from facemime.export import load_performance
from facemime.export.animation import node_keys
from facemime.export.gltf import accessor_array, read_glb
from facemime.export.vrm import BONES, HEAD_HEIGHT, LICENCE, PRESETS
from facemime.io.actor_file import load_actor
from facemime.live.vmc import unity_quaternion, unity_translation
from facemime.types.pose import Pose, rotation_matrix

from .conftest import WEB
from .test_gltf_valid import validate

#: The humanoid bones VRM 1.0 requires and the bone each hangs from, the optional bones between
#: (chest, upperChest, neck, shoulders) being absent.
REQUIRED = {
    "hips": None,
    "spine": "hips",
    "head": "spine",
    "leftUpperArm": "spine",
    "leftLowerArm": "leftUpperArm",
    "leftHand": "leftLowerArm",
    "rightUpperArm": "spine",
    "rightLowerArm": "rightUpperArm",
    "rightHand": "rightLowerArm",
    "leftUpperLeg": "hips",
    "leftLowerLeg": "leftUpperLeg",
    "leftFoot": "leftLowerLeg",
    "rightUpperLeg": "hips",
    "rightLowerLeg": "rightUpperLeg",
    "rightFoot": "rightLowerLeg",
}
BACKGROUND = (40, 40, 40)


@pytest.fixture(scope="module")
def generic_vrm(generic_export, tmp_path_factory):
    """(track, .vrm, .glb): the synthetic track on the generic head."""
    track, glb = generic_export
    out = tmp_path_factory.mktemp("vrm") / "head.vrm"
    export_track(track, out)
    return track, out, glb


@pytest.fixture(scope="module")
def real_vrm(real_export, tmp_path_factory):
    """(track, .actor, .vrm): lp_d0's track on the actor fitted on its first frame."""
    track, actor, _ = real_export
    out = tmp_path_factory.mktemp("vrm") / "lp_d0.vrm"
    export_track(track, out, actor)
    return track, actor, out


def parents(doc):
    """Each node's parent index (None for a scene root)."""
    up = dict.fromkeys(range(len(doc["nodes"])))
    for k, node in enumerate(doc["nodes"]):
        for child in node.get("children", []):
            assert up[child] is None, f"node {child} has two parents"
            up[child] = k
    return up


def check_vrm(path, glb, perf):
    doc, blob = read_glb(path.read_bytes())
    assert "VRMC_vrm" in doc["extensionsUsed"] and "KHR_materials_unlit" in doc["extensionsUsed"]
    vrm = doc["extensions"]["VRMC_vrm"]
    assert vrm["specVersion"] == "1.0"
    # humanoid: every required bone, each on its own node, hanging from the bone the spec names
    bones = {name: b["node"] for name, b in vrm["humanoid"]["humanBones"].items()}
    assert set(bones) == set(REQUIRED) and len(set(bones.values())) == len(bones)
    up = parents(doc)
    for name, parent in REQUIRED.items():
        if parent is None:
            assert up[bones[name]] in doc["scenes"][0]["nodes"] or up[up[bones[name]]] is None
        else:
            assert up[bones[name]] == bones[parent], name
    # the T-pose: no rotation or scale anywhere at rest; arms along x, the avatar's left at +x
    assert not any("rotation" in n or "scale" in n or "matrix" in n for n in doc["nodes"])
    world = {}
    for k in range(len(doc["nodes"])):
        chain, p = [], k
        while p is not None:
            chain.append(p)
            p = up[p]
        world[k] = sum(np.array(doc["nodes"][c].get("translation", [0.0, 0.0, 0.0])) for c in chain)
    assert world[bones["leftHand"]][0] > world[bones["leftUpperArm"]][0] > 0 > world[bones["rightUpperArm"]][0]
    assert world[bones["head"]][1] > world[bones["spine"]][1] > world[bones["hips"]][1] > world[bones["leftFoot"]][1]
    # the face: one node under the head bone, the .glb's mesh at rest weights 0
    [face] = [k for k, n in enumerate(doc["nodes"]) if "mesh" in n]
    assert up[face] == bones["head"]
    m = perf.metres_per_unit
    assert np.allclose(world[face], world[bones["head"]]) and world[face].tolist() == [0.0, HEAD_HEIGHT, 0.0]
    mesh = doc["meshes"][doc["nodes"][face]["mesh"]]
    assert mesh["weights"] == [0.0] * len(ARKIT) and mesh["extras"]["targetNames"] == list(ARKIT)
    gdoc, gblob = read_glb(glb.read_bytes())
    prim, gprim = mesh["primitives"][0], gdoc["meshes"][0]["primitives"][0]
    for key in ("POSITION", "TEXCOORD_0"):
        assert np.array_equal(
            accessor_array(doc, blob, prim["attributes"][key]), accessor_array(gdoc, gblob, gprim["attributes"][key])
        )
    assert np.array_equal(accessor_array(doc, blob, prim["indices"]), accessor_array(gdoc, gblob, gprim["indices"]))
    for t, gt in zip(prim["targets"], gprim["targets"], strict=True):
        assert np.array_equal(accessor_array(doc, blob, t["POSITION"]), accessor_array(gdoc, gblob, gt["POSITION"]))
    assert doc["materials"] == gdoc["materials"] and len(doc["images"]) == 1
    # expressions: 52 custom ones, each its own target at weight 1; the presets ARKit has
    ex = vrm["expressions"]
    assert list(ex["custom"]) == list(ARKIT)
    for k, name in enumerate(ARKIT):
        assert ex["custom"][name]["morphTargetBinds"] == [{"node": face, "index": k, "weight": 1.0}], name
    assert set(ex["preset"]) == {"blink", "blinkLeft", "blinkRight", "aa"} == set(PRESETS)
    binds = {p: sorted(b["index"] for b in e["morphTargetBinds"]) for p, e in ex["preset"].items()}
    slot = ARKIT.index
    assert binds == {
        "blink": sorted([slot("eyeBlinkLeft"), slot("eyeBlinkRight")]),
        "blinkLeft": [slot("eyeBlinkLeft")],
        "blinkRight": [slot("eyeBlinkRight")],
        "aa": [slot("jawOpen")],
    }
    # meta: the actor's name, facemime, the VRM 1.0 licence, nothing allowed beyond its defaults
    meta = vrm["meta"]
    assert meta["name"] == perf.actor.model.name and meta["authors"] == ["facemime"]
    assert meta["licenseUrl"] == LICENCE
    assert meta["avatarPermission"] == "onlyAuthor" and meta["commercialUsage"] == "personalNonProfit"
    assert not meta["allowRedistribution"] and meta["modification"] == "prohibited"
    # the performance kept: the .glb's keys, on the face's node
    [anim] = doc["animations"]
    paths = {c["target"]["path"]: anim["samplers"][c["sampler"]] for c in anim["channels"]}
    assert {c["target"]["node"] for c in anim["channels"]} == {face}
    translation, rotation, _ = node_keys(perf.poses, m)
    out = accessor_array(doc, blob, paths["translation"]["output"])
    assert np.allclose(out, translation, atol=1e-6)
    assert np.allclose(accessor_array(doc, blob, paths["rotation"]["output"]), rotation, atol=1e-6)
    assert np.allclose(
        accessor_array(doc, blob, paths["weights"]["output"]).reshape(perf.weights.shape), perf.weights, atol=1e-6
    )
    return doc


def test_the_generic_head_becomes_a_vrm_1_avatar(generic_vrm):
    track, vrm, glb = generic_vrm
    check_vrm(vrm, glb, load_performance(track))
    assert [b[0] for b in BONES] == list(REQUIRED)


def test_a_fitted_actor_becomes_a_vrm_1_avatar(real_vrm, real_export):
    track, actor, vrm = real_vrm
    check_vrm(vrm, real_export[2], load_performance(track, load_actor(actor)))


def test_the_cli_writes_a_vrm_by_its_suffix_and_names_both_suffixes(generic_vrm, tmp_path, capsys):
    track, vrm, _ = generic_vrm
    code, out, err = run(capsys, "export", str(track), "--out", str(tmp_path / "Avatar.VRM"))
    assert code == 0 and out.strip() == str(tmp_path / "Avatar.VRM"), err
    assert (tmp_path / "Avatar.VRM").read_bytes() == vrm.read_bytes()
    code, out, err = run(capsys, "export", str(track), "--out", str(tmp_path / "a.vrml"))
    assert code == 1 and out == "" and err.startswith("facemime: error:") and ".glb or .vrm" in err, err
    assert not (tmp_path / "a.vrml").exists()


def test_the_vrm_files_have_no_validation_errors_or_warnings(node, generic_vrm, real_vrm):
    code, reports = validate(node, generic_vrm[1], real_vrm[2])
    for r in reports:
        assert r["errors"] == 0 and r["warnings"] == 0, r["messages"]
        assert r["info"]["hasMorphTargets"] and r["info"]["hasTextures"]
    assert code == 0 and len(reports) == 2


@pytest.fixture(scope="module")
def avatar(browser, node):
    """A page with the three-vrm test page loaded: ``load(vrm bytes)`` then ``pose(frame)``;
    fails at the end on a page error or a warning of three.js or three-vrm."""
    import shutil
    import subprocess

    subprocess.run([shutil.which("npm"), "run", "--silent", "build-vrm-page"], cwd=WEB, check=True)
    context = browser.new_context()
    page = context.new_page()
    errors = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.on(
        "console",
        lambda m: errors.append(m.text) if m.type in ("warning", "error") and "GL Driver" not in m.text else None,
    )
    page.set_content("<!doctype html><html><body></body></html>")
    page.add_script_tag(content=(WEB / ".test-build" / "vrm-page.js").read_text())

    class Avatar:
        def load(self, data: bytes, size=(256, 256)):
            options = {"width": size[0], "height": size[1], "margin": 0.3, "background": list(BACKGROUND)}
            return page.evaluate("([b, o]) => loadVrm(b, o)", [base64.b64encode(data).decode(), options])

        def pose(self, head=(0.0, 0.0, 0.0, 1.0), root=(0.0, 0.0, 0.0), **values):
            frame = {"head": [float(x) for x in head], "root": [float(x) for x in root]}
            frame["values"] = {n: float(values.get(n, 0.0)) for n in (*ARKIT, *PRESETS)}  # the rest 0
            out = page.evaluate("(f) => applyVmc(f)", frame)
            png = np.frombuffer(base64.b64decode(out["png"].split(",", 1)[1]), np.uint8)
            picture = cv2.cvtColor(cv2.imdecode(png, cv2.IMREAD_COLOR), cv2.COLOR_BGR2RGB)
            return picture, np.array(page.evaluate("faceVertices()")), out

        def pixels(self, points):
            return np.array(page.evaluate("(p) => toPixels(p)", np.asarray(points, float).tolist()))

    yield Avatar()
    context.close()
    assert not errors, errors


def test_three_vrm_plays_the_avatar_as_vmc_frames_say(avatar, real_vrm):
    track, actor, vrm = real_vrm
    perf = load_performance(track, load_actor(actor))
    m = perf.metres_per_unit
    info = avatar.load(vrm.read_bytes())
    assert set(info["expressions"]) == set(ARKIT) | set(PRESETS) and len(info["expressions"]) == 56
    assert set(info["bones"]) >= set(REQUIRED) and info["targets"] == list(ARKIT)
    assert info["meta"]["name"] == perf.actor.model.name and info["meta"]["licenseUrl"] == LICENCE
    rest_picture, rest, out = avatar.pose()
    assert out["influences"] == [0.0] * len(ARKIT)
    # at rest the face is the model's, its origin on the head bone
    head = np.array(info["head"])
    model = perf.actor.model.vertices * m
    assert np.allclose(head, [0.0, HEAD_HEIGHT, 0.0]) and np.allclose(rest, model + head, atol=1e-6)

    # jawOpen 1 moves the vertices by the jawOpen field, through the custom expression "jawOpen"
    jaw = ARKIT.index("jawOpen")
    assert perf.fields[jaw].any()
    _, opened, out = avatar.pose(jawOpen=1.0)
    assert out["influences"][jaw] == 1.0 and sum(out["influences"]) == 1.0
    assert np.allclose(opened - rest, perf.fields[jaw] * m, atol=1e-6)
    lips = perf.actor.model.groups["mouth_inner_lower"]
    assert (opened[lips, 1] - rest[lips, 1]).min() < -0.003  # the lower lip drops by millimetres
    _, _, out = avatar.pose(aa=0.5)  # the preset binds the same target
    assert out["influences"][jaw] == 0.5

    # a yaw of 20 degrees to the subject's left, as live sends it: the head turns about its bone
    picture, turned, out = avatar.pose(head=unity_quaternion(Pose(yaw=20)))
    assert np.allclose(turned, head + (rest - head) @ rotation_matrix(yaw=20).T, atol=1e-6)
    nose = perf.actor.model.groups["nose"][np.argmax(model[perf.actor.model.groups["nose"], 2])]
    before, after = avatar.pixels([rest[nose], turned[nose]])
    print(f"nose tip at x {before[0]:.1f} px at rest, {after[0]:.1f} px turned 20 degrees to the subject's left")
    assert after[0] - before[0] > 10  # towards the picture's right
    # in the picture: the patch around the nose tip at rest is found again where the nose tip went
    (x0, y0), (x1, y1) = np.round(before).astype(int).tolist(), np.round(after).astype(int).tolist()
    patch = rest_picture[y0 - 15 : y0 + 16, x0 - 15 : x0 + 16]
    scores = cv2.matchTemplate(picture, patch, cv2.TM_CCOEFF_NORMED)
    found = np.array(cv2.minMaxLoc(scores)[3]) + 15
    print(f"the nose's patch found at {found.tolist()}, the nose tip projected to {[x1, y1]}")
    # the tip stands out of the patch, which moves less: at least half as far, and no further
    assert x0 + (x1 - x0) / 2 < found[0] <= x1 + 2 and abs(found[1] - y1) <= 4

    # any turn: the head bone's rotation in three's axes is the pose's own
    pose = Pose(yaw=-15, pitch=10, roll=12)
    _, posed, out = avatar.pose(head=unity_quaternion(pose))
    assert np.allclose(posed, head + (rest - head) @ rotation_matrix(-15, 10, 12).T, atol=1e-6)
    assert np.allclose(
        np.abs(np.dot(out["head"], node_keys(np.array([[-15, 10, 12, 1, 0, 0]]), 1.0)[1][0])), 1, atol=1e-6
    )

    # the root's translation, Unity's axes: the subject moving image-right moves the avatar to +x
    first = Pose(scale=2.0, tx=100.0, ty=100.0)
    root = unity_translation(Pose(scale=2.0, tx=120.0, ty=90.0), first, m)
    _, moved, _ = avatar.pose(root=root)
    assert np.allclose(moved - rest, [[0.01, 0.005, 0.0]], atol=1e-6)
