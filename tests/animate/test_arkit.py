"""ARKit's 52 blendshapes: the names, how the measures map to them, and what they show on renders
of known expressions and on real clips against the Face Mesh references."""

import numpy as np
import pytest

from facemime.animate.analysis import Analysis, analysed
from facemime.animate.arkit import (
    BLINK_FROM,
    BLINK_TO,
    LID_FROM,
    LID_HOLD,
    LID_TO,
    LOOK_DOWN,
    LOOK_SIDE,
    LOOKS,
    NAMES,
    UNMEASURED,
    ArkitSolver,
    arkit_values,
    blinks,
    looks,
)
from facemime.animate.expressions import NAMES as CONTROLS
from facemime.animate.expressions import Expressions
from facemime.animate.synth import key_frame, scene_mesh, synthesize
from facemime.fit.actor import fit_actor
from facemime.io.photo import read_photo
from facemime.io.video import VideoReader
from facemime.metrics import reference_eyes


def test_all_52_names_once_the_controls_under_their_own_and_the_unmeasured_apart():
    assert len(NAMES) == 52 == len(set(NAMES))
    assert set(CONTROLS) <= set(NAMES) and set(UNMEASURED) <= set(NAMES) and set(LOOKS) <= set(NAMES)
    assert not set(UNMEASURED) & (set(CONTROLS) | set(LOOKS))
    assert len(CONTROLS) + len(LOOKS) + len(UNMEASURED) == 52  # every name is one of the three
    assert all(n.endswith(("Left", "Right")) for n in LOOKS) and len(LOOKS) == 8


def test_the_look_directions_are_the_subjects_own():
    # both irises to the image's right: the right eye (image-left) looks in, the left eye out
    right = looks(np.array([[LOOK_SIDE / 2, 0.0], [LOOK_SIDE / 2, 0.0]]))
    assert right["eyeLookInRight"] == pytest.approx(0.5) and right["eyeLookOutLeft"] == pytest.approx(0.5)
    assert right["eyeLookOutRight"] == right["eyeLookInLeft"] == 0.0
    down = looks(np.array([[0.0, 2 * LOOK_DOWN], [0.0, -0.01]]))  # beyond a full look: 1
    assert down["eyeLookDownRight"] == 1.0 and down["eyeLookUpRight"] == 0.0 and down["eyeLookUpLeft"] > 0.0


def test_a_blink_is_a_ramp_of_the_closure_and_the_landmarks_count_where_measured():
    assert blinks(np.array([BLINK_FROM, BLINK_TO])).tolist() == [0.0, 1.0]
    mid = (BLINK_FROM + BLINK_TO) / 2
    assert blinks(np.array([mid, -0.2])) == pytest.approx([0.5, 0.0])
    # the landmarks read an eye open while the eye tracker reads it half shut (a look down): no blink
    assert blinks(np.array([0.5, 0.5]), np.array([0.0, np.nan])).tolist() == [0.0, blinks(np.array([0.5]))[0]]


def test_where_the_eye_model_looked_its_closure_makes_the_blink():
    # both quick measures read the eyes shut; the eye model reads the right one half open (a
    # look down) and did not look at the left: the left keeps the quick measures' blink
    quick = blinks(np.array([0.9, 0.9]), np.array([0.4, 0.4]))
    assert quick.tolist() == [1.0, 1.0]
    assert blinks(np.array([0.9, 0.9]), np.array([0.4, 0.4]), np.array([0.3, np.nan])).tolist() == [0.0, 1.0]
    mid = (LID_FROM + LID_TO) / 2
    assert blinks(np.zeros(2), None, np.array([mid, LID_TO])) == pytest.approx([0.5, 1.0])
    # an eye that blinked on the frame before stays shut down to LID_HOLD less closure
    lid = np.full(2, LID_TO - LID_HOLD)
    held = blinks(np.zeros(2), None, lid, np.array([True, False]))
    assert held == pytest.approx([1.0, 1.0 - LID_HOLD / (LID_TO - LID_FROM)])


def test_opposite_controls_show_their_difference_and_the_unmeasured_are_zero():
    w = np.zeros(len(CONTROLS))
    w[CONTROLS.index("mouthLeft")], w[CONTROLS.index("mouthRight")] = 0.3, 0.1
    w[CONTROLS.index("jawRight")] = 0.4
    w[CONTROLS.index("browInnerUp")] = 0.7
    v = dict(zip(NAMES, arkit_values(w, np.zeros((2, 2)))))
    assert v["mouthLeft"] == pytest.approx(0.2) and v["mouthRight"] == 0.0
    assert v["jawRight"] == pytest.approx(0.4) and v["browInnerUp"] == pytest.approx(0.7)
    assert all(v[n] == 0.0 for n in UNMEASURED)


