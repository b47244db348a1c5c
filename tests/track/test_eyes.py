"""Eyes measured: the iris on a drawn eye, openness and gaze on renders of the generic head with
known looks, and blinks on a real video."""

import numpy as np
import pytest

from facemime.animate.analysis import Analysis
from facemime.animate.deform import Deformer
from facemime.animate.synth import Puppet
from facemime.fit.actor import generic_actor
from facemime.io.video import VideoReader
from facemime.shared_constants import DENSITY, SPAN_U, SPAN_V
from facemime.track.eyes import EyeFrame, EyeTracker, find_iris
from facemime.types.head import model_iod
from facemime.types.look import Look


def drawn_eye(iris_uv: tuple[float, float]) -> np.ndarray:
    """An eye patch as :meth:`EyeFrame.patch` gives it: skin, a white almond opening between
    lids at v = ±0.18, a dark iris disc of radius 0.21 centred at ``iris_uv``."""
    cols = round((SPAN_U[1] - SPAN_U[0]) * DENSITY) + 1
    rows = round((SPAN_V[1] - SPAN_V[0]) * DENSITY) + 1
    u = SPAN_U[0] + np.arange(cols) / DENSITY
    v = SPAN_V[0] + np.arange(rows)[:, None] / DENSITY
    patch = np.full((rows, cols), 150.0, np.float32)
    opening = np.abs(v) <= 0.18 * (1 - (u / 0.5) ** 2)
    patch[opening] = 225.0
    iris = ((u - iris_uv[0]) ** 2 + (v - iris_uv[1]) ** 2 <= 0.21**2) & opening
    patch[iris] = 60.0
    return patch


@pytest.mark.parametrize("iris", [(0.0, 0.0), (-0.18, 0.02), (0.2, -0.03)])
def test_the_iris_is_found_on_a_drawn_eye(iris):
    found, contrast = find_iris(drawn_eye(iris))
    assert np.abs(found - iris).max() < 0.03
    assert contrast > 100


def test_eye_frames_map_both_ways():
    frame = EyeFrame.of(
        np.array([[100, 50], [110, 45], [120, 44], [130, 45], [140, 50], [130, 55], [120, 56], [110, 55]], float)
    )
    assert frame.width == pytest.approx(40.0)
    assert np.allclose(frame.to_image([0.0, 0.0]), [120, 50])
    assert np.allclose(frame.to_image([0.5, 0.25]), [140, 60])  # v points down the screen
    assert np.allclose(frame.to_eye(frame.to_image([[0.3, -0.1]])), [[0.3, -0.1]])


@pytest.fixture(scope="module")
def generic():
    actor = generic_actor((512, 512))
    puppet = Puppet(actor, Deformer(actor.model).feature_sizes(), model_iod(actor.model), mask_only=True)
    render = lambda look: puppet.render(actor.pose, np.zeros((60, 2)), (512, 512), look=look).copy()  # noqa: E731
    return actor, render


@pytest.mark.parametrize("closure", [(0.0, 0.0), (0.5, 0.8), (0.3, 0.0)])
def test_openness_of_the_generic_head_with_known_closure(generic, closure):
    actor, render = generic
    eyes = EyeTracker(actor.model, render(Look()), actor.pose)
    measured, _ = eyes.look(eyes.update(render(Look(closure=closure)), actor.pose))
    assert np.abs(measured - closure).max() < 0.2, measured


@pytest.mark.parametrize("closure", [(1.0, 0.0), (1.0, 1.0)])
def test_a_shut_eye_of_the_generic_head_is_seen_shut(generic, closure):
    """A shut painted eye (two thin lid lines on one another) is measured at least 0.6 closed
    (0.65: its lines are thinner than the open eye's rims the measure expects), an open one open."""
    actor, render = generic
    eyes = EyeTracker(actor.model, render(Look()), actor.pose)
    measured, _ = eyes.look(eyes.update(render(Look(closure=closure)), actor.pose))
    shut = np.array(closure) == 1.0
    assert (measured[shut] > 0.6).all() and (np.abs(measured[~shut]) < 0.2).all(), measured


def test_gaze_of_the_generic_head_with_known_iris_shift(generic):
    actor, render = generic
    eyes = EyeTracker(actor.model, render(Look()), actor.pose)
    shift = np.array([[0.1, 0.0], [-0.1, 0.03]])
    closure, iris = eyes.look(eyes.update(render(Look(iris=shift)), actor.pose))
    assert np.abs(iris - shift).max() < 0.04, iris
    assert np.abs(closure).max() < 0.2


def test_a_shut_eye_keeps_its_iris_where_it_was_last_seen(generic):
    actor, render = generic
    eyes = EyeTracker(actor.model, render(Look()), actor.pose)
    shift = np.array([[0.1, 0.0], [-0.1, 0.03]])
    eyes.look(eyes.update(render(Look(iris=shift)), actor.pose))
    closure, iris = eyes.look(eyes.update(render(Look(closure=[1.0, 1.0])), actor.pose))
    assert (closure > 0.6).all()
    assert np.abs(iris - shift).max() < 0.04


def test_the_winks_and_the_closed_eyes_of_lp_d3_are_measured(shared):
    """lp_d3 (Face Mesh reference openings, IOD): both eyes open in frames 0-3 (0.11-0.12); her
    left eye shut in frames 6-11 (0.03, the right 0.09-0.11), her right eye in 36-41 (0.01,
    the left 0.10), both nearly shut and looking down in 113-128 (0.015 and 0.03)."""
    closure = {}
    with VideoReader(shared / "video" / "lp_d3.mp4") as reader:
        for i, frame in enumerate(reader):
            if i == 0:
                analysis = Analysis(frame, "lp_d3")
            else:
                closure[i] = analysis.update(frame).look.closure
            if i == 128:
                break
    assert max(np.abs(closure[i]).max() for i in range(1, 4)) < 0.35
    left_wink = np.array([closure[i] for i in range(6, 12)])
    right_wink = np.array([closure[i] for i in range(36, 42)])
    # measured with the landmark pose: left wink 0.79 (the open eye 0.17), right wink 0.47 (the
    # open eye 0.17); with the flow-based pose 0.75 (0.17) and 0.55 (0.32)
    assert left_wink[:, 1].mean() > 0.5 and left_wink[:, 1].mean() > left_wink[:, 0].mean() + 0.15
    assert right_wink[:, 0].mean() > 0.42 and right_wink[:, 0].mean() > right_wink[:, 1].mean() + 0.15
    shut = np.array([closure[i] for i in range(113, 129)])
    assert (np.median(shut, axis=0) > 0.3).all()
