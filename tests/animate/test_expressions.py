import json

import numpy as np
import pytest

from facemime.animate.expressions import BLINKS, NAMES, Expressions
from facemime.animate.motion_file import read_motion, weights_to_motion
from facemime.animate.synth import Puppet
from facemime.fit.actor import generic_actor
from facemime.head import generic_head
from facemime.io.contours_json import ContourFileError, track_entry
from facemime.types.pose import Pose

POSE = {"yaw": 4.0, "pitch": -2.0, "roll": 3.0, "scale": 2.4, "tx": 256.0, "ty": 240.0}


@pytest.fixture(scope="module")
def head():
    return generic_head()


@pytest.fixture(scope="module")
def expressions(head):
    return Expressions.of(head)


def knot_sets(head, d):
    g, v = head.groups, head.vertices
    mouth = np.isin(d.knots, np.concatenate([g[n] for n in g if n.startswith("mouth")]))
    brow = np.isin(d.knots, np.concatenate([g[n] for n in g if n.startswith("brow_")]))
    x = v[d.knots, 0]
    return mouth, brow, x


def test_each_control_moves_only_its_region(head, expressions):
    d = expressions.deformer
    mouth, brow, x = knot_sets(head, d)
    eye_y = head.vertices[np.concatenate([head.groups["eye_left"], head.groups["eye_right"]]), 1].mean()
    above = head.vertices[:, 1] > eye_y
    rings = np.concatenate([head.groups["eye_left"], head.groups["eye_right"]])
    for name, pattern, field in zip(expressions.names, expressions.patterns, expressions.fields):
        moved = np.abs(pattern).max(axis=1) > 0
        if name in BLINKS:
            assert not moved.any()
            assert set(np.flatnonzero(np.abs(field).max(axis=1) > 0)) <= set(rings.tolist())
            continue
        assert moved.any(), name
        if name.startswith(("mouth", "jaw")):
            assert not (moved & brow).any(), name
            assert np.abs(field[above]).max() == 0.0, name  # nothing above the eyes
        else:
            assert not (moved & mouth).any(), name
            assert np.abs(field[~above]).max() == 0.0, name  # nothing below the eyes
        # the subject's left is +x: a left control moves no knot beyond the middle on the right
        # (mouthLeft and mouthRight move the whole mouth that way, jawLeft and jawRight the lower lip)
        if name.endswith("Left") and name not in ("mouthLeft", "jawLeft"):
            assert not (moved & (x < -1.0)).any(), name
        if name.endswith("Right") and name not in ("mouthRight", "jawRight"):
            assert not (moved & (x > 1.0)).any(), name
        if name.startswith("jaw") and name != "jawOpen":  # sideways, towards its side: +x the subject's left
            sign = 1.0 if name.endswith("Left") else -1.0
            assert (sign * pattern[moved, 0] > 0).all() and not pattern[:, 1].any(), name
    # the fields are the synthesis's own deformation of the patterns
    k = NAMES.index("jawOpen")
    assert np.allclose(expressions.fields[k, :, :2], d.weights @ expressions.patterns[k])
    assert np.allclose(d.vertices(expressions.patterns[k]), expressions.vertices(np.eye(len(NAMES))[k]))
    # directions: a smile lifts its corner, the jaw lowers the lower lip, a blink closes the lid
    g = head.groups
    corner = list(d.knots).index(g["mouth_outer_upper"][-1])  # image-right: the subject's left
    assert expressions.patterns[NAMES.index("mouthSmileLeft"), corner, 1] > 0
    lip = list(d.knots).index(g["mouth_outer_lower"][5])
    assert expressions.patterns[k, lip, 1] < -0.3 * 51  # 0.70 mouth widths of 51.5 mm
    ring = g["eye_left"]
    closed = head.vertices + expressions.fields[NAMES.index("eyeBlinkLeft")]
    assert np.abs(closed[ring[1:4], 1] - closed[ring[7:4:-1], 1]).max() < 1e-9


def performance(t: int = 100, seed: int = 3) -> np.ndarray:
    """Weights (T, E) that change smoothly, 0.8 at most, the mouth and the jaw never sideways both
    ways."""
    time = np.linspace(0, 4, t)[:, None]
    rng = np.random.default_rng(seed)
    w = np.clip(np.sin(rng.uniform(0.3, 2, len(NAMES)) * time + rng.uniform(0, 6, len(NAMES))), 0, 1) * 0.8
    w[:, [NAMES.index("mouthRight"), NAMES.index("jawRight")]] = 0.0
    return w


