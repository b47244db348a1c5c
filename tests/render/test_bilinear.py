"""The resampling of the eyes and the face networks' crops (facemime.render.bilinear), the
arithmetic the browser receiver follows: whole-pixel moves copy pixels, half-pixel ones average
them with the stated rounding, the border is replicated or zero as asked, and nothing depends on
OpenCV."""

import numpy as np

from facemime.render.bilinear import sample_affine, shift_offset, shifted

RNG = np.random.default_rng(7)
IMAGE = RNG.integers(0, 256, (9, 11, 3), dtype=np.uint8)


def test_an_identity_or_whole_pixel_map_copies_pixels_and_replicates_the_border():
    assert np.array_equal(sample_affine(IMAGE, np.array([[1.0, 0, 0], [0, 1.0, 0]]), (11, 9)), IMAGE)
    moved = sample_affine(IMAGE, np.array([[1.0, 0, 2], [0, 1.0, -1]]), (11, 9))
    rows, cols = np.clip(np.arange(9) - 1, 0, 8), np.clip(np.arange(11) + 2, 0, 10)
    assert np.array_equal(moved, IMAGE[np.ix_(rows, cols)])


def test_a_half_pixel_sample_is_the_mean_rounded_half_up():
    image = np.array([[[10, 11, 0], [13, 12, 255]]], np.uint8)
    got = sample_affine(image, np.array([[1.0, 0, 0.5], [0, 1.0, 0]]), (1, 1))
    assert got[0, 0].tolist() == [12, 12, 128]  # (10 + 13) / 2 = 11.5 -> 12; (0 + 255) / 2 -> 128


def test_positions_are_taken_to_a_32nd_of_a_pixel():
    ramp = np.repeat(np.arange(0, 256, 64, dtype=np.uint8)[None, :, None], 3, axis=2)  # 0, 64, 128, 192
    for x in (0.01, 0.3, 1.0 / 32 + 0.001):
        got = int(sample_affine(ramp, np.array([[1.0, 0, x], [0, 1.0, 0]]), (1, 1))[0, 0, 0])
        assert got == round(64 * round(x * 32) / 32)


def test_a_shift_moves_the_picture_and_a_zero_border_fades_it():
    d = np.array([1.0, -2.0])
    offset = shift_offset(d)
    assert offset == (-32, 64)
    image = RNG.random((6, 7))
    moved = shifted(image, offset, replicate=True)
    assert np.array_equal(moved[:4, 1:], image[2:, :-1])  # the picture moved right 1 px and up 2
    assert np.array_equal(moved[4:, 1:], np.repeat(image[-1:, :-1], 2, axis=0))  # the border replicated
    zero = shifted(image, offset, replicate=False)
    assert np.array_equal(zero[:4, 1:], image[2:, :-1]) and not zero[4:].any() and not zero[:, 0].any()


def test_a_fractional_shift_weighs_its_neighbours_and_keeps_colour_channels_apart():
    image = np.zeros((3, 4, 3), np.float32)
    image[1, 2] = (32.0, 64.0, 96.0)
    moved = shifted(image, shift_offset(np.array([0.25, 0.0])), replicate=False)
    assert np.allclose(moved[1, 2], 0.75 * image[1, 2]) and np.allclose(moved[1, 3], 0.25 * image[1, 2])
    assert moved.sum() == image.sum()


def test_beyond_the_picture_a_zero_border_reads_zero_and_a_bad_map_is_one_error():
    import pytest

    from facemime.errors import InvalidInputError

    shifted_out = sample_affine(IMAGE, np.array([[1.0, 0, -2], [0, 1.0, 0]]), (11, 9), border="zero")
    assert not shifted_out[:, :2].any() and np.array_equal(shifted_out[:, 2:], IMAGE[:, :9])
    for bad in ({"m": np.array([[np.nan, 0, 0], [0, 1.0, 0]])}, {"m": np.eye(3)}, {"border": "wrap"}):
        args = {"m": np.array([[1.0, 0, 0], [0, 1.0, 0]]), "border": "replicate"} | bad
        with pytest.raises(InvalidInputError):
            sample_affine(IMAGE, args["m"], (4, 4), border=args["border"])
    with pytest.raises(InvalidInputError) as told:  # a long argument is shown cut, not echoed whole
        sample_affine(IMAGE, np.array([[1.0, 0, 0], [0, 1.0, 0]]), (4, 4), border="x" * 10**6)
    assert len(str(told.value)) < 120


def test_the_face_networks_crops_do_not_depend_on_opencvs_warp(monkeypatch, lp_d0):
    """The detector's and the landmark model's crops are sampled in this arithmetic, not by
    cv2.warpAffine, whose rounding changed between OpenCV 4.14, 5.0 and 5.1 (the automatic
    start's NME on the shared videos moved from 0.0187 to 0.0212 with it)."""
    import cv2

    from facemime.networks.finder import find_face

    def refused(*args, **kwargs):
        raise AssertionError("cv2.warpAffine was called")

    monkeypatch.setattr(cv2, "warpAffine", refused)
    face = find_face(lp_d0[0])
    assert face.landmarks.shape == (468, 3)
