"""The snakes' image field (built in the Rust core) equals the OpenCV recipe it replaces."""

import cv2
import numpy as np
import pytest

from facemime.io.video import VideoReader
from facemime.track.field import build_field, regions

LUMA = np.array([[0.299, 0.587, 0.114]], np.float32)


def opencv_field(frame, prev, box, sigma):
    """The field by OpenCV on the box's crop: GaussianBlur, then Sobel(ksize=1, scale=0.5)."""
    x0, y0, x1, y1 = box
    smooth = lambda img: cv2.GaussianBlur(img, (0, 0), sigma)  # noqa: E731
    luma = lambda rgb: smooth(cv2.transform(rgb[y0:y1, x0:x1].astype(np.float32), LUMA))  # noqa: E731
    crop = frame[y0:y1, x0:x1]
    lum, chroma = luma(frame), smooth(np.subtract(crop[..., 0], crop[..., 1], dtype=np.float32))
    d = lambda img, dx, dy: cv2.Sobel(img, cv2.CV_32F, dx, dy, ksize=1, scale=0.5)  # noqa: E731
    return cv2.merge([d(lum, 1, 0), d(lum, 0, 1), d(chroma, 1, 0), d(chroma, 0, 1), lum, luma(prev)])


@pytest.fixture(scope="module")
def frames(shared):
    with VideoReader(shared / "video" / "vr_1.mp4") as reader:
        it = iter(reader)
        return next(it), next(it)


@pytest.mark.parametrize("box", [(200, 300, 480, 520), (0, 0, 37, 700), (690, 10, 700, 14)])
@pytest.mark.parametrize("sigma", [0.8, 1.5, 3.0])
def test_equals_opencv_on_a_real_frame_up_to_float_rounding(frames, box, sigma):
    prev, frame = frames
    got = build_field(frame, prev, box, sigma)
    want = opencv_field(frame, prev, box, sigma)
    assert got.dtype == np.float32 and got.shape == want.shape == (box[3] - box[1], box[2] - box[0], 6)
    np.testing.assert_allclose(got, want, atol=2e-3)


def test_without_a_previous_frame_the_last_channel_repeats_the_luma(frames):
    got = build_field(frames[1], None, (100, 100, 160, 150), 1.5)
    np.testing.assert_array_equal(got[..., 5], got[..., 4])


def test_the_regions_cover_their_knots_with_their_margin_inside_the_image():
    knots = np.array([[10.2, 50.0], [90.7, 60.5], [99.0, 79.0]])
    bands = [(np.array([0, 1], np.uintp), 5.0), (np.array([2], np.uintp), 0.0)]
    # σ = 0.5: a 5-tap Gaussian, radius 2, by which the box grows (inside the image).
    box, boxes = regions(knots, bands, 100, 80, 0.5)
    assert boxes == [(5, 45, 97, 67), (96, 76, 100, 80)]
    assert box == (3, 43, 100, 80)
    with pytest.raises(ValueError, match="past the 3 knots"):
        regions(knots, [(np.array([3], np.uintp), 1.0)], 100, 80, 0.5)
    with pytest.raises(ValueError, match="sigma"):
        regions(knots, bands, 100, 80, 0.0)


def test_a_field_read_inside_its_bands_is_that_of_a_box_grown_far_beyond_them(frames):
    """The pixels of a band hold the values of a field over a much larger box (no mirrored
    edge reaches them), so the snakes read the same field however tight the box."""
    knots = np.array([[200.0, 300.0], [260.0, 310.0]])
    bands = [(np.array([0, 1], np.uintp), 6.0)]
    box, (band,) = regions(knots, bands, 700, 700, 1.5)
    tight = build_field(frames[1], frames[0], box, 1.5, [band])
    wide_box = (box[0] - 40, box[1] - 40, box[2] + 40, box[3] + 40)
    wide = build_field(frames[1], frames[0], wide_box, 1.5)
    (x0, y0, x1, y1), (ox, oy) = band, (box[0] - wide_box[0], box[1] - wide_box[1])
    read = (slice(y0 - box[1] + 1, y1 - box[1] - 1), slice(x0 - box[0] + 1, x1 - box[0] - 1))
    wide_read = (slice(read[0].start + oy, read[0].stop + oy), slice(read[1].start + ox, read[1].stop + ox))
    np.testing.assert_array_equal(tight[read], wide[wide_read])


def test_a_reused_buffer_gets_the_same_field_whatever_it_held(frames):
    _prev, frame = frames
    box, bands = (150, 200, 400, 480), [(0, 210, 512, 260), (220, 400, 330, 470)]
    want = build_field(frame, None, box, 1.5, bands)
    buffer = np.full((280, 250, 6), np.nan, np.float32)
    got = build_field(frame, None, box, 1.5, bands, out=buffer)
    assert got is buffer
    np.testing.assert_array_equal(got, want)
    # Pixels outside the bands are 0, not what the buffer held.
    assert not got[100:140].any() and not got[200:270, :70].any() and not got[200:270, 180:].any()
    np.testing.assert_array_equal(got[210:260, 80:170], build_field(frame, None, box, 1.5)[210:260, 80:170])


def test_a_buffer_of_the_wrong_shape_is_refused(frames):
    with pytest.raises(ValueError, match="shape"):
        build_field(frames[1], None, (100, 100, 160, 150), 1.5, out=np.zeros((50, 61, 6), np.float32))