def test_rendered_expressions_are_measured_as_rendered(shared):
    """The actor of a shared photo (closed lips) rendered with known controls: the lower lip to
    her left, then to her right, then a smile and raised brows, each held, neutral between."""
    actor = fit_actor(read_photo(shared / "photos" / "lp_s42.jpg"), "lp_s42.jpg")[0]
    scene, ex = scene_mesh(actor), Expressions.of(actor.model)
    key = key_frame(actor, scene)

    def weights(**named):
        w = np.zeros(len(CONTROLS))
        for name, x in named.items():
            w[CONTROLS.index(name)] = x
        return w

    held = 4
    script = (
        [weights()] * 3
        + [weights(jawLeft=k / 3) for k in (1, 2)]
        + [weights(jawLeft=1.0)] * held
        + [weights()] * 3
        + [weights(jawRight=1.0)] * held
        + [weights()] * 3
        + [weights(mouthSmileLeft=1.0, browInnerUp=1.0)] * held
    )
    frames = [synthesize(actor, ex.vertices(w), actor.pose, (512, 512), scene=scene, key=key) for w in script]
    analysis = Analysis(frames[0], "rendered", fps=25)
    solver = ArkitSolver(analysis.actor.model)
    values = [solver.step(analysis.last.offsets, analysis.last.look)]
    values += [solver.step(m.offsets, m.look, m.landmark_closure) for m in map(analysis.update, frames[1:])]
    v = {n: np.array(values)[:, k] for k, n in enumerate(NAMES)}
    jaw_left, jaw_right, smile = slice(5, 9), slice(12, 16), slice(19, 23)
    # measured: jawLeft 0.63-0.72 (jawRight 0), jawRight 0.27-0.40 (jawLeft 0), browInnerUp 0.61-0.75
    # and mouthSmileLeft 0.17-0.24 (the smile's corner lift is shared with the brows' frame's noise)
    assert v["jawLeft"][jaw_left].min() > 0.45 and v["jawRight"][jaw_left].max() < 0.05
    assert v["jawRight"][jaw_right].min() > 0.15 and v["jawLeft"][jaw_right].max() < 0.05
    assert v["browInnerUp"][smile].min() > 0.4 and v["mouthSmileLeft"][smile].min() > 0.1
    assert v["mouthSmileRight"][smile].max() < v["mouthSmileLeft"][smile].min()
    assert max(v[n].max() for n in UNMEASURED) == 0.0


def _clip_values(path):
    with VideoReader(path) as reader:
        solver, out = None, []
        for _, analysis, motion in analysed(reader, path.name, fps=reader.fps, eye_model=True):
            solver = solver or ArkitSolver(analysis.actor.model)
            m = motion
            out.append(solver.step(m.offsets, m.look, m.landmark_closure, m.landmark_jaw, m.lid_closure))
    return {n: np.array(out)[:, k] for k, n in enumerate(NAMES)}


@pytest.fixture(scope="module")
def lp_d3(shared):
    """lp_d3's values, and its reference landmarks."""
    return _clip_values(shared / "video" / "lp_d3.mp4"), np.load(shared / "video" / "lp_d3.landmarks.npz")["landmarks"]


def test_blinks_are_told_apart_from_looking_down_on_a_real_clip(lp_d3):
    """lp_d3 winks, shuts her eyes and looks down; the reference's lids mark the frames: shut
    (opening under 0.35 of frame 0's) and open, looking down (over 0.6, the iris 0.04 eye widths
    down)."""
    v, landmarks = lp_d3
    opening, iris = reference_eyes(landmarks)
    shut_values, down_values = [], []
    for eye, side in ((0, "Right"), (1, "Left")):
        blink = v[f"eyeBlink{side}"][: len(opening)]
        shut_values.append(blink[opening[:, eye] < 0.35])
        down_values.append(blink[(opening[:, eye] > 0.6) & (iris[:, eye, 1] > 0.04)])
    shut, down = np.concatenate(shut_values), np.concatenate(down_values)
    assert len(shut) > 200 and len(down) > 50
    # measured: 234 of 244 shut eye-frames above 0.5 (median 1), all 76 looking down below 0.2
    # (median 0); the quick measures alone gave 240 of 244 and 41 of 76
    assert np.mean(shut > 0.5) > 0.9 and np.median(shut) > 0.9
    assert np.mean(down < 0.2) > 0.95 and np.median(down) < 0.05


def test_the_jaw_opens_as_the_reference_mouth_does_on_a_real_clip(lp_d3):
    """lp_d3 ends on a wide "O": jawOpen, from the landmarks' chin, follows the gap between the
    reference's inner lips (the lips' solve alone put the opening in mouthLowerDown: jawOpen at
    most 0.025, correlation -0.02)."""
    v, landmarks = lp_d3
    n = min(len(landmarks), len(v["jawOpen"]))
    p = landmarks[:n, :, :2].astype(np.float64)
    gap = np.linalg.norm(p[:, 13] - p[:, 14], axis=1) / np.linalg.norm(p[:, 33] - p[:, 263], axis=1)
    jaw = v["jawOpen"][:n]
    # measured: correlation 0.94, jawOpen up to 0.56
    assert np.corrcoef(jaw, gap)[0, 1] > 0.85 and 0.3 < jaw.max() < 0.9
    assert np.median(jaw[gap < np.percentile(gap, 20)]) < 0.1  # closed, no jaw


def test_the_eyes_look_where_the_reference_looks_on_a_real_clip(shared):
    """lp_d0 glances sideways: the eyes' look across follows the reference iris's shift."""
    v = _clip_values(shared / "video" / "lp_d0.mp4")
    _, iris = reference_eyes(np.load(shared / "video" / "lp_d0.landmarks.npz")["landmarks"])
    n = min(len(iris), len(v["eyeLookInRight"]))
    across_right = v["eyeLookInRight"][:n] - v["eyeLookOutRight"][:n]  # towards image-right
    across_left = v["eyeLookOutLeft"][:n] - v["eyeLookInLeft"][:n]
    # measured: 0.96 and 0.91
    assert np.corrcoef(across_right, iris[:n, 0, 0])[0, 1] > 0.85
    assert np.corrcoef(across_left, iris[:n, 1, 0])[0, 1] > 0.8
