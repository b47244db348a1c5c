"""The actor's own mouth and eyes: the nearest sample is pasted, the key frame's shape pastes none."""

import numpy as np
import pytest

from facemime.animate.samples import IRIS_WEIGHT, SamplePainter, nearest, weigh_eyes
from facemime.errors import InvalidInputError
from facemime.types.look import Look
from facemime.types.samples import SampleGroup, Samples


def test_nearest_picks_the_exact_sample_at_its_own_key_and_none_at_the_key_frames():
    keys = np.array([[1.0, 0.0], [0.0, 2.0], [1.0, 0.0]])
    assert nearest(keys, np.array([0.0, 2.0])) == 1
    assert nearest(keys, np.array([1.0, 0.0])) == 0  # the first of equals
    assert nearest(keys, np.zeros(2)) is None  # the key frame itself
    assert nearest(keys, np.array([0.3, 0.0])) is None  # nearer the key frame than any sample
    assert nearest(keys, np.array([0.7, 0.0])) == 0


def test_the_irises_weigh_more_than_the_lids():
    w = weigh_eyes(np.ones(6))
    assert w.tolist() == [1.0, 1.0] + [IRIS_WEIGHT] * 4


def _painter(texture_shape=(40, 60)):
    boxes = np.array([[2, 2, 24, 18], [32, 2, 24, 18]])
    eyes = SampleGroup(
        "eyes",
        boxes,
        [[np.full((18, 24, 3), 200, np.uint8)] * 2, [np.full((18, 24, 3), 50, np.uint8)] * 2],
        np.array([[1.0, 1.0, 0, 0, 0, 0], [0.0, 0.0, 0.1, 0, 0.1, 0]]),
        np.array([3, 7]),
    )
    groups = {"mouth_outer_upper": np.array([0]), "mouth_outer_lower": np.array([1]),
              "mouth_inner_upper": np.array([0]), "mouth_inner_lower": np.array([1])}  # fmt: skip
    return SamplePainter(Samples((eyes,)), groups, np.array([0, 1, 5]))


def test_a_closed_eye_look_pastes_the_closed_eye_sample_and_nothing_outside_its_boxes():
    painter = _painter()
    texture = np.full((40, 60, 3), 100, np.uint8)
    out, interior = painter.paint(texture, painter.choose(np.zeros((3, 2)), Look(closure=[0.9, 1.0])))
    assert interior is None  # no mouth samples
    assert out is not texture and (texture == 100).all()  # the texture given is left alone
    assert out[10, 14].tolist() == [200, 200, 200] and out[10, 44].tolist() == [200, 200, 200]  # inside, past the fade
    assert out[30, 30].tolist() == [100, 100, 100]
    assert 100 < out[2, 14, 0] < 200  # the box's edge fades into the texture
    looked_aside, _ = painter.paint(texture, painter.choose(np.zeros((3, 2)), Look(iris=[[0.09, 0.0], [0.11, 0.0]])))
    assert looked_aside[10, 14].tolist() == [50, 50, 50]


def test_the_key_frames_look_draws_the_texture_as_it_is():
    texture = np.full((40, 60, 3), 100, np.uint8)
    painter = _painter()
    out, interior = painter.paint(texture, painter.choose(np.zeros((3, 2)), Look()))
    assert out is texture and interior is None


def test_a_group_needs_an_image_of_each_box_and_six_values_for_an_eye_key():
    box, one = np.array([[0, 0, 4, 4]]), np.zeros(1, int)
    with pytest.raises(InvalidInputError, match="RGB image of each box"):
        SampleGroup("eyes", box, [[np.zeros((3, 4, 3), np.uint8)]], np.zeros((1, 6)), one)
    with pytest.raises(InvalidInputError, match="6 values"):
        SampleGroup("eyes", box, [[np.zeros((4, 4, 3), np.uint8)]], np.zeros((1, 5)), one)
    with pytest.raises(InvalidInputError, match="one of"):
        SampleGroup("nose", box, [[np.zeros((4, 4, 3), np.uint8)]], np.zeros((1, 6)), one)


def test_an_open_mouth_shows_the_samples_interior_between_the_lips_instead_of_drawn_teeth():
    from facemime.animate.samples import interior_strip
    from facemime.animate.synth import synthesize
    from facemime.fit.actor import generic_actor

    actor = generic_actor((256, 256))
    model = actor.model
    vertices = model.vertices.copy()
    lower = model.groups["mouth_inner_lower"][1:-1]  # the corners stay
    vertices[lower, 1] -= 0.15 * np.ptp(model.vertices[:, 1])  # the mouth opens wide
    green = np.zeros((40, 96, 3), np.uint8)
    green[..., 1] = 255
    drawn = synthesize(actor, vertices, actor.pose, (256, 256))
    sampled = synthesize(actor, vertices, actor.pose, (256, 256), interior=(green, *interior_strip(model)))
    is_green = (sampled[..., 1] > 200) & (sampled[..., 0] < 60) & (sampled[..., 2] < 60)
    assert is_green.sum() > 100  # the opening shows the sample
    assert not ((drawn[..., 1] > 200) & (drawn[..., 0] < 60)).any()
    assert (sampled[~is_green] == drawn[~is_green]).mean() > 0.97  # the rest of the face is as drawn


def test_a_sent_choice_overrides_the_shapes_and_an_index_beyond_the_samples_draws_none():
    painter = _painter()
    assert painter.choose(np.zeros((3, 2)), Look(), (1, None)) == {"eyes": 1, "mouth": None}
    assert painter.choose(np.zeros((3, 2)), Look(closure=[1.0, 1.0]), (None, None)) == {"eyes": None, "mouth": None}
    assert painter.choose(np.zeros((3, 2)), Look(), (2, 0)) == {"eyes": None, "mouth": None}  # 2 samples; no mouth


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ({"boxes": [["a", 0, 4, 4]]}, "boxes must be"),
        ({"boxes": np.array([[2**62, 0, 4, 4]])}, "boxes must be"),
        ({"keys": np.array([["x"] * 6])}, "keys must be rows of real numbers"),
        ({"keys": np.full((1, 6), 1e300)}, "finite, within"),
        ({"frames": None}, "one key, one frame"),
        ({"images": None}, "one key, one frame"),
        ({"interiors": [np.zeros((40, 96, 3), np.uint8)]}, "interiors are the mouth's"),
    ],
)
def test_a_malformed_group_is_refused_with_the_libraries_own_error(change, message):
    args = {
        "name": "eyes",
        "boxes": np.array([[0, 0, 4, 4]]),
        "images": [[np.zeros((4, 4, 3), np.uint8)]],
        "keys": np.zeros((1, 6)),
        "frames": np.zeros(1, int),
    } | change
    with pytest.raises(InvalidInputError, match=message):
        SampleGroup(**args)


def test_a_library_is_a_tuple_of_groups():
    for groups in (None, (1, 2), "eyes"):
        with pytest.raises(InvalidInputError, match="tuple of sample groups"):
            Samples(groups)
