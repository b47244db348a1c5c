import numpy as np
import pytest

from facemime.animate.synth import Puppet, UserMotion, draw_mouth_interior, synthesize, teeth_uncovered
from facemime.errors import InvalidInputError
from facemime.shared_constants import SEAL
from facemime.types.head import model_iod
from facemime.types.pose import project

GREEN = (0, 255, 0)


def mouth_polygon_mask(points, actor, shape):
    import cv2

    g = actor.model.groups
    poly = np.concatenate([points[g["mouth_inner_upper"]], points[g["mouth_inner_lower"]][::-1]])
    mask = np.zeros(shape, np.uint8)
    cv2.fillPoly(mask, [np.round(poly).astype(np.int32)], 1)
    return cv2.erode(mask, np.ones((3, 3), np.uint8)).astype(bool)


def test_an_open_mouth_shows_a_dark_cavity_and_teeth_not_the_background(actor):
    vertices = actor.model.deform({"jawOpen": 0.33})
    img = synthesize(actor, vertices, actor.pose, (512, 512), background=GREEN)
    inside = mouth_polygon_mask(project(vertices, actor.pose)[0], actor, img.shape[:2])
    assert inside.sum() > 300
    pixels = img[inside].astype(int)
    assert not (np.abs(pixels - GREEN).sum(axis=1) < 60).any()
    brightness = pixels.mean(axis=1)
    assert (brightness < 60).mean() > 0.2  # the cavity
    assert (brightness > 150).mean() > 0.1  # the teeth


def test_a_closed_mouth_only_fills_the_sliver_between_the_lips(actor):
    from facemime.render.head_view import render_head

    plain = render_head(actor.model, actor.texture, actor.pose, (512, 512), background=GREEN)
    synth = synthesize(actor, actor.model.vertices, actor.pose, (512, 512), background=GREEN)
    changed = np.abs(synth.astype(int) - plain).max(axis=2) > 1
    # Only pixels where the background leaked between the lips change.
    assert changed.sum() < 30 and (plain[changed] == GREEN).all()


@pytest.mark.parametrize("gap", [0.3, 1.0, 2.0])
def test_lips_barely_apart_show_a_dark_line_and_no_teeth(gap):
    # A 70 px mouth whose inner lips are a few pixels apart: a real one shows the dark gap
    # between the lips; a bright line of teeth there cost the synthesis 3-6 dB on real videos.
    x = np.linspace(100.0, 170.0, 9)
    arch = gap * np.sin(np.linspace(0.0, np.pi, 9))
    upper = np.column_stack([x, 80.0 - arch / 2])
    lower = np.column_stack([x, 80.0 + arch / 2])
    out = np.full((160, 260, 3), 120, np.uint8)
    draw_mouth_interior(out, upper, lower)
    changed = (out != 120).any(axis=2)
    assert changed.any()
    assert out[changed].max() <= 120  # darker than the lips around it: no teeth


def test_teeth_meet_in_a_grin_and_the_cavity_shows_once_the_mouth_opens_wide():
    # A 100 px mouth: a grin's opening is filled by the teeth (a dark band there cost the
    # synthesis about 1 dB on a grinning face); a wide-open mouth shows the cavity between them.
    x = np.linspace(100.0, 200.0, 11)
    arch = np.sin(np.linspace(0.0, np.pi, 11))

    def middle_column(opening):
        out = np.full((200, 300, 3), 120, np.uint8)
        draw_mouth_interior(
            out, np.column_stack([x, 80.0 - 0.4 * opening * arch]), np.column_stack([x, 80.0 + 0.6 * opening * arch])
        )
        column = out[:, 155].astype(int).mean(axis=1)  # between two gaps of the teeth
        return column[column != 120]

    grin = middle_column(14.0)
    assert len(grin) >= 12 and not (grin < 60).any()
    wide = middle_column(40.0)
    assert (wide < 60).sum() >= 15 and (wide > 150).sum() >= 12


