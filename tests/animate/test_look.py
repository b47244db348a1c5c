"""Eyes in the synthesis: lids that close, irises that move, on the actor's own texture and on
another actor's."""

import numpy as np
import pytest

from facemime.animate.deform import Deformer
from facemime.animate.eyes import LookPainter, close_lids
from facemime.animate.synth import Puppet
from facemime.fit.actor import generic_actor
from facemime.shared_constants import EYES
from facemime.types.head import model_iod
from facemime.types.look import NAMES, Look
from facemime.types.pose import project


@pytest.fixture(scope="module")
def actor():
    return generic_actor((512, 512))


def test_the_look_round_trips_through_its_vector_and_dict():
    look = Look([0.5, -0.2], [[0.1, 0.02], [-0.05, 0.0]])
    assert np.array_equal(Look.from_vector(look.vector()).vector(), look.vector())
    assert Look.from_dict(look.as_dict()).as_dict() == look.as_dict()
    assert list(look.as_dict()) == list(NAMES)
    assert not Look.from_dict({}).vector().any()  # a name left out is 0


def test_closed_lids_lie_on_the_lower_lids_and_open_ones_stay(actor):
    model = actor.model
    rings = [model.groups[e] for e in EYES]
    moved = close_lids(model.vertices, rings, np.array([1.0, 0.0]))
    right, left = rings
    assert np.allclose(moved[right[[1, 2, 3]]], model.vertices[right[[7, 6, 5]]])
    assert np.array_equal(moved[left], model.vertices[left])
    half = close_lids(model.vertices, rings, np.array([0.5, 0.5]))
    assert np.allclose(half[right[2]], (model.vertices[right[2]] + model.vertices[right[6]]) / 2)


def test_a_neutral_look_leaves_the_texture_as_it_was(actor):
    """Only the iris disc's soft edge is blended with the painted-out eye."""
    painter = LookPainter(actor)
    diff = np.abs(painter.texture(Look()).astype(int) - actor.texture).max(axis=2)
    for eye in painter._eyes:
        x0, y0, x1, y1 = eye.box
        assert (diff[y0:y1, x0:x1] > 12).mean() < 0.01
        diff[y0:y1, x0:x1] = 0
    assert not diff.any()


def _iris_centre(texture: np.ndarray, box: tuple) -> np.ndarray:
    """The mean place of the painted iris's blue in ``box`` of ``texture``."""
    x0, y0, x1, y1 = box
    rgb = texture[y0:y1, x0:x1].astype(int)
    ys, xs = np.nonzero(rgb[:, :, 2] - rgb[:, :, 0] > 25)
    return np.array([xs.mean(), ys.mean()])


def test_an_iris_shift_moves_the_iris_by_that_share_of_the_eye(actor):
    painter = LookPainter(actor)
    eye = painter._eyes[0]
    before = _iris_centre(painter.texture(Look()).copy(), eye.box)
    after = _iris_centre(painter.texture(Look(iris=[[0.15, 0.0], [0.0, 0.0]])), eye.box)
    moved = (after - before) @ np.linalg.inv(eye.frame.axes)  # eye widths, (u, v)
    assert moved[0] == pytest.approx(0.15, abs=0.04) and abs(moved[1]) < 0.04


def test_another_actor_closes_its_eyes_with_the_measured_look(actor):
    """Transfer: a puppet of another actor (here the generic head, driven by a face whose feature
    sizes are its own) shuts the eye the look shuts: the sclera's bright pixels go."""
    puppet = Puppet(actor, Deformer(actor.model).feature_sizes(), model_iod(actor.model), mask_only=True)
    open_ = puppet.render(actor.pose, np.zeros((60, 2)), (512, 512), look=Look()).copy()
    shut = puppet.render(actor.pose, np.zeros((60, 2)), (512, 512), look=Look(closure=[1.0, 0.0]))
    boxes = [project(actor.model.vertices[actor.model.groups[e]], actor.pose)[0] for e in EYES]

    def bright(img, pts):
        return (
            img[
                int(pts[:, 1].min()) : int(pts[:, 1].max()) + 1,
                int(pts[:, 0].min()) : int(pts[:, 0].max()) + 1,
            ].min(axis=2)
            > 200
        ).sum()

    assert bright(shut, boxes[0]) < 0.1 * bright(open_, boxes[0])
    assert bright(shut, boxes[1]) == pytest.approx(bright(open_, boxes[1]), rel=0.05)
