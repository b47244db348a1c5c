import subprocess
import sys

import av
import cv2
import numpy as np
import pytest

from facemime.cli.main import main


def first_frames(source, count, path):
    """A clip of the first ``count`` frames of video ``source``, written (H.264) to ``path``."""
    from facemime.io.video import VideoWriter

    with av.open(str(source)) as c, VideoWriter(path, fps=25) as w:
        for _, frame in zip(range(count), c.decode(video=0)):
            w.write(frame.to_ndarray(format="rgb24"))
    return path


def run(capsys, *args):
    with pytest.raises(SystemExit) as exc:
        main(list(args))
        raise SystemExit(0)
    out, err = capsys.readouterr()
    return exc.value.code or 0, out, err


def test_demo_fits_animates_tracks_back_and_resynthesises(tmp_path, capsys):
    from facemime.app.demo import FILES

    code, out, err = run(capsys, "demo", "--out", str(tmp_path / "d"))
    assert code == 0, err
    assert out.split() == [str(tmp_path / "d" / n) for n in FILES]
    assert {p.name for p in (tmp_path / "d").iterdir()} == set(FILES)
    with av.open(str(tmp_path / "d" / "resynthesis.mp4")) as c:
        s = c.streams.video[0].codec_context
        assert (s.name, s.width, s.height) == ("h264", 1536, 512)
        assert sum(1 for _ in c.decode(video=0)) == 150
    # Tracked back from an automatic start, the contours stay on the known truth.
    report = (tmp_path / "d" / "report.html").read_text()
    import re

    means = [float(m) for m in re.findall(r"<tr><td>(?:mouth outer|mouth inner|brows)</td><td>([0-9.]+)</td>", report)]
    assert len(means) == 3 and max(means) < 0.03
    assert 'src="resynthesis.mp4"' in report and 'src="stills.png"' in report
    stills = cv2.imread(str(tmp_path / "d" / "stills.png"))
    assert stills.shape == (1024, 768, 3)
    for col in range(3):  # each panel of each still shows a face, not the empty backdrop
        panel = stills[:256, 256 * col : 256 * (col + 1)].astype(int)
        assert (np.abs(panel - panel[5, 5]).sum(axis=2) > 60).mean() > 0.1
    # A second run refuses to overwrite, in one line, and changes nothing.
    before = (tmp_path / "d" / "resynthesis.mp4").stat().st_mtime_ns
    code, out, err = run(capsys, "demo", "--out", str(tmp_path / "d"))
    assert code == 1 and err.count("\n") == 1 and err.startswith("facemime: error:") and "--force" in err
    assert (tmp_path / "d" / "resynthesis.mp4").stat().st_mtime_ns == before


def test_model_preview_of_a_candide_file(tmp_path, capsys, candide_path):
    code, out, _ = run(capsys, "model-preview", str(candide_path), "--out", str(tmp_path / "c.png"))
    assert code == 0 and out.strip() == str(tmp_path / "c.png")
    assert cv2.imread(str(tmp_path / "c.png")).shape == (320, 1600, 3)


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["model-preview", "missing.wfm", "--out", "x.png"], "missing.wfm: no such model file"),
        (["model-preview", "BAD", "--out", "y.png"], "not valid JSON"),
        (["model-preview", "--out", "y.gifx"], "its name must end in one of .png"),
        (["model-preview", "--out", "/proc/preview.png"], "cannot write /proc/preview.png"),
        (["model-preview", "BIN", "--out", "z.png"], "not a text file"),
        (["model-preview", ".", "--out", "z.png"], "is a folder, expected a model file"),
    ],
)
def test_errors_are_one_line_without_traceback(tmp_path, capsys, monkeypatch, args, message):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "BAD").write_text("{")
    (tmp_path / "BIN").write_bytes(bytes(range(128, 256)))
    code, _, err = run(capsys, *args)
    assert code == 1 and message in err and "Traceback" not in err and err.count("\n") == 1


def test_installed_command_runs():
    done = subprocess.run([sys.executable, "-m", "facemime", "--version"], capture_output=True, text=True)
    assert done.returncode == 0 and done.stdout.startswith("facemime, version")
