"""The NME metric of the shared data README, with pinned values."""

import numpy as np
import pytest

from facemime.metrics import curve_error, group_nme, pooled_summary, resample, summarize


def test_identical_curves_score_zero_and_direction_does_not_matter():
    c = np.array([[0.0, 0.0], [3.0, 1.0], [7.0, 0.0]])
    assert curve_error(c, c) == pytest.approx(0.0, abs=1e-12)
    assert curve_error(c[::-1], c) == pytest.approx(0.0, abs=1e-12)


def test_a_parallel_shift_scores_the_shift():
    r = np.array([[0.0, 0.0], [10.0, 0.0]])
    assert curve_error(r + [0.0, 2.0], r) == pytest.approx(2.0)
    assert group_nme({"a": r + [0.0, 2.0], "b": r}, {"a": r, "b": r}, ["a", "b"], iod=10.0) == pytest.approx(0.1)


def test_pinned_value_of_a_bent_curve():
    # P is a tent 1 px high over R. Its 100 samples are even in x, so d(P->R) is the mean tent
    # height h over x_i = 10 i / 99; R's samples lie at h / sqrt(1 + 0.2^2) from the tent's sides.
    r = np.array([[0.0, 0.0], [10.0, 0.0]])
    p = np.array([[0.0, 0.0], [5.0, -1.0], [10.0, 0.0]])
    h = np.mean(1.0 - np.abs(10.0 * np.arange(100) / 99 - 5.0) / 5.0)
    assert curve_error(p, r) == pytest.approx(h * (1.0 + 1.0 / np.sqrt(1.04)) / 2.0, rel=1e-9)
    assert curve_error(p, r) == pytest.approx(0.49014, abs=1e-5)


def test_missing_or_malformed_curves_are_infinite():
    r = np.array([[0.0, 0.0], [10.0, 0.0]])
    assert curve_error(None, r) == np.inf
    assert curve_error([[1.0, 2.0]], r) == np.inf
    assert curve_error([[1.0, np.nan], [2.0, 3.0]], r) == np.inf


def test_summaries_count_missing_frames_as_failures():
    s = summarize(np.array([0.01, 0.02, np.inf, 0.2, 0.01, 0.03]))
    assert s["mean"] == pytest.approx(0.054)
    assert s["failure_rate"] == pytest.approx(2 / 6)
    assert s["p90"] == np.inf
    assert s["drift"] == pytest.approx((0.01 + 0.03) / 2 - 0.015)
    pooled = pooled_summary([np.array([0.01, 0.01]), np.array([0.2, 0.2, 0.2, 0.2])])
    assert pooled["mean"] == pytest.approx(0.105) and pooled["failure_rate"] == pytest.approx(0.5)


def test_resample_is_even_in_arc_length():
    pts = resample(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 3.0]]), 5)
    np.testing.assert_allclose(np.linalg.norm(np.diff(pts, axis=0), axis=1)[[0, 2, 3]], 1.0)
