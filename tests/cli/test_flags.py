"""Each global flag and exit status of the command line has its effect: ``--force`` overwrites
and its absence refuses, ``--traceback`` shows the trace that is otherwise one line, a usage
error exits 2, an interrupt 130 and a termination 128 + the signal's number."""

import re
import signal
import subprocess
import sys

import cv2
import pytest

import facemime.head
from facemime.cli import main as cli_main
from facemime.errors import FacemimeError

from .test_cli import run


def test_model_preview_refuses_to_overwrite_without_force(tmp_path, capsys):
    out = tmp_path / "head.png"
    out.write_bytes(b"earlier")
    code, stdout, err = run(capsys, "model-preview", "--out", str(out))
    assert code == 1 and stdout == "" and err.count("\n") == 1 and "already exists" in err and "--force" in err
    assert out.read_bytes() == b"earlier"
    code, stdout, err = run(capsys, "model-preview", "--out", str(out), "--force")
    assert code == 0 and stdout.strip() == str(out), err
    assert cv2.imread(str(out)).shape == (640, 1600, 3)  # the built-in head, textured and shaded


def _raise(error):
    def head(*args, **kwargs):
        raise error

    return head


def test_an_error_is_one_line_without_traceback_and_the_trace_with_it(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    args = ["model-preview", "missing.wfm", "--out", "x.png"]
    code, _, err = run(capsys, *args)
    assert code == 1 and err == "facemime: error: missing.wfm: no such model file\n"
    with pytest.raises(FacemimeError, match="no such model file"):
        cli_main.main(["--traceback", *args])


def test_a_defect_says_so_in_one_line_and_shows_its_trace_with_traceback(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(facemime.head, "generic_head", _raise(RuntimeError("broken head")))
    out = str(tmp_path / "x.png")
    code, _, err = run(capsys, "model-preview", "--out", out)
    assert code == 2 and err.count("\n") == 1
    assert err.startswith("facemime: error: unexpected RuntimeError: broken head") and "--traceback" in err
    with pytest.raises(RuntimeError, match="broken head"):
        cli_main.main(["--traceback", "model-preview", "--out", out])


def test_the_installed_command_prints_the_trace_with_traceback(tmp_path):
    command = [sys.executable, "-m", "facemime", "model-preview", "missing.wfm", "--out", "x.png"]
    plain = subprocess.run(command, capture_output=True, text=True, cwd=tmp_path)
    assert plain.returncode == 1 and plain.stderr == "facemime: error: missing.wfm: no such model file\n"
    traced = subprocess.run([*command[:3], "--traceback", *command[3:]], capture_output=True, text=True, cwd=tmp_path)
    assert traced.returncode == 1 and traced.stderr.startswith("Traceback (most recent call last):")
    assert "no such model file" in traced.stderr.splitlines()[-1]


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["no-such-command"], "No such command 'no-such-command'"),
        (["track"], "Missing argument 'VIDEO'"),
        (["model-preview"], "Missing option '--out'"),
        (["model-preview", "--out", "x.png", "--no-such-flag"], "No such option(: | ')--no-such-flag"),
        (["view", "x.json", "--port", "many"], "'many' is not a valid integer"),
    ],
)
def test_a_usage_error_exits_2_with_the_usage(tmp_path, capsys, monkeypatch, args, message):
    monkeypatch.chdir(tmp_path)
    code, stdout, err = run(capsys, *args)
    # the message in click's words (8.1 and 8.2 write "No such option: --x", later ones "No such option '--x'")
    assert code == 2 and stdout == "" and "Usage: facemime" in err and re.search(message, err), err
    assert "Traceback" not in err and not any(tmp_path.iterdir())


@pytest.mark.parametrize("error", [KeyboardInterrupt(), cli_main.Terminated(signal.SIGTERM)])
def test_an_interrupt_exits_130_and_a_termination_143_leaving_nothing(tmp_path, capsys, monkeypatch, error):
    monkeypatch.setattr(facemime.head, "generic_head", _raise(error))
    code, stdout, err = run(capsys, "model-preview", "--out", str(tmp_path / "x.png"))
    if isinstance(error, KeyboardInterrupt):
        assert code == 130 and err.splitlines()[-1] == "facemime: interrupted"
    else:
        assert code == 128 + signal.SIGTERM and err.splitlines()[-1] == "facemime: terminated"
    assert stdout == "" and "Traceback" not in err and not any(tmp_path.iterdir())
