"""The product's tracker settings, pinned: the defaults were tuned on the shared videos (see
TrackerParams's docstring and benchmarks/accuracy.py), and most of the searches they switch on
(``inner_search``, ``mouth_patch``, ``brow_search``...) change the track of only a few hard
frames, so switching one off by accident passes every accuracy test. A deliberate change of a
default updates this table, with the measurement that justified it."""

import dataclasses

from facemime.track import params as params_module
from facemime.track.params import CurveWeights, TrackerParams

DEFAULTS = {
    "mouth": CurveWeights(alpha=30.0, beta=24.0, tau=2.0, rho=1.0, gamma=0.0, luma=1.0, chroma=0.5),
    "mouth_inner": CurveWeights(alpha=8.0, beta=12.0, tau=2.0, rho=1.0, gamma=0.0, luma=0.5, chroma=1.0),
    "brows": CurveWeights(alpha=30.0, beta=24.0, tau=2.0, rho=1.0, gamma=0.0, luma=1.0, chroma=0.0),
    "operator": "directional",
    "points_per_segment": 3,
    "delta0": 1.5,
    "sigma": 0.75,
    "iterations": 15,
    "tol": 0.0,
    "smoothing": 1.5,
    "lip_keep": 0.5,
    "gap_weight": 0.5,
    "brow_weight": 0.05,
    "mouth_knots": None,
    "brow_knots": None,
    "motion": True,
    "knot_flow": True,
    "lost_response": 0.1,
    "calibration_passes": 3,
    "mouth_affine": 0.7,
    "mouth_passes": 2,
    "lip_reach": 0.3,
    "lip_step": 0.3,
    "brow_search": 0.3,
    "inner_search": 3,
    "mouth_patch": 0.5,
    "mouth_relocate": 1,
    "face_width": 240.0,
}


def test_every_default_setting_is_the_tuned_one():
    params = TrackerParams()
    fields = {f.name for f in dataclasses.fields(TrackerParams)}
    # A new setting must be added here with its tuned default; a removed one taken out.
    assert fields == set(DEFAULTS)
    for name, value in DEFAULTS.items():
        actual = getattr(params, name)
        assert actual == value and type(actual) is type(value), f"TrackerParams().{name} = {actual!r}, tuned {value!r}"
    assert params.reach == 6.0  # δ0/(1−σ): every search's step is a multiple of it


def test_the_gates_the_defaults_were_tuned_with():
    # The solver's extra-pass gate and the mouth patch's reach gate (docs/tracker.md, the settings).
    assert params_module.FAST == 0.6
    assert params_module.AGREE == 1.0


def test_with_changes_one_setting_and_keeps_the_rest():
    changed = TrackerParams().with_(inner_search=0)
    assert changed.inner_search == 0
    assert {n: getattr(changed, n) for n in DEFAULTS if n != "inner_search"} == {
        n: v for n, v in DEFAULTS.items() if n != "inner_search"
    }