def test_lips_cover_the_teeth_unless_the_mouth_spreads(actor):
    # Talking or an "O" shows the dark cavity under the edge of the upper teeth; a smile, whose
    # corners spread, uncovers both rows (measured: +0.6 dB in the mouth on lp_d3).
    def teeth_rows(weights):
        vertices = actor.model.deform(weights)
        img = synthesize(actor, vertices, actor.pose, (512, 512), background=GREEN)
        inside = mouth_polygon_mask(project(vertices, actor.pose)[0], actor, img.shape[:2])
        ys = np.nonzero(inside)[0]
        middle = (ys.min() + ys.max()) / 2
        bright = inside & (img.astype(int).mean(axis=2) > 150)
        rows = np.nonzero(bright)[0]
        return (rows < middle).sum(), (rows > middle).sum(), inside.sum()

    o_upper, o_lower, o_area = teeth_rows({"jawOpen": 0.33, "mouthPucker": 0.52})  # corners at 0.77 of rest
    assert o_upper > 0.02 * o_area and o_lower == 0
    _, open_lower, _ = teeth_rows({"jawOpen": 0.33})
    stretch = {"mouthStretchLeft": 0.23, "mouthStretchRight": 0.23}
    s_upper, s_lower, s_area = teeth_rows({"jawOpen": 0.33, **stretch})  # corners at 1.23 of rest
    assert s_upper > 0.05 * s_area and s_lower > 0.02 * s_area and 0 < open_lower < s_lower
    assert teeth_uncovered(0.85) == 0.0 and teeth_uncovered(1.2) == 1.0 and 0.0 < teeth_uncovered(1.0) < 1.0


def test_lips_all_but_touching_are_shown_closed_and_an_opening_mouth_grows_smoothly(actor):
    puppet = Puppet(actor, Puppet(actor, np.ones(60), 1.0).deformer.feature_sizes(), model_iod(actor.model))
    d, g = puppet.deformer, actor.model.groups
    upper, lower = g["mouth_inner_upper"][1:-1], g["mouth_inner_lower"][1:-1]
    width = np.ptp(actor.model.vertices[g["mouth_outer_upper"][[0, -1]], 0])
    lower_knots = np.isin(d.knots, lower)

    def gap(opening):  # the shown gap at the middle of the lips, model units
        offsets = np.zeros((len(d.knots), 2))
        offsets[lower_knots, 1] = -opening
        v = puppet.vertices(offsets)
        return float(np.median(v[upper, 1] - v[lower, 1]))

    rest = float(np.median(actor.model.vertices[upper, 1] - actor.model.vertices[lower, 1]))
    small = 0.5 * SEAL * width - rest
    assert gap(small) == pytest.approx(0.0, abs=1e-3 * width)
    wide = 3.0 * SEAL * width - rest
    assert gap(wide) == pytest.approx(wide + rest, abs=1e-3 * width)
    openings = np.linspace(small, wide, 40)
    shown = [gap(o) for o in openings]
    assert (np.diff(shown) >= -1e-9).all() and np.abs(np.diff(shown)).max() < 4.0 * (openings[1] - openings[0])


def test_motion_carries_to_a_face_of_other_proportions(actor):
    from dataclasses import replace

    wide = actor.model.vertices.copy()
    wide[:, 0] *= 1.3  # a wider face: wider mouth and brows, wider-set eyes
    other = replace(actor, model=replace(actor.model, vertices=wide))
    source = Puppet(actor, Puppet(actor, np.ones(60), 1.0).deformer.feature_sizes(), model_iod(actor.model))
    puppet = Puppet(other, source.deformer.feature_sizes(), model_iod(actor.model))
    offsets = np.zeros((60, 2))
    offsets[:40, 1] = -4.0
    moved = puppet.vertices(offsets) - puppet.vertices(np.zeros((60, 2)))  # lips kept apart: both sealed alike
    assert np.allclose(moved[:40, 1], -4.0 * 1.3, atol=0.01)
    # The driven face keeps the measured face's size on screen.
    assert puppet.pose(actor.pose).scale * model_iod(other.model) == pytest.approx(
        actor.pose.scale * model_iod(actor.model)
    )
    with pytest.raises(InvalidInputError, match="knots"):
        Puppet(other, np.ones(12), 90.0)