def test_solving_offsets_made_from_known_weights_gives_them_back(expressions):
    w = performance()
    offsets, closure = expressions.offsets(w), expressions.closure(w)
    # without the pull to the previous frame: exact (measured 2e-14)
    assert np.abs(expressions.solve(offsets, closure, smooth=0.0) - w).max() < 1e-8
    # with it: weights along nearly collinear patterns are shared otherwise (measured up to 0.45),
    # but the offsets they make stay (measured: 0.0007 IOD mean, 0.011 IOD at most; IOD 90 mm)
    solved = expressions.solve(offsets, closure)
    assert solved.min() >= 0.0 and solved.max() <= 1.0
    error = np.linalg.norm(expressions.offsets(solved) - offsets, axis=2) / 90.0
    assert error.mean() < 0.002 and error.max() < 0.03
    assert np.array_equal(expressions.closure(solved), closure)
    # one frame at a time, as run does, is the same
    solver = expressions.solver()
    assert np.allclose([solver.step(o, c) for o, c in zip(offsets, closure)], solved, atol=1e-12)


def write_track(path, frames, model=None):
    doc = {
        "format": "facemime.track/1",
        "frames": frames,
        "video": {"width": 512, "height": 512, "fps": 25.0, "frames": len(frames)},
    }
    if model is not None:
        doc["model"] = model
    path.write_text(json.dumps(doc))
    return path


def test_weights_round_trip_through_the_track_file_and_bad_ones_are_refused(tmp_path, expressions):
    w = performance(3)
    d = expressions.deformer
    model = {"unit": "mm", "knots": d.knots.tolist(), "feature_sizes": d.feature_sizes().tolist(), "iod": 90.0}
    named = [{n: float(x) for n, x in zip(NAMES, row) if x > 0} for row in w]
    frames = [
        track_entry(
            {"index": i, "contours": {}, "pose": POSE, "offsets": expressions.offsets(w[i]), "weights": named[i]}
        )
        for i in range(3)
    ]
    _, _, motion = read_motion(write_track(tmp_path / "t.json", frames, model))
    assert np.abs(np.array([m["weights"] for m in motion]) - w).max() <= 5e-5  # 4 decimals
    for bad, message in (
        ({"jawOpen": 1.5}, "must be a number in \\[0, 1\\]"),
        ({"smile": 0.2}, "unknown expression"),
        ([0.1, 0.2], "must be an object"),
        ({"jawOpen": "x"}, "must be a number"),
    ):
        frames[1]["weights"] = bad
        with pytest.raises(ContourFileError, match=message) as e:
            read_motion(write_track(tmp_path / "bad.json", frames, model))
        assert "\n" not in str(e.value)


def test_a_performance_written_as_weights_plays_like_its_offsets(tmp_path, expressions):
    w = performance(3)
    w[:, NAMES.index("eyeBlinkLeft")] = [0.0, 0.5, 1.0]
    authored = [
        {"index": i, "pose": POSE, "weights": {n: round(float(x), 4) for n, x in zip(NAMES, row) if x > 0}}
        for i, row in enumerate(w)
    ]
    _video, model, motion = read_motion(write_track(tmp_path / "authored.json", authored))  # no model block
    d = expressions.deformer
    assert model["knots"] == d.knots.tolist()
    w4 = np.round(w, 4)
    offsets = expressions.offsets(w4)
    assert np.allclose([m["offsets"] for m in motion], offsets)
    assert np.allclose([m["look"].closure for m in motion], expressions.closure(w4))
    assert np.allclose(weights_to_motion(w4[1], d.feature_sizes())[0], offsets[1])
    # the same frames as the offsets (and look) written out
    knots = [
        {
            "index": i,
            "pose": POSE,
            "offsets": offsets[i].tolist(),
            "look": {
                "eye_right_closure": float(w4[i, NAMES.index("eyeBlinkRight")]),
                "eye_left_closure": float(w4[i, NAMES.index("eyeBlinkLeft")]),
            },
        }
        for i in range(3)
    ]
    model_block = {"unit": "mm", "knots": d.knots.tolist(), "feature_sizes": d.feature_sizes().tolist(), "iod": 90.0}
    _, _, played = read_motion(write_track(tmp_path / "knots.json", knots, model_block))
    actor = generic_actor()
    puppet = Puppet(actor, np.array(model["feature_sizes"]), float(model["iod"]), Pose(**POSE), mask_only=True)
    for a, b in zip(motion, played):
        pa = puppet.render(Pose(**a["pose"]), a["offsets"], (256, 256), look=a["look"]).copy()
        pb = puppet.render(Pose(**b["pose"]), b["offsets"], (256, 256), look=b["look"])
        assert np.array_equal(pa, pb)
    assert np.abs(motion[2]["offsets"]).max() > 1.0  # the performance does move the face
