import threading

import av
import numpy as np
import pytest

from facemime.errors import InputFileError, InvalidInputError, OutputFileError
from facemime.io import VideoWriter, check_outputs
from facemime.io.outputs import OutputExistsError
from facemime.io.video import VideoReader


@pytest.mark.parametrize(("suffix", "codec"), [(".mp4", "h264"), (".webm", "vp9")])
def test_written_video_plays_back(tmp_path, suffix, codec):
    path = tmp_path / f"clip{suffix}"
    frames = [np.full((31, 45, 3), 25 * i, np.uint8) for i in range(8)]  # odd size gets padded
    with VideoWriter(path, fps=25) as w:
        for f in frames:
            w.write(f)
    with av.open(str(path)) as c:
        stream = c.streams.video[0]
        decoded = [f.to_ndarray(format="rgb24") for f in c.decode(stream)]
        assert stream.codec_context.name == codec and stream.codec_context.pix_fmt == "yuv420p"
    assert len(decoded) == 8 and decoded[0].shape == (32, 46, 3)
    assert abs(int(decoded[5][10, 10, 0]) - 125) <= 3
    assert [p.name for p in tmp_path.iterdir()] == [path.name]  # no temporary file left


@pytest.mark.parametrize("suffix", [".mp4", ".webm"])
def test_colours_survive_writing_and_reading(tmp_path, suffix):
    """Red, green, blue, skin and grey blocks come back as themselves (the encoder's colour
    conversion is RGB, not BGR, and of FFmpeg's range)."""
    colours = np.array([[230, 40, 40], [40, 200, 60], [50, 60, 220], [224, 172, 140], [128, 128, 128]], np.uint8)
    frame = np.repeat(np.repeat(colours[None], 32, axis=0), 32, axis=1)  # 32 x 160, one block per colour
    with VideoWriter(tmp_path / f"c{suffix}", fps=25) as w:
        for _ in range(3):
            w.write(frame)
    with VideoReader(tmp_path / f"c{suffix}") as r:
        back = list(r)
    assert len(back) == 3
    centres = back[-1][16, 16::32].astype(int)
    assert np.abs(centres - colours).max() <= 6, centres.tolist()


def test_failed_write_leaves_nothing(tmp_path):
    path = tmp_path / "clip.mp4"
    with pytest.raises(RuntimeError), VideoWriter(path, fps=10) as w:
        w.write(np.zeros((16, 16, 3), np.uint8))
        raise RuntimeError("interrupted")
    assert list(tmp_path.iterdir()) == []


def test_a_reused_frame_buffer_is_written_as_it_was_at_each_write(tmp_path):
    """Frames are encoded beside the caller's work; the caller may refill its buffer at once."""
    buffer = np.empty((16, 32, 3), np.uint8)
    with VideoWriter(tmp_path / "c.mp4", fps=25) as w:
        for level in (20, 120, 220, 70):
            buffer[...] = level
            w.write(buffer)
    with VideoReader(tmp_path / "c.mp4") as r:
        levels = [int(f.mean().round()) for f in r]
    assert np.allclose(levels, [20, 120, 220, 70], atol=3), levels


def test_an_encoding_error_is_one_line_and_leaves_nothing(tmp_path, monkeypatch):
    def disk_full(*args, **kwargs):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(av.VideoFrame, "from_ndarray", disk_full)
    with (
        pytest.raises(OutputFileError, match=r"cannot write video .*clip\.mp4: No space left on device"),
        VideoWriter(tmp_path / "clip.mp4", fps=25) as w,
    ):
        for _ in range(3 * VideoWriter.QUEUED):  # more than the queue holds: no writer waits forever
            w.write(np.zeros((16, 16, 3), np.uint8))
    assert list(tmp_path.iterdir()) == []


def test_bad_video_arguments(tmp_path):
    with pytest.raises(InvalidInputError, match=r"must end in \.mp4 or \.webm"):
        VideoWriter(tmp_path / "x.avi", 25)
    with pytest.raises(InvalidInputError, match="size changed"), VideoWriter(tmp_path / "x.mp4", 25) as w:
        w.write(np.zeros((16, 16, 3), np.uint8))
        w.write(np.zeros((18, 16, 3), np.uint8))
    assert list(tmp_path.iterdir()) == []


def test_existing_outputs_are_not_overwritten_without_force(tmp_path):
    (tmp_path / "a.png").write_bytes(b"mine")
    with pytest.raises(OutputExistsError, match=r"a.png already exists; use --force"):
        check_outputs([tmp_path / "a.png", tmp_path / "b.png"], force=False)
    check_outputs([tmp_path / "a.png"], force=True)
    assert (tmp_path / "a.png").read_bytes() == b"mine"


def test_long_output_names_are_written_and_too_long_ones_refused_in_one_line(tmp_path):
    from facemime.io.outputs import NAME_MAX, Outputs

    longest = tmp_path / ("b" * (NAME_MAX - 4) + ".vrm")  # a legal name: its temporary one is cut to fit
    with Outputs([longest], force=False) as out:
        out.stage(longest).write_bytes(b"avatar")
    assert longest.read_bytes() == b"avatar" and [p.name for p in tmp_path.iterdir()] == [longest.name]
    with pytest.raises(InvalidInputError, match=f"its name is over {NAME_MAX} bytes long") as e:
        check_outputs([tmp_path / ("a" * 300 + ".vrm")], force=False)
    assert "\n" not in str(e.value)


def _decoders() -> list[str]:
    return [t.name for t in threading.enumerate() if t.name.startswith("decoder ")]


def _levels_clip(path, count: int) -> None:
    with VideoWriter(path, fps=25) as w:
        for i in range(count):
            w.write(np.full((16, 32, 3), 10 + 9 * i, np.uint8))


def test_frames_decoded_ahead_come_in_order_and_the_decoder_ends(tmp_path):
    count = 3 * VideoReader.AHEAD  # more than the decoder queues
    _levels_clip(tmp_path / "c.mp4", count)
    with VideoReader(tmp_path / "c.mp4") as r:
        levels = [int(f.mean().round()) for f in r]
        assert _decoders() == []
    assert np.allclose(levels, [10 + 9 * i for i in range(count)], atol=3), levels


def test_stopping_early_stops_the_decoder(tmp_path):
    _levels_clip(tmp_path / "c.mp4", 3 * VideoReader.AHEAD)
    with VideoReader(tmp_path / "c.mp4") as r:
        for index, _ in enumerate(r):
            if index == 1:
                break
        assert _decoders() == []
    with VideoReader(tmp_path / "c.mp4") as r:
        frames = iter(r)
        next(frames)
        r.close()  # while the caller still holds the iteration
        assert _decoders() == []
        assert list(frames) == []


class _FailingConverter:
    """Converts frames as PyAV does until the ``fail_at``-th, which raises an FFmpeg error."""

    def __init__(self, fail_at: int):
        self.calls, self.fail_at = 0, fail_at

    def reformat(self, frame, **kwargs):
        self.calls += 1
        if self.calls == self.fail_at:
            raise av.InvalidDataError(1094995529, "Invalid data found when processing input")
        return frame.reformat(**kwargs)


def test_a_decoding_error_reaches_the_caller_as_one_line_where_it_happened(tmp_path):
    _levels_clip(tmp_path / "c.mp4", 12)
    with VideoReader(tmp_path / "c.mp4") as r:
        r._to_rgb = _FailingConverter(fail_at=5)
        got = []
        with pytest.raises(InputFileError, match=r"^cannot decode video .*c\.mp4: Invalid data found"):
            for frame in r:
                got.append(frame)
        assert len(got) == 4 and _decoders() == []
