"""VideoReader on real-world input: phone videos stored sideways with a rotation, any frame rate,
files none of whose frames decode, truncated files; and the decode-ahead queue's bound in bytes."""

import math
import struct
from pathlib import Path

import av
import numpy as np
import pytest

from facemime.errors import InputFileError, InvalidInputError
from facemime.io import VideoWriter
from facemime.io.video import VideoReader

SHARED = Path(__file__).resolve().parents[3] / "shared" / "data" / "video" / "lp_d0.mp4"
#: Skipped without the shared data, failed without it when CI is set (the ``shared`` fixture).
needs_shared = pytest.mark.usefixtures("shared")


def _shared_frames(count: int) -> list[np.ndarray]:
    """The first ``count`` frames of a shared face video, cropped to 512 wide by 384 high."""
    with av.open(str(SHARED)) as c:
        return [f.to_ndarray(format="rgb24")[64:448] for _, f in zip(range(count), c.decode(video=0))]


def _encode(
    path: Path, frames: list[np.ndarray], fmt: str = "mp4", metadata: dict | None = None, options: dict | None = None
) -> None:
    """H.264 (x264 defaults) in ``fmt``, 25 fps, with ``metadata`` tags on the video stream."""
    with av.open(str(path), "w", format=fmt, options=options or {}) as out:
        stream = out.add_stream("libx264", rate=25)
        stream.height, stream.width = frames[0].shape[:2]
        stream.pix_fmt = "yuv420p"
        stream.metadata.update(metadata or {})
        for a in frames:
            out.mux(stream.encode(av.VideoFrame.from_ndarray(np.ascontiguousarray(a), format="rgb24")))
        out.mux(stream.encode())


def _set_track_rotation(path: Path, clockwise: int) -> None:
    """Write a rotation into the MP4 track header's matrix, as phones do: the player turns the
    stored frames ``clockwise`` degrees (a multiple of 90) to show them."""
    data = bytearray(path.read_bytes())
    at = data.index(b"tkhd") + 4
    assert data[at] == 0  # version 0: 32-bit times
    matrix = at + 4 + 5 * 4 + 8 + 8  # after version/flags, times, track, duration; layer .. volume
    c, s = {90: (0, 1), 180: (-1, 0), 270: (0, -1)}[clockwise]
    data[matrix : matrix + 36] = struct.pack(">9i", c << 16, s << 16, 0, -s << 16, c << 16, 0, 0, 0, 1 << 30)
    path.write_bytes(data)


