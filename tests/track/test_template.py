"""Finding a patch again: grey crops and the coarse-to-fine template match, on a real frame."""

import cv2
import numpy as np
import pytest

from facemime.errors import InvalidInputError
from facemime.track.template import find, gray_crop


def test_gray_crops_are_opencv_grey_levels(lp_d0):
    frame = lp_d0[0]
    crop = gray_crop(frame, (101, 57), (230, 190))
    assert np.array_equal(crop, cv2.cvtColor(np.ascontiguousarray(frame[57:190, 101:230]), cv2.COLOR_RGB2GRAY))
    assert np.array_equal(gray_crop(crop, (3, 4), (20, 9)), crop[4:9, 3:20])


@pytest.mark.parametrize("size", [(31, 87), (54, 123)])
def test_a_patch_of_the_face_is_found_where_it_lies_from_a_wide_search(lp_d0, size):
    # Brow- and mouth-sized templates, searched over ± 30 px: far more placements than the full
    # resolution is searched over, so the halved images pick the place to refine.
    frame, points, _ = lp_d0
    h, w = size
    for name in ("brow_left_upper", "mouth_outer_lower"):
        cx, cy = np.round(points[name].mean(axis=0)).astype(int)
        lo = (cx - w // 2, cy - h // 2)
        template = gray_crop(frame, lo, (lo[0] + w, lo[1] + h))
        centre = np.array([lo[0] + (w - 1) / 2.0, lo[1] + (h - 1) / 2.0])
        for miss in [(0.0, 0.0), (17.0, -11.0), (-23.0, 8.0)]:
            found = find(frame, template, centre + miss, 30.0, 0.5)
            assert found is not None and np.allclose(found, centre), (name, miss, found)


def test_no_match_below_the_threshold_or_where_the_template_does_not_fit(lp_d0):
    frame = lp_d0[0]
    noise = np.random.default_rng(0).integers(0, 256, (40, 60), np.uint8)
    assert find(frame, noise, np.array([250.0, 300.0]), 30.0, 0.5) is None
    assert find(frame, noise, np.array([5.0, 5.0]), 2.0, 0.5) is None  # clipped at the corner
    with pytest.raises(InvalidInputError):
        gray_crop(frame, (500, 10), (520, 40))
