"""The face detector: anchors, decoding and weighted non-maximum suppression on hand-made
network outputs, the search windows, and the shipped model on real photos."""

import numpy as np
import pytest

from facemime.io.photo import read_photo
from facemime.networks.detector import INPUT, Detection, anchors, decode, detect_faces, suppress, windows


def test_anchors_are_the_two_grids_of_the_short_range_model():
    a = anchors()
    assert a.shape == (896, 2)
    # 16 x 16 cells of 8 px, two anchors each, then 8 x 8 cells of 16 px, six each.
    np.testing.assert_allclose(a[:2], [[0.5 / 16, 0.5 / 16]] * 2)
    np.testing.assert_allclose(a[2], [1.5 / 16, 0.5 / 16])
    np.testing.assert_allclose(a[512:518], [[0.5 / 8, 0.5 / 8]] * 6)
    np.testing.assert_allclose(a[-1], [7.5 / 8, 7.5 / 8])


def test_decode_reads_offsets_from_the_anchor_centre_in_input_pixels():
    scores = np.full(896, -10.0)
    raw = np.zeros((896, 16))
    k = 512 + 6 * (8 * 3 + 5)  # a stride-16 anchor in row 3, column 5: centre (5.5, 3.5) / 8
    scores[k] = 2.0
    raw[k, :4] = [4.0, -8.0, 32.0, 48.0]  # centre moved (+4, -8) px, box 32 x 48 px
    raw[k, 4:] = np.arange(12)  # keypoint j moved (2j, 2j + 1) px
    (d,) = decode(scores, raw)
    centre = np.array([5.5, 3.5]) / 8 + np.array([4.0, -8.0]) / INPUT
    np.testing.assert_allclose(d.box, np.r_[centre - [16 / INPUT, 24 / INPUT], centre + [16 / INPUT, 24 / INPUT]])
    np.testing.assert_allclose(d.keypoints, np.arange(12).reshape(6, 2) / INPUT + [5.5 / 8, 3.5 / 8])
    assert d.score == pytest.approx(1 / (1 + np.exp(-2.0)))


def test_decode_keeps_only_scores_above_the_threshold():
    scores = np.full(896, -10.0)
    scores[[3, 700]] = [0.1, -0.1]  # sigmoid 0.525 and 0.475
    assert [round(d.score, 3) for d in decode(scores, np.zeros((896, 16)))] == [0.525]
    assert decode(np.full(896, 1e6), np.zeros((896, 16)))[0].score == pytest.approx(1.0)  # clipped, no overflow


def test_weighted_suppression_merges_overlaps_and_keeps_the_rest():
    box = lambda x0, y0, s: np.array([x0, y0, x0 + s, y0 + s], float)  # noqa: E731
    a = Detection(box(0, 0, 10), np.zeros((6, 2)), 0.9)
    b = Detection(box(1, 1, 10), np.full((6, 2), 10.0), 0.3)  # overlaps a by 0.68
    c = Detection(box(8, 8, 10), np.zeros((6, 2)), 0.8)  # overlaps a by 0.02
    out = suppress([b, c, a])
    assert [d.score for d in out] == [0.9, 0.8]
    np.testing.assert_allclose(out[0].box, box(0.25, 0.25, 10))  # (0.9 * a + 0.3 * b) / 1.2
    np.testing.assert_allclose(out[0].keypoints, 2.5)
    np.testing.assert_allclose(out[1].box, c.box)
    assert suppress([]) == []


@pytest.mark.parametrize(("width", "height"), [(512, 512), (576, 768), (704, 1216), (300, 200)])
def test_windows_cover_the_image_whole_then_in_squares(width, height):
    found = windows(width, height)
    x, y, side = found[0]
    assert side == max(width, height) and x <= 0 and y <= 0  # the whole image, letterboxed
    covered = np.zeros((height, width), bool)
    for x, y, side in found[1:]:
        assert x >= 0 and y >= 0 and x + side <= width and y + side <= height
        covered[y : y + side, x : x + side] = True
    assert len(found) == 1 or covered.all()


def test_the_shipped_detector_finds_the_faces_of_real_photos_and_nothing_in_a_blank(shared):
    for name in ("lp_s1", "lp_s9"):
        image = read_photo(shared / "photos" / f"{name}.jpg")
        ref = np.load(shared / "photos" / f"{name}.landmarks.npz")
        iris, iod = ref["landmarks"][0, [468, 473], :2], float(ref["iod"][0])
        (face,) = detect_faces(image)
        # The eye keypoints fell within 0.07 IOD of the iris centres on the ten videos' first
        # frames (lp_d3: 0.08 in y) and the box held the eyes and mouth.
        assert np.linalg.norm(face.keypoints[:2] - iris, axis=1).max() < 0.1 * iod
        lips = ref["landmarks"][0, [13, 14], :2].mean(axis=0)
        assert (face.box[:2] < lips).all() and (lips < face.box[2:]).all()
        assert face.score > 0.9
    assert detect_faces(np.full((240, 320, 3), 128, np.uint8)) == []


@pytest.mark.parametrize("quarters", [1, 2, 3])
def test_a_face_turned_on_its_side_or_upside_down_is_found(shared, quarters):
    image = read_photo(shared / "photos" / "lp_s42.jpg")
    ref = np.load(shared / "photos" / "lp_s42.landmarks.npz")
    h, w = image.shape[:2]
    turned = np.ascontiguousarray(np.rot90(image, quarters))
    (face,) = detect_faces(turned, 0.8)
    # The iris centres, turned the same way (np.rot90: counter-clockwise, quarter by quarter).
    iris = ref["landmarks"][0, [468, 473], :2].astype(float)
    for _ in range(quarters):
        iris = np.column_stack([iris[:, 1], w - 1 - iris[:, 0]])
        w, h = h, w
    assert np.linalg.norm(face.keypoints[:2] - iris, axis=1).max() < 0.1 * float(ref["iod"][0])
