"""A performance written by hand as expression weights (a ``facemime.track/1`` file with
``weights`` and no ``offsets``) plays through `facemime run` and through `facemime encode` +
`facemime decode`; a track from `facemime run` on a real clip encodes too; bad input, one line."""

import json

import numpy as np

from facemime.animate.deform import Deformer
from facemime.animate.expressions import NAMES, Expressions
from facemime.animate.motion_file import read_motion
from facemime.codec.clip import read_stream
from facemime.codec.decoder import MotionDecoder
from facemime.codec.stream import COEFFICIENT_STEP, DEFAULT_QUALITY, LADDER
from facemime.fit.actor import generic_actor
from facemime.head import generic_head
from facemime.io.video import VideoReader
from facemime.types.pose import project

from .test_cli import first_frames, run

SIZE = (320, 240)
#: The performance: still, the jaw opening, open, a smile, a blink, and a frame without a face.
WEIGHTS = [
    {},
    {"jawOpen": 0.5},
    {"jawOpen": 1.0},
    {"mouthSmileLeft": 1.0, "mouthSmileRight": 1.0},
    {"eyeBlinkLeft": 1.0, "eyeBlinkRight": 1.0},
    {},
]


def write_performance(path):
    """The performance as a hand-written track file: a pose framing the generic head, weights."""
    pose = generic_actor(SIZE).pose
    frames = [
        {"index": i, "pose": {k: getattr(pose, k) for k in ("yaw", "pitch", "roll", "scale", "tx", "ty")}, "weights": w}
        for i, w in enumerate(WEIGHTS)
    ]
    frames[-1].update(face=False, lost=["mouth_inner"])
    path.write_text(
        json.dumps(
            {"format": "facemime.track/1", "video": {"width": SIZE[0], "height": SIZE[1], "fps": 10}, "frames": frames}
        )
    )
    return path


def weight_matrix():
    return np.array([[w.get(n, 0.0) for n in NAMES] for w in WEIGHTS])


def region(groups, margin):
    """(rows, columns) slices around the generic head's ``groups`` as the performance shows them."""
    head = generic_head()
    points = project(head.vertices[np.concatenate([head.groups[g] for g in groups])], generic_actor(SIZE).pose)[0]
    (x0, y0), (x1, y1) = np.floor(points.min(axis=0)).astype(int), np.ceil(points.max(axis=0)).astype(int)
    return slice(y0 - margin, y1 + margin), slice(x0 - margin, x1 + margin)


def test_a_performance_written_as_weights_plays_through_run(tmp_path, capsys):
    track = write_performance(tmp_path / "performance.json")
    code, out, err = run(capsys, "run", str(track), "--out", str(tmp_path / "p.mp4"))
    assert code == 0, err
    assert out.split() == [str(tmp_path / "p.mp4")] and "played 6 frames" in err and "no face in 1 frames" in err
    frames = [f.astype(float) for f in VideoReader(tmp_path / "p.mp4")]
    assert len(frames) == len(WEIGHTS) and frames[0].shape == (SIZE[1], SIZE[0], 3)
    mouth = region(["mouth_outer_upper", "mouth_outer_lower"], 6)
    brows = region(["brow_left_upper", "brow_right_upper"], 0)
    forehead = (slice(brows[0].start - 20, brows[0].start - 2), brows[1])
    change = lambda a, b, r: np.abs(frames[a][r] - frames[b][r]).mean()  # noqa: E731
    assert change(2, 0, mouth) > 15 and change(3, 0, mouth) > 6  # the jaw opens, the mouth smiles
    assert change(2, 0, forehead) < 1.5 and change(3, 0, forehead) < 1.5  # the forehead stays
    eyes = region(["eye_right", "eye_left"], 2)
    assert change(4, 0, eyes) > 10 and change(4, 0, mouth) < 3  # the blink closes the eyes (H.264 noise)
    assert np.abs(frames[5] - frames[0] * 0.45).mean() < 3  # the frame without a face: dimmed