@needs_shared
@pytest.mark.parametrize("clockwise", [90, 180, 270])
def test_a_rotated_phone_video_is_read_upright(tmp_path, clockwise):
    upright = _shared_frames(20)
    path = tmp_path / "phone.mp4"
    _encode(path, [np.rot90(f, clockwise // 90) for f in upright])  # stored turned the other way
    _set_track_rotation(path, clockwise)
    with VideoReader(path) as r:
        assert (r.width, r.height, r.frames) == (512, 384, 20)
        frames = list(r)
    assert r.rotation == (360 - clockwise) % 360
    assert len(frames) == 20 and all(f.shape == (384, 512, 3) and f.flags.c_contiguous for f in frames)
    errors = [np.abs(f.astype(int) - u).mean() for f, u in zip(frames, upright)]
    assert max(errors) < 4, errors  # only the encoding's loss


@needs_shared
def test_a_rotate_tag_turns_frames_upright(tmp_path):
    """Tools that write no display matrix leave a ``rotate`` tag (degrees clockwise)."""
    upright = _shared_frames(5)
    path = tmp_path / "tagged.mkv"
    _encode(path, [np.rot90(f, 1) for f in upright], fmt="matroska", metadata={"rotate": "90"})
    with VideoReader(path) as r:
        assert (r.width, r.height, r.rotation) == (512, 384, 270)
        frames = list(r)
    assert max(np.abs(f.astype(int) - u).mean() for f, u in zip(frames, upright)) < 4


def test_an_unrotated_video_keeps_its_frames(tmp_path):
    frames = [np.full((16, 32, 3), 40 * i, np.uint8) for i in range(3)]
    with VideoWriter(tmp_path / "c.mp4", fps=25) as w:
        for f in frames:
            w.write(f)
    with VideoReader(tmp_path / "c.mp4") as r:
        assert (r.width, r.height, r.rotation) == (32, 16, 0)
        assert [f.shape for f in r] == [(16, 32, 3)] * 3


@pytest.mark.parametrize("fps", [300, 1000, 2.5])
def test_any_frame_rate_is_written_and_read(tmp_path, fps):
    with VideoWriter(tmp_path / "fast.mp4", fps=fps) as w:
        for i in range(10):
            w.write(np.full((16, 16, 3), 20 * i, np.uint8))
    with VideoReader(tmp_path / "fast.mp4") as r:
        assert r.fps == pytest.approx(fps) and len(list(r)) == 10 and r.warnings == []


@pytest.mark.parametrize("fps", [0, -25, math.inf, math.nan])
def test_a_frame_rate_that_is_not_positive_and_finite_is_refused(tmp_path, fps):
    with pytest.raises(InvalidInputError, match="fps must be positive and finite"):
        VideoWriter(tmp_path / "x.mp4", fps=fps)


def _clip(path: Path, count: int) -> bytes:
    """A ``count``-frame faststart MP4 of a shared video's frames (of noise without it); its bytes."""
    frames = (
        _shared_frames(count)
        if SHARED.exists()
        else list(np.random.default_rng(0).integers(0, 255, (count, 384, 512, 3), np.uint8))
    )
    _encode(path, frames, options={"movflags": "+faststart"})
    return path.read_bytes()


def test_a_video_no_frame_of_which_decodes_is_refused_as_such(tmp_path):
    data = _clip(tmp_path / "good.mp4", 10)
    payload = data.index(b"mdat") + 4
    (tmp_path / "zeros.mp4").write_bytes(data[:payload] + bytes(len(data) - payload))  # the frames' data zeroed
    with pytest.raises(InputFileError, match=r"^video .*zeros\.mp4 has no decodable frames$"):
        VideoReader(tmp_path / "zeros.mp4")


def test_a_video_whose_codec_is_damaged_is_refused_in_one_line(tmp_path):
    """A damaged header can leave the stream's codec unknown (FFmpeg opens it with no decoder)."""
    data = _clip(tmp_path / "good.mp4", 10)
    at = data.index(b"avc1", data.index(b"moov"))
    (tmp_path / "bad.mp4").write_bytes(data[:at] + b"zzzz" + data[at + 4 :])
    with pytest.raises(InputFileError, match=r"bad\.mp4: its video stream's codec is unknown"):
        VideoReader(tmp_path / "bad.mp4")


def test_a_stream_header_without_frames_is_refused_as_such(tmp_path):
    """An MPEG-TS cut after its stream tables: FFmpeg guesses 90000 fps from the time base."""
    with av.open(str(tmp_path / "c.ts"), "w") as out:
        stream = out.add_stream("libx264", rate=25)
        stream.width = stream.height = 64
        for i in range(5):
            out.mux(stream.encode(av.VideoFrame.from_ndarray(np.full((64, 64, 3), 40 * i, np.uint8), format="rgb24")))
        out.mux(stream.encode())
    (tmp_path / "head.ts").write_bytes((tmp_path / "c.ts").read_bytes()[: 3 * 188])
    with pytest.raises(InputFileError, match=r"^video .*head\.ts has no decodable frames$"):
        VideoReader(tmp_path / "head.ts")


def test_a_truncated_video_is_read_with_a_warning(tmp_path):
    data = _clip(tmp_path / "full.mp4", 60)
    payload = data.index(b"mdat")
    (tmp_path / "cut.mp4").write_bytes(data[: payload + (len(data) - payload) // 3])
    with VideoReader(tmp_path / "full.mp4") as r:
        assert len(list(r)) == 60 and r.decoded == 60 and r.warnings == []
    with VideoReader(tmp_path / "cut.mp4") as r:
        assert r.frames == 60 and r.warnings == []
        frames = list(r)
    assert 0 < len(frames) == r.decoded < 40
    assert (
        r.warnings[0] == f"video {tmp_path / 'cut.mp4'} ended after {len(frames)} of the 60 frames its "
        "container declares (a truncated file?)"
    )
    assert all("\n" not in w for w in r.warnings)


def test_stopping_early_gives_no_truncation_warning(tmp_path):
    _clip(tmp_path / "c.mp4", 12)
    with VideoReader(tmp_path / "c.mp4") as r:
        for index, _ in enumerate(r):
            if index == 2:
                break
        assert r.decoded == 3 and r.warnings == []


def test_frames_decoded_ahead_are_bounded_in_bytes(tmp_path, monkeypatch):
    _clip(tmp_path / "c.mp4", 12)
    monkeypatch.setattr(VideoReader, "AHEAD_BYTES", 2 * 512 * 384 * 3 + 1)
    with VideoReader(tmp_path / "c.mp4") as r:
        frames = iter(r)
        next(frames)
        assert r._decoding[2].maxsize == 2
        assert len(list(frames)) == 11
    monkeypatch.setattr(VideoReader, "AHEAD_BYTES", 1)
    with VideoReader(tmp_path / "c.mp4") as r:
        frames = iter(r)
        next(frames)
        assert r._decoding[2].maxsize == 1  # one frame at least
