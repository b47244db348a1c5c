"""`facemime encode` / `facemime decode`: a video to a stream and back to a video of the
synthesised face, with the actor carried or named, and one-line errors for bad input."""

import re

import cv2
import numpy as np
import pytest

from codec.reference_decoder import chunks
from facemime.io.actor_file import save_actor
from facemime.io.video import VideoReader
from facemime.shared_constants import BACKGROUND

from .test_cli import first_frames, run

FRAMES = 50


@pytest.fixture(scope="module")
def clip(shared, tmp_path_factory):
    return first_frames(shared / "video" / "lp_d0.mp4", FRAMES, tmp_path_factory.mktemp("clip") / "lp_d0.mp4")


@pytest.fixture(scope="module")
def stream(clip, tmp_path_factory):
    out = tmp_path_factory.mktemp("enc") / "lp_d0.fmstream"
    from facemime.cli.main import main

    with pytest.raises(SystemExit) as exc:
        main(["encode", str(clip), "--out", str(out)])
        raise SystemExit(0)
    assert (exc.value.code or 0) == 0
    return out


def test_encode_then_decode_gives_the_synthesised_picture_at_the_videos_size(stream, clip, tmp_path, capsys):
    code, out, err = run(capsys, "decode", str(stream), "--out", str(tmp_path / "face.mp4"))
    assert code == 0, err
    assert out.split() == [str(tmp_path / "face.mp4")]
    assert f"decoded {FRAMES} frames" in err
    frames = list(VideoReader(tmp_path / "face.mp4"))
    assert len(frames) == FRAMES and frames[0].shape == (512, 512, 3)
    real = list(VideoReader(clip))[25]
    mse = np.mean((frames[25].astype(float) - real) ** 2)
    assert 10 * np.log10(255**2 / mse) > 24  # the face in its scene: the whole picture resembles the video's


def test_decode_mask_only_shows_the_face_alone_mid_picture(stream, tmp_path, capsys):
    code, _, err = run(capsys, "decode", str(stream), "--mask-only", "--out", str(tmp_path / "face.mp4"))
    assert code == 0, err
    frames = list(VideoReader(tmp_path / "face.mp4"))
    face = np.abs(frames[25].astype(int) - BACKGROUND).sum(axis=2) > 30
    ys, xs = np.nonzero(face)
    assert 0.1 < face.mean() < 0.5 and 150 < xs.mean() < 360 and 150 < ys.mean() < 360  # a face, mid-picture


def test_encode_reports_the_motions_rate_and_the_actors_bytes(clip, tmp_path, capsys):
    code, _, err = run(capsys, "encode", str(clip), "--rate", "1", "--out", str(tmp_path / "s.fmstream"))
    assert code == 0, err
    m = re.search(
        r"motion ([\d.]+) kbit/s .* header (\d+) bytes, the actor (\d+) bytes once, its scene (\d+) of them", err
    )
    assert m and float(m[1]) <= 1.0 and int(m[3]) > int(m[4]) > 5000


def test_a_stream_naming_its_actor_decodes_only_with_that_actor(clip, shared, tmp_path, capsys):
    from facemime.codec.clip import analyse

    own, other = tmp_path / "own.actor", tmp_path / "other.actor"
    save_actor(own, analyse(clip).actor)
    code, _, err = run(capsys, "fit", str(shared / "video" / "vr_1.mp4"), "--out", str(other))
    assert code == 0, err
    code, _, err = run(capsys, "encode", str(clip), "--actor", str(own), "--out", str(tmp_path / "s.fmstream"))
    assert code == 0 and "the actor named" in err
    for args, message in (([], "does not carry its actor"), (["--actor", str(other)], "another actor")):
        code, out, err = run(capsys, "decode", str(tmp_path / "s.fmstream"), *args, "--out", str(tmp_path / "x.mp4"))
        assert code == 1 and out == "" and err.count("\n") == 1 and message in err, err
        assert not (tmp_path / "x.mp4").exists()
    code, _, err = run(
        capsys, "decode", str(tmp_path / "s.fmstream"), "--actor", str(own), "--out", str(tmp_path / "x.mp4")
    )
    assert code == 0, err


def test_bad_streams_and_outputs_give_one_line(stream, tmp_path, capsys):
    cut = tmp_path / "cut.fmstream"
    cut.write_bytes(stream.read_bytes()[:1000])  # inside the header
    damaged = tmp_path / "damaged.fmstream"
    data = bytearray(stream.read_bytes())
    *_, (_, _, _, before), (_, _, _, last) = chunks(bytes(data))
    data[-8 - len(last) - len(before) // 2] ^= 0x10  # inside the packet before the last: concealed, not an error
    damaged.write_bytes(bytes(data))
    (tmp_path / "exists.mp4").write_bytes(b"mine")
    photo = tmp_path / "photo.fmstream"
    photo.write_bytes(cv2.imencode(".png", np.zeros((8, 8, 3), np.uint8))[1].tobytes())
    cases = [
        (["decode", str(tmp_path / "none.fmstream")], "does not exist"),
        (["decode", str(photo)], "is not a facemime stream"),
        (["decode", str(cut)], "header is damaged or cut short"),
        (["decode", str(stream), "--out", str(tmp_path / "x.avi")], "must end in .mp4 or .webm"),
        (["encode", str(stream), "--out", str(tmp_path / "x.mp4")], "must end in .fmstream"),
    ]
    for args, message in cases:
        if "--out" not in args:
            args = [*args, "--out", str(tmp_path / "x.mp4")]
        code, out, err = run(capsys, *args)
        assert code == 1 and out == "" and err.startswith("facemime: error:") and err.count("\n") == 1, (args, err)
        assert message in err, (args, err)
    assert not (tmp_path / "x.mp4").exists()
    code, _, err = run(capsys, "decode", str(stream), "--out", str(tmp_path / "exists.mp4"))
    assert code == 1 and "already exists" in err and (tmp_path / "exists.mp4").read_bytes() == b"mine"
    code, _, err = run(capsys, "decode", str(damaged), "--out", str(tmp_path / "d.mp4"))
    assert code == 0 and "concealed" in err, err
    assert len(list(VideoReader(tmp_path / "d.mp4"))) == FRAMES


def test_quality_and_rate_are_one_or_the_other(clip, tmp_path, capsys):
    code, _out, err = run(
        capsys, "encode", str(clip), "--quality", "3", "--rate", "1", "--out", str(tmp_path / "s.fmstream")
    )
    assert code == 1 and "not both" in err and not (tmp_path / "s.fmstream").exists()


def test_appearance_updates_are_sent_within_their_budget_and_applied(clip, tmp_path, capsys):
    code, _, err = run(capsys, "encode", str(clip), "--appearance", "8", "--out", str(tmp_path / "s.fmstream"))
    assert code == 0, err
    m = re.search(r"appearance ([\d.]+) kbit/s \((\d+) updates, (\d+) bytes\)", err)
    assert m and 0 < float(m[1]) <= 8.0 and int(m[2]) > 0, err
    code, _, err = run(capsys, "decode", str(tmp_path / "s.fmstream"), "--out", str(tmp_path / "x.mp4"))
    assert code == 0 and f"{m[2]} appearance updates" in err, err
    for bad in ("-1", "nan", "5000"):
        code, out, err = run(capsys, "encode", str(clip), "--appearance", bad, "--out", str(tmp_path / "b.fmstream"))
        assert code == 1 and out == "" and err.count("\n") == 1 and "appearance budget" in err, err
    assert not (tmp_path / "b.fmstream").exists()
