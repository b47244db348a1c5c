"""Head-motion compensation: the robust similarity fit and reproducible tracks."""

import numpy as np

from facemime.track import Tracker
from facemime.track.motion import apply, robust_similarity
from facemime.track.synthetic import band_face


def test_robust_similarity_recovers_the_motion_despite_gross_outliers():
    rng = np.random.default_rng(3)
    src = rng.uniform(100, 300, (40, 2))
    angle, scale = np.radians(4.0), 1.05
    truth = np.array([[scale * np.cos(angle), -scale * np.sin(angle), 7.5],
                      [scale * np.sin(angle), scale * np.cos(angle), -3.0]])
    dst = apply(truth, src) + rng.normal(0.0, 0.1, src.shape)
    bad = rng.choice(40, 12, replace=False)  # 30 % of the points jump 5-40 px
    dst[bad] += rng.uniform(5, 40, (12, 2)) * rng.choice([-1, 1], (12, 2))
    m, inliers = robust_similarity(src, dst, limit=1.0)
    assert np.abs(apply(m, src) - apply(truth, src)).max() < 0.15
    assert not inliers[bad].any() and inliers.sum() >= 40 - 12 - 1


def test_the_same_frames_give_the_same_track_twice_in_one_process():
    frames = [band_face(shift=(0.8 * t, -0.5 * t), opening=0.5 * t, noise=3.0, seed=t)[0] for t in range(12)]
    _, truth0 = band_face()
    runs = []
    for _ in range(2):
        tracker = Tracker(frames[0], truth0)
        runs.append([tracker.update(f).contours for f in frames[1:]])
    for a, b in zip(*runs):
        for name in a:
            np.testing.assert_array_equal(a[name], b[name])
