"""The contour tracker on synthetic faces with known truth and on a real shared video."""

import numpy as np
import pytest

from facemime.errors import InvalidInputError
from facemime.metrics import curve_error, group_nme
from facemime.track import Tracker
from facemime.track.params import TrackerParams
from facemime.track.synthetic import band_face
from facemime.types.contours import CONTOUR_NAMES, FEATURES, GROUPS


def sequence(steps, **per_step):
    """Frames t = 1..steps of a face moving by per_step * t, with noise."""
    for t in range(1, steps + 1):
        yield band_face(
            noise=2.0,
            seed=t,
            **{k: tuple(x * t for x in v) if isinstance(v, tuple) else v * t for k, v in per_step.items()},
        )


def test_follows_a_translated_bent_and_opening_face_within_half_a_pixel():
    # Every frame the eight curves lie within 0.5 px of the truth on average, and no single
    # curve strays 0.75 px (the pointed curve ends wobble a few tenths along the edge as the
    # anti-aliased drawing changes with the sub-pixel shift).
    frame0, truth0 = band_face(noise=2.0)
    tracker = Tracker(frame0, truth0)
    for frame, truth in sequence(20, shift=(0.7, 0.4), opening=0.4, bend=0.1, brow_raise=0.2):
        result = tracker.update(frame)
        assert not result.lost and result.motion_ok
        errors = {name: curve_error(result.contours[name], truth[name]) for name in CONTOUR_NAMES}
        assert np.mean(list(errors.values())) < 0.5, (result.index, errors)
        assert max(errors.values()) < 0.75, (result.index, errors)