def test_user_motion_adds_turns_zoom_and_exaggeration(actor):
    puppet = Puppet(actor, Puppet(actor, np.ones(60), 1.0).deformer.feature_sizes(), model_iod(actor.model))
    user = UserMotion(yaw=20, roll=-5, zoom=1.5)
    pose = puppet.pose(actor.pose, user)
    assert pose.yaw == actor.pose.yaw + 20 and pose.roll == pytest.approx(actor.pose.roll - 5)
    assert pose.scale == pytest.approx(1.5 * actor.pose.scale)
    assert UserMotion().changed(gain=2.0, yaw=-200).gain == 2.0 and UserMotion().changed(yaw=-200).yaw == -180
    for bad in ({"zoom": 0.0}, {"gain": -1}, {"yaw": float("nan")}):
        with pytest.raises(InvalidInputError):
            UserMotion(**bad)


def test_another_actor_plays_in_its_own_picture_moved_as_the_source_moves(actor, lp_d0):
    """Transfer in the scene: the driven actor sits where its own picture has it, moves by the
    source's motion relative to the source's key pose, and a picture of another shape is fitted
    whole into the frame."""
    from dataclasses import replace

    import cv2

    from facemime.fit.actor import smear_texture
    from facemime.fit.adjust import fit_model
    from facemime.shared_constants import BACKGROUND

    frame, points, _ = lp_d0
    tall = np.zeros((768, 512, 3), np.uint8)
    tall[128:640] = frame
    moved_points = {k: np.asarray(v) + [0.0, 128.0] for k, v in points.items()}
    target = smear_texture(
        actor.model,
        tall,
        fit_model(actor.model, moved_points),
        moved_points,
        {"file": "tall.png", "frame": 0, "width": 512, "height": 768},
    )
    sizes = Puppet(actor, np.ones(60), 1.0).deformer.feature_sizes()
    puppet = Puppet(target, sizes, model_iod(actor.model), actor.pose)
    rest = puppet.pose(actor.pose)  # the source at its key pose: the target at its own
    assert np.allclose([getattr(rest, k) for k in vars(rest)], [getattr(target.pose, k) for k in vars(rest)])
    shifted = puppet.pose(replace(actor.pose, tx=actor.pose.tx + 10, roll=actor.pose.roll + 3))
    # shifts scale by the two faces' sizes on screen (eye distances in pixels; the same face here)
    ratio = target.pose.scale * model_iod(target.model) / (actor.pose.scale * model_iod(actor.model))
    assert shifted.tx == pytest.approx(target.pose.tx + 10 * ratio) and abs(ratio - 1) < 0.01
    assert shifted.roll == pytest.approx(target.pose.roll + 3)
    still = puppet.render(actor.pose, np.zeros((60, 2)), (512, 512)).astype(int)
    # the 512 x 768 picture fitted into 512 x 512: 341 px wide, centred, plain margins beside it
    assert np.abs(still[:, :80] - BACKGROUND).max() == 0 and np.abs(still[:, -80:] - BACKGROUND).max() == 0
    expected = cv2.resize(tall, (341, 512), interpolation=cv2.INTER_AREA).astype(int)
    assert np.abs(still[:, 85:426] - expected).mean() < 6
    mask = Puppet(target, sizes, model_iod(actor.model), actor.pose, mask_only=True)
    assert mask.pose(actor.pose).tx == pytest.approx(actor.pose.tx)  # face alone: where the source's face is