def test_a_performance_written_as_weights_encodes_and_decodes(tmp_path, capsys):
    track = write_performance(tmp_path / "performance.json")
    stream = tmp_path / "p.fmstream"
    code, out, err = run(capsys, "encode", str(track), "--out", str(stream))
    assert code == 0 and out.split() == [str(stream)] and "encoded 6 frames" in err, err
    code, _, err = run(capsys, "decode", str(stream), "--out", str(tmp_path / "d.mp4"))
    assert code == 0, err
    video = list(VideoReader(tmp_path / "d.mp4"))
    assert len(video) == len(WEIGHTS) and video[0].shape == (SIZE[1], SIZE[0], 3)
    decoder = MotionDecoder()
    decoded = decoder.push(read_stream(stream)) + decoder.finish()
    assert len(decoded) == len(WEIGHTS) and decoder.info.fps == 10 and decoder.info.size == SIZE
    expressions = Expressions.of(generic_head())
    faces = [f.face for f in decoded]
    offsets = np.array([f.offsets for f in decoded])[:5]
    step = COEFFICIENT_STEP * LADDER[DEFAULT_QUALITY][0]  # the coefficients' quantiser step, mm
    assert np.abs(offsets - expressions.offsets(weight_matrix()[:5])).max() < step
    assert np.abs(offsets[2]).max() > 20  # the jaw moved millimetres: the comparison means something
    assert np.allclose(decoded[4].look.closure, expressions.closure(weight_matrix()[4]), atol=0.05)
    assert faces == [True] * 5 + [False] and decoded[5].lost == ["mouth_inner"]


def test_a_track_from_run_on_a_real_clip_encodes(shared, tmp_path, capsys):
    clip = first_frames(shared / "video" / "lp_d0.mp4", 8, tmp_path / "lp_d0.mp4")
    code, _, err = run(capsys, "run", str(clip), "--out", str(tmp_path / "run.mp4"))
    assert code == 0, err
    stream = tmp_path / "run.fmstream"
    code, _, err = run(capsys, "encode", str(tmp_path / "run.json"), "--quality", "10", "--out", str(stream))
    assert code == 0 and "encoded 8 frames" in err and "the actor" in err, err
    decoder = MotionDecoder()
    decoded = decoder.push(read_stream(stream)) + decoder.finish()
    assert len(decoded) == 8 and decoder.info.size == (512, 512) and decoder.info.fps == 25
    # the generic head carries the motion, scaled from the clip's face to its own
    _, model, motion = read_motion(tmp_path / "run.json")
    ratio = Deformer(generic_head()).feature_sizes() / np.array(model["feature_sizes"])
    want = np.array([m["offsets"] for m in motion]) * ratio[None, :, None]
    assert np.abs(np.array([f.offsets for f in decoded]) - want).max() < COEFFICIENT_STEP * LADDER[10][0]
    code, _, err = run(capsys, "decode", str(stream), "--out", str(tmp_path / "d.mp4"))
    assert code == 0 and len(list(VideoReader(tmp_path / "d.mp4"))) == 8, err


def test_bad_tracks_and_options_that_need_a_video_give_one_line(tmp_path, capsys):
    track = write_performance(tmp_path / "performance.json")
    cut = tmp_path / "cut.json"
    cut.write_text(track.read_text()[:200])
    unknown = tmp_path / "unknown.json"
    unknown.write_text(track.read_text().replace("jawOpen", "jawOpened"))
    cases = [
        (["run", str(cut), "--out", str(tmp_path / "x.mp4")], "is not valid JSON"),
        (["encode", str(cut), "--out", str(tmp_path / "x.fmstream")], "is not valid JSON"),
        (["run", str(unknown), "--out", str(tmp_path / "x.mp4")], "unknown expression weight 'jawOpened'"),
        (["encode", str(track), "--appearance", "5", "--out", str(tmp_path / "x.fmstream")], "is a track file"),
        (["run", str(track), "--track", str(tmp_path / "x.json"), "--out", str(tmp_path / "x.mp4")], "is a track file"),
        (
            ["run", str(track), "--weights", str(tmp_path / "x.csv"), "--out", str(tmp_path / "x.mp4")],
            "is a track file",
        ),
    ]
    for args, message in cases:
        code, out, err = run(capsys, *args)
        assert code == 1 and out == "" and err.startswith("facemime: error:") and err.count("\n") == 1, (args, err)
        assert message in err, (args, err)
    assert not any((tmp_path / n).exists() for n in ("x.mp4", "x.fmstream", "x.json", "x.csv"))