def lip_thickness(contours):
    """Thickness of the upper and of the lower lip and the mouth opening at the middle (px)."""
    y = {n: c[len(c) // 2, 1] for n, c in contours.items() if n.startswith("mouth")}
    return (
        y["mouth_inner_upper"] - y["mouth_outer_upper"],
        y["mouth_outer_lower"] - y["mouth_inner_lower"],
        y["mouth_inner_lower"] - y["mouth_inner_upper"],
    )


@pytest.mark.parametrize("repulsion", [True, False])
def test_repulsion_keeps_thinning_lips_from_merging_onto_one_edge(repulsion):
    # The lips thin to a fifth while the mouth is open: the outer and inner edges of each lip
    # approach each other. With repulsion every lip keeps half its first-frame thickness and the
    # inner curves do not cross (by more than half a pixel); without it the curves follow the edges together.
    params = TrackerParams() if repulsion else TrackerParams(gap_weight=0.0)
    frame0, truth0 = band_face(opening=6.0)
    start_upper, start_lower, _ = lip_thickness(truth0)
    tracker = Tracker(frame0, truth0, params)
    for t in range(1, 17):
        upper, lower, opening = lip_thickness(
            tracker.update(band_face(opening=6.0, lips=1.0 - 0.05 * t, noise=2.0, seed=t)[0]).contours
        )
    if repulsion:
        assert upper >= 0.5 * start_upper - 0.5 and lower >= 0.5 * start_lower - 0.5 and opening > -0.5
    else:
        assert upper < 0.35 * start_upper and lower < 0.35 * start_lower


@pytest.mark.parametrize("mouth_passes", [1, 2])
def test_no_coordinate_moves_more_than_the_solver_bound_per_pass_in_a_frame(mouth_passes):
    # The brows get one solver pass per frame, the mouth ``mouth_passes``: each pass moves a
    # coordinate at most δ0/(1−σ); a motion faster than that uses the mouth's extra passes.
    # A brow that this fast motion loses jumps back to its rest shape instead (not a pass); the
    # wide searches for a brow, a mouth or an inner mouth lost, which are not solver passes
    # either, are off.
    params = TrackerParams(
        motion=False,
        delta0=1.0,
        sigma=0.6,
        mouth_passes=mouth_passes,
        brow_search=0.0,
        mouth_relocate=0,
        inner_search=0,
    )
    bound = params.delta0 / (1.0 - params.sigma)
    frame0, truth0 = band_face()
    tracker = Tracker(frame0, truth0, params)
    before = tracker.contours
    moved = dict.fromkeys(CONTOUR_NAMES, 0.0)
    for frame, _ in sequence(6, shift=(5.0, -4.0)):
        result = tracker.update(frame)
        after = result.contours
        for name in CONTOUR_NAMES:
            if not any(name.startswith(f) for f in result.lost if f.startswith("brow")):
                moved[name] = max(moved[name], np.abs(after[name] - before[name]).max())
        before = after
    for name, most in moved.items():
        passes = mouth_passes if name.startswith("mouth") else 1
        assert most <= passes * bound + 1e-9, name
        assert most > (passes - 1) * bound, name


@pytest.mark.parametrize("mouth_passes", [1, 2])
def test_a_mouth_opening_faster_than_one_pass_reaches_is_followed_by_a_second_pass(mouth_passes):
    # Without the optical flow of the knots (as when the lips' texture defeats it), the lower
    # lip drops 6.3 px in one frame, more than one solver pass may move it (6 px).
    params = TrackerParams(knot_flow=False, mouth_passes=mouth_passes)
    frame0, truth0 = band_face(noise=2.0)
    tracker = Tracker(frame0, truth0, params)
    frame, truth = band_face(opening=9.0, noise=2.0, seed=1)
    contours = tracker.update(frame).contours
    error = max(curve_error(contours[n], truth[n]) for n in CONTOUR_NAMES if n.startswith("mouth"))
    assert error < 1.0 if mouth_passes == 2 else error > 2.5


def test_confidence_and_lost_flag_when_the_face_disappears():
    frame0, truth0 = band_face()
    tracker = Tracker(frame0, truth0)
    ok = tracker.update(band_face(noise=1.0)[0])
    assert ok.lost == [] and min(ok.confidence.values()) > 0.8
    blank = np.full_like(frame0, 128)
    gone = tracker.update(blank)
    assert sorted(gone.lost) == sorted(FEATURES) and max(gone.confidence.values()) < 0.1


def test_a_mouth_drawn_as_one_straight_line_is_tracked():
    # A closed mouth drawn flat (all four lip curves on one line), taken as given (no
    # calibration on the image edges), leaves the rest shape's affine fit without a vertical
    # extent: the tracker still follows the face.
    frame0, truth0 = band_face()
    flat = {n: c.copy() for n, c in truth0.items()}
    line = np.mean([c[:, 1].mean() for n, c in flat.items() if n.startswith("mouth")])
    for n in flat:
        if n.startswith("mouth"):
            flat[n][:, 1] = line
    tracker = Tracker(frame0, flat, TrackerParams(calibration_passes=0))
    for frame, _ in sequence(3, shift=(0.5, 0.0)):
        result = tracker.update(frame)
        assert all(np.isfinite(c).all() for c in result.contours.values())


def test_editing_a_result_does_not_change_the_track():
    frame0, truth0 = band_face()
    frames = [band_face(shift=(0.7 * k, 0.3 * k))[0] for k in range(1, 4)]
    plain, edited = Tracker(frame0, truth0), Tracker(frame0, truth0)
    for frame in frames:
        want = plain.update(frame).contours
        got = edited.update(frame).contours
        for name in CONTOUR_NAMES:
            np.testing.assert_array_equal(got[name], want[name])
            got[name] += 40.0  # a caller drawing or smoothing in place


def test_a_lost_inner_mouth_is_looked_for_up_and_down_the_face():
    # The line where thick lips meet drops 20 px in the middle within a frame, more than a
    # solver pass reaches (6 px), with nothing (no knot flow, no lip search) to carry the inner
    # curves there: left alone they lose it; the search finds the lips' edges below.
    def track(inner_search):
        params = TrackerParams(knot_flow=False, lip_reach=0.0, mouth_passes=1, inner_search=inner_search)
        tracker = Tracker(*band_face(lips=2.5), params)
        frame, truth = band_face(lips=2.5, parting=20.0, noise=1.0)
        result = tracker.update(frame)
        error = max(curve_error(result.contours[n], truth[n]) for n in FEATURES["mouth_inner"])
        return result, error

    alone, alone_error = track(0)
    searched, searched_error = track(3)
    assert "mouth_inner" in alone.lost and alone_error > 10.0
    assert searched.lost == [] and searched.confidence["mouth_inner"] > 2 * alone.confidence["mouth_inner"]
    assert searched_error < 0.5 * alone_error
    for name in FEATURES["mouth_outer"]:  # the outer mouth stays where the solver put it
        np.testing.assert_array_equal(searched.contours[name], alone.contours[name])


def test_a_lost_brow_goes_back_to_its_rest_shape_and_is_found_again():
    frame0, truth0 = band_face()
    tracker = Tracker(frame0, truth0)
    for raise_ in (2.0, 4.0, 6.0, 8.0, 8.0):
        raised, truth = band_face(brow_raise=raise_, noise=1.0, seed=int(raise_))
        tracker.update(raised)
    brows = [n for n in CONTOUR_NAMES if n.startswith("brow")]
    assert max(curve_error(tracker.contours[n], truth[n]) for n in brows) < 1.0
    erased = raised.copy()
    erased[40:100, 40:216] = (205, 160, 140)  # skin over both brows
    gone = tracker.update(erased)
    assert {"brow_left", "brow_right"} <= set(gone.lost)
    for n in brows:  # back on the first frame's brows (the head has not moved), not 8 px up
        assert curve_error(gone.contours[n], truth0[n]) < 1.0
    back, truth = band_face(noise=1.0, seed=9)
    found = tracker.update(back)
    assert not any(f.startswith("brow") for f in found.lost)
    assert max(curve_error(found.contours[n], truth[n]) for n in brows) < 1.0


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (lambda c: c.pop("brow_left_lower"), "contours lack brow_left_lower"),
        (lambda c: c.__setitem__("mouth_outer_upper", [[1.0, 2.0]]), "needs at least 2 points"),
        (lambda c: c.__setitem__("brow_right_upper", [[1.0, 2.0], [np.nan, 3.0]]), "must be finite"),
        (lambda c: c.__setitem__("brow_right_upper", [[1.0, 2.0], [900.0, 3.0]]), "outside the 256x256 image"),
        (lambda c: c.__setitem__("mouth_outer_upper", [[90.0, 70.0]] * 5), "mouth_outer_upper ends where it starts"),
    ],
)
def test_bad_contours_are_refused(change, message):
    frame0, truth0 = band_face()
    contours = {k: v.tolist() for k, v in truth0.items()}
    change(contours)
    with pytest.raises(InvalidInputError, match=message):
        Tracker(frame0, contours)


