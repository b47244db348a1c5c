"""An actor fitted on a photo whose mouth is open shows that photo's own mouth: the opening is
closed in its mesh by triangles textured from the photo (fit.actor.mouth_cap), not covered by the
synthesis's drawn interior."""

import numpy as np
import pytest

from facemime.animate.deform import Deformer
from facemime.animate.synth import Puppet
from facemime.fit.actor import fit_actor, mouth_cap
from facemime.io.video import VideoReader
from facemime.types.head import model_iod, mouth_capped
from facemime.types.pose import project


@pytest.fixture(scope="module")
def open_mouth(shared):
    """st_aoc's first frame (the mouth wide open, teeth showing) and the actor fitted on it."""
    frame = next(iter(VideoReader(shared / "video" / "st_aoc.mp4")))
    return frame, fit_actor(frame, "st_aoc.mp4")[0]


def mouth_box(actor):
    """The outer lips' bounding box on the actor's photo, (x0, y0, x1, y1) whole pixels."""
    g = actor.model.groups
    px = project(actor.model.vertices, actor.pose)[0][np.concatenate([g["mouth_outer_upper"], g["mouth_outer_lower"]])]
    (x0, y0), (x1, y1) = np.floor(px.min(axis=0)).astype(int), np.ceil(px.max(axis=0)).astype(int)
    return x0, y0, x1, y1


def psnr(a, b):
    return 10 * np.log10(255**2 / max(np.mean((a.astype(np.float64) - b) ** 2), 1e-12))


def test_the_key_frame_shows_the_photos_own_open_mouth(open_mouth):
    frame, actor = open_mouth
    cap = mouth_cap(actor.model, actor.model.vertices, project(actor.model.vertices, actor.pose)[0])
    assert len(cap) == 18  # two triangles between each of the 10 pairs of knots, none at the corners
    assert {frozenset(t) for t in cap.tolist()} <= {frozenset(t) for t in actor.model.triangles.tolist()}
    assert mouth_capped(actor.model)
    puppet = Puppet(actor, Deformer(actor.model).feature_sizes(), model_iod(actor.model))
    shown = puppet.render(actor.pose, np.zeros((len(puppet.deformer.knots), 2)), (frame.shape[1], frame.shape[0]))
    x0, y0, x1, y1 = mouth_box(actor)
    # measured: the photo's pixels exactly (120 dB); with the lips' slight gap at the corners
    # sealed, as before the seal spared a capped mouth's own shape, 24.4 dB; without the cap, the
    # drawn cavity and teeth over the real ones, 15.7 dB
    assert psnr(shown[y0:y1, x0:x1], frame[y0:y1, x0:x1]) > 40.0


def test_a_closed_mouth_gets_no_cap_and_a_refit_drops_an_earlier_one(open_mouth, actor, lp_d0):
    _, opened = open_mouth
    assert len(actor.model.triangles) == len(opened.model.triangles) - 18  # lp_d0's closed mouth: no cap
    assert not mouth_capped(actor.model)
    # the open actor's model refitted on a closed mouth loses the cap it had, rather than keep it
    frame, points, _ = lp_d0
    refit = fit_actor(frame, "lp_d0", points, model=opened.model)[0]
    assert np.array_equal(refit.model.triangles, actor.model.triangles)