def test_bad_frames_are_refused():
    frame0, truth0 = band_face()
    with pytest.raises(InvalidInputError, match="RGB"):
        Tracker(frame0[..., 0], truth0)
    tracker = Tracker(frame0, truth0)
    with pytest.raises(InvalidInputError, match="frame size changed"):
        tracker.update(frame0[:100])
    with pytest.raises(InvalidInputError, match="operator must be one of"):
        Tracker(frame0, truth0, TrackerParams(operator="laplace"))


#: Per group, the mean and the largest NME allowed on either video: about 1.5x the measured
#: values (mean, max; vr_2 / lp_d0): mouth outer 0.0145 / 0.0155, 0.042 / 0.035; mouth inner
#: 0.0179 / 0.0174, 0.056 / 0.033 (its max kept at the earlier 0.06); brows 0.0054 / 0.0053,
#: 0.0080 / 0.0081.
LIMITS = {"mouth_outer": (0.023, 0.06), "mouth_inner": (0.027, 0.06), "brows": (0.008, 0.012)}


@pytest.mark.parametrize(("name", "count"), [("vr_2", 40), ("lp_d0", 78)])
def test_tracks_a_real_talking_face(shared, name, count):
    # lp_d0 opens her mouth wide and closes it again: with a rest shape that could not change
    # (TrackerParams(mouth_affine=0)) the inner lips stayed behind (mean NME 0.044, max 0.08).
    from facemime.io.video import VideoReader
    from facemime.types.contours import from_face_mesh as reference_contours

    z = np.load(shared / "video" / f"{name}.landmarks.npz")
    with VideoReader(shared / "video" / f"{name}.mp4") as reader:
        frames = [f for _, f in zip(range(count), reader)]
    tracker = Tracker(frames[0], reference_contours(z["landmarks"][0]))
    errors = {g: [] for g in GROUPS}
    for i in range(1, len(frames)):
        result = tracker.update(frames[i])
        for g, names in GROUPS.items():
            errors[g].append(
                group_nme(result.contours, reference_contours(z["landmarks"][i]), names, float(z["iod"][i]))
            )
    for g, e in errors.items():
        mean, most = LIMITS[g]
        assert np.mean(e) < mean and max(e) < most, (g, np.mean(e), max(e))


@pytest.mark.parametrize("fast", [0.0, 1e9])
def test_the_frame_call_solves_as_building_the_field_and_solving_pass_by_pass(fast):
    # SnakeSolver.track (field, a pass, the mouth's further passes while it moves `fast` px)
    # against the separate calls it replaces: fast 0 always takes the mouth's second pass,
    # 1e9 never does.
    frame0, truth0 = band_face(noise=2.0)
    tracker = Tracker(frame0, truth0)
    frame = band_face(noise=2.0, seed=5, shift=(1.5, 1.0), opening=1.5)[0]
    t, p = tracker, tracker.params
    start, rest, down, targets = t._knots + [1.0, -0.5], t._knots0, t._down0, t._targets0
    knots, iters, resp = t._solver.track(
        frame,
        None,
        start,
        rest,
        tuple(down),
        targets,
        (t.width, t.height),
        p.smoothing,
        t._frame_bands,
        t._mouth_uintp,
        t._mouth_curves,
        p.mouth_passes,
        fast,
    )
    field = t._field(frame, start)
    want, want_iters, want_resp = t._solve(field, start, rest, down, targets)
    if fast == 0.0:
        mouth, curves = t._mouth_knots, t._mouth_curves
        again, more, again_resp = t._solve(field, want.copy(), rest, down, targets, curves)
        want[mouth], want_resp[curves], want_iters = again[mouth], again_resp[curves], want_iters + more
    np.testing.assert_array_equal(knots, want)
    np.testing.assert_array_equal(resp, want_resp)
    assert iters == want_iters
