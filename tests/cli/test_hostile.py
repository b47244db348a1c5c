"""Hostile input against every file-taking command: outputs that would replace an input, deeply
nested or huge JSON, image bombs, damaged actor archives, mutated documents (hypothesis), and
SIGTERM mid-run. Each must end in exit 1 with one ``facemime: error:`` line (or succeed), never a
traceback, and leave no file behind."""

import json
import signal
import struct
import subprocess
import sys
import time
import zipfile
import zlib

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from facemime.io.actor_file import save_actor
from facemime.io.contours_json import init_document, write_json
from facemime.io.video import VideoWriter
from facemime.track.synthetic import band_face

from .test_cli import run

DEEP = "[" * 100_000 + "]" * 100_000


@pytest.fixture(scope="module")
def files(tmp_path_factory, actor):
    """A synthetic face video, its init, a photo, an actor file: the valid inputs."""
    d = tmp_path_factory.mktemp("inputs")
    with VideoWriter(d / "face.mp4", fps=25) as w:
        for t in range(8):
            w.write(band_face(shift=(0.5 * t, 0.0), opening=0.3 * t)[0])
    write_json(d / "init.json", init_document(0, band_face()[1]))
    save_actor(d / "a.actor", actor)
    return d


def one_line_error(code, out, err, message=""):
    assert code == 1, err
    assert out == "" and err.startswith("facemime: error:") and err.count("\n") == 1, err
    assert "Traceback" not in err and message in err, err


def listing(folder):
    return sorted(p.name for p in folder.iterdir())


def test_no_output_may_replace_an_input(files, tmp_path, capsys):
    video, init, actor = files / "face.mp4", files / "init.json", files / "a.actor"
    (tmp_path / "link.mp4").symlink_to(video)
    (tmp_path / "link.json").symlink_to(init)
    (tmp_path / "p.actor").symlink_to(init)
    before = {p: p.read_bytes() for p in (video, init, actor)}
    cases = [
        (["track", str(video), "--init", str(init), "--out", str(video), "--force"], "must end in .json"),
        (
            [
                "track",
                str(video),
                "--init",
                str(init),
                "--out",
                str(tmp_path / "t.json"),
                "--overlay",
                str(video),
                "--force",
            ],
            "would replace the input",
        ),
        (
            ["track", str(video), "--init", str(init), "--out", str(tmp_path / "link.json"), "--force"],
            "would replace the input",
        ),
        (
            ["track", str(video), "--out", str(tmp_path / "t.mp4"), "--overlay", str(tmp_path / "t.mp4")],
            "must end in .json",
        ),
        (["run", str(video), "--out", str(video), "--force"], "would replace the input"),
        (["run", str(video), "--out", str(tmp_path / "link.mp4"), "--force"], "would replace the input"),
        (
            [
                "run",
                str(video),
                "--actor",
                str(actor),
                "--out",
                str(tmp_path / "o.mp4"),
                "--track",
                str(actor),
                "--force",
            ],
            "must end in .json",
        ),
        (
            [
                "run",
                str(video),
                "--actor",
                str(actor),
                "--out",
                str(tmp_path / "o.mp4"),
                "--track",
                str(tmp_path / "o.json"),
                "--force",
            ],
            "",
        ),  # allowed: distinct files (the face is synthetic: an error)
        (["encode", str(video), "--out", str(tmp_path / "link.mp4"), "--force"], "must end in .fmstream"),
        (
            ["fit", str(video), "--out", str(tmp_path / "p.actor"), "--points", str(tmp_path / "p.actor"), "--force"],
            "would replace the input",
        ),
        (["model-preview", str(init), "--out", str(tmp_path / "link.json"), "--force"], "cannot write image"),
    ]
    for args, message in cases:
        code, out, err = run(capsys, *args)
        if code == 1:
            one_line_error(code, out, err, message)
        assert {p: p.read_bytes() for p in before} == before, args
    (tmp_path / "s.fmstream").symlink_to(video)
    code, out, err = run(capsys, "encode", str(video), "--out", str(tmp_path / "s.fmstream"), "--force")
    one_line_error(code, out, err, "would replace the input")
    assert {p: p.read_bytes() for p in before} == before


def test_a_photos_preview_never_takes_its_name(tmp_path, capsys, astronaut):
    photo = tmp_path / "face.png"
    photo.write_bytes(astronaut.read_bytes())
    code, out, err = run(capsys, "fit", str(photo), "--out", str(tmp_path / "face.actor"))
    assert code == 0, err
    assert out.split() == [str(tmp_path / "face.actor"), str(tmp_path / "face.preview.png")]
    assert photo.read_bytes() == astronaut.read_bytes()


def deep_actor(src, dst):
    with zipfile.ZipFile(src) as z, zipfile.ZipFile(dst, "w") as out:
        for info in z.infolist():
            out.writestr(info.filename, DEEP if info.filename == "actor.json" else z.read(info))


def crc_broken_actor(src, dst):
    data = bytearray(src.read_bytes())
    with zipfile.ZipFile(src) as z:
        info = z.getinfo("actor.json")
    start = info.header_offset + 30 + len(info.filename) + len(info.extra)
    data[start + 10] ^= 0xFF  # inside the deflated actor.json: its CRC no longer matches
    dst.write_bytes(bytes(data))


def bomb_actor(path, inflated=256 << 20):
    """An actor whose actor.json says it holds 1000 bytes and inflates to ``inflated``."""
    deflate = zlib.compressobj(9, zlib.DEFLATED, -15)
    data = b"".join(deflate.compress(bytes(1 << 22)) for _ in range(inflated >> 22)) + deflate.flush()
    name = b"actor.json"
    local = struct.pack("<IHHHHHIIIHH", 0x04034B50, 20, 0, 8, 0, 0, 0, len(data), 1000, len(name), 0) + name
    central = (
        struct.pack(
            "<IHHHHHHIIIHHHHHII", 0x02014B50, 20, 20, 0, 8, 0, 0, 0, len(data), 1000, len(name), 0, 0, 0, 0, 0, 0
        )
        + name
    )
    end = struct.pack("<IHHHHIIH", 0x06054B50, 0, 0, 1, 1, len(central), len(local) + len(data), 0)
    path.write_bytes(local + data + central + end)


def huge_png(path, side=30000):
    ihdr = struct.pack(">IIBBBBB", side, side, 8, 2, 0, 0, 0)
    chunk = b"IHDR" + ihdr
    path.write_bytes(
        b"\x89PNG\r\n\x1a\n" + struct.pack(">I", 13) + chunk + struct.pack(">I", zlib.crc32(chunk)) + b"\x00" * 100
    )


def test_deep_huge_and_damaged_inputs_give_one_line(files, tmp_path, capsys, monkeypatch):
    (tmp_path / "deep.json").write_text(DEEP)
    deep_actor(files / "a.actor", tmp_path / "deep.actor")
    crc_broken_actor(files / "a.actor", tmp_path / "crc.actor")
    huge_png(tmp_path / "huge.png")
    bomb_actor(tmp_path / "bomb.actor")
    video, out = files / "face.mp4", tmp_path / "out"
    out.mkdir()
    cases = [
        (
            ["track", str(video), "--init", str(tmp_path / "deep.json"), "--out", str(out / "t.json")],
            "nested too deeply",
        ),
        (
            ["fit", str(files / "face.mp4"), "--points", str(tmp_path / "deep.json"), "--out", str(out / "a.actor")],
            "nested too deeply",
        ),
        (["model-preview", str(tmp_path / "deep.json"), "--out", str(out / "m.png")], ""),
        (
            ["run", str(video), "--actor", str(tmp_path / "deep.actor"), "--out", str(out / "o.mp4")],
            "nested too deeply",
        ),
        (["run", str(video), "--actor", str(tmp_path / "crc.actor"), "--out", str(out / "o.mp4")], "crc.actor"),
        (["run", str(video), "--actor", str(tmp_path / "bomb.actor"), "--out", str(out / "o.mp4")], "Bad CRC"),
        (["fit", str(tmp_path / "huge.png"), "--out", str(out / "h.actor")], "30000x30000 pixels, more than"),
    ]
    for args, message in cases:
        t0 = time.perf_counter()
        one_line_error(*run(capsys, *args), message)
        assert time.perf_counter() - t0 < 30, args  # refused, not worked through
        assert listing(out) == [], args
    monkeypatch.setenv("FACEMIME_MAX_JSON_BYTES", "100")
    one_line_error(
        *run(capsys, "track", str(video), "--init", str(files / "init.json"), "--out", str(out / "t.json")),
        "more than the 100 allowed (set FACEMIME_MAX_JSON_BYTES",
    )
    assert listing(out) == []


@settings(max_examples=40, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.data())
def test_mutated_init_files_never_escape_as_a_traceback(files, tmp_path, capsys, data):
    doc = json.loads((files / "init.json").read_text())
    path = data.draw(
        st.sampled_from(
            [
                ["frame"],
                ["contours"],
                ["contours", "mouth_outer_upper"],
                ["contours", "mouth_outer_upper", 0],
                ["format"],
                [],
            ]
        )
    )
    value = data.draw(
        st.one_of(
            st.none(),
            st.booleans(),
            st.integers(-(10**12), 10**12),
            st.floats(allow_nan=True),
            st.text(max_size=5),
            st.lists(st.floats(), max_size=3),
            st.just({}),
        )
    )
    target = doc
    for key in path[:-1]:
        target = target[key]
    if path:
        target[path[-1]] = value
    else:
        doc = value
    init = tmp_path / "m.json"
    init.write_text(json.dumps(doc))
    out = tmp_path / "t.json"
    out.unlink(missing_ok=True)
    code, stdout, err = run(capsys, "track", str(files / "face.mp4"), "--init", str(init), "--out", str(out))
    assert code in (0, 1) and "Traceback" not in err and "unexpected" not in err, err
    if code == 1:
        one_line_error(code, stdout, err) and not out.exists()


@settings(max_examples=60, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.lists(st.tuples(st.integers(0, 10**7), st.integers(1, 255)), min_size=1, max_size=6))
def test_mutated_actor_files_never_escape_as_a_traceback(files, tmp_path, capsys, edits):
    data = bytearray((files / "a.actor").read_bytes())
    for at, value in edits:
        data[at % len(data)] ^= value
    bad = tmp_path / "bad.actor"
    bad.write_bytes(bytes(data))
    out = tmp_path / "o.mp4"
    code, _stdout, err = run(capsys, "run", str(files / "face.mp4"), "--actor", str(bad), "--out", str(out))
    assert code == 1 and "Traceback" not in err and "unexpected" not in err and not out.exists(), err


@pytest.mark.parametrize("command", ["run", "track"])
def test_sigterm_stops_a_run_and_leaves_nothing(shared, tmp_path, command):
    video = shared / "video" / "lp_d6.mp4"
    out = tmp_path / ("o.mp4" if command == "run" else "t.json")
    args = [sys.executable, "-m", "facemime", command, str(video), "--out", str(out)]
    if command == "track":
        args += ["--overlay", str(tmp_path / "o.mp4")]
    proc = subprocess.Popen(args, stderr=subprocess.PIPE, text=True)
    deadline = time.time() + 60
    while not any(p.name.startswith(".") for p in tmp_path.iterdir()) and time.time() < deadline:
        time.sleep(0.05)
    time.sleep(0.5)
    proc.send_signal(signal.SIGTERM)
    _, err = proc.communicate(timeout=60)
    assert proc.returncode == 128 + signal.SIGTERM, err
    assert err.strip().endswith("facemime: terminated") and "Traceback" not in err
    assert listing(tmp_path) == []


def test_a_failed_demo_leaves_no_folder_it_made(tmp_path, capsys, monkeypatch):
    import facemime.app.demo
    from facemime.errors import InvalidInputError

    def fail(*args, **kwargs):
        raise InvalidInputError("stopped on purpose")

    monkeypatch.setattr(facemime.app.demo, "analysed", fail)
    one_line_error(*run(capsys, "demo", "--out", str(tmp_path / "d")), "stopped on purpose")
    assert listing(tmp_path) == []
    (tmp_path / "kept").mkdir()
    (tmp_path / "kept" / "mine.txt").write_text("mine")
    one_line_error(*run(capsys, "demo", "--out", str(tmp_path / "kept")), "stopped on purpose")
    assert listing(tmp_path / "kept") == ["mine.txt"]
    one_line_error(*run(capsys, "demo", "--out", "/proc/facemime-demo"), "cannot write /proc/facemime-demo")


def mutate(doc, data):
    """``doc`` with one value somewhere in it replaced by an odd one (hypothesis draws both)."""
    paths, stack = [[]], [([], doc)]
    while stack:
        path, node = stack.pop()
        items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else []
        for key, child in list(items)[:6]:
            paths.append(path + [key])
            stack.append((path + [key], child))
    path = data.draw(st.sampled_from(paths))
    value = data.draw(
        st.one_of(
            st.none(),
            st.booleans(),
            st.integers(-(10**12), 10**12),
            st.floats(allow_nan=True),
            st.text(max_size=5),
            st.lists(st.floats(), max_size=3),
            st.just({}),
            st.just([[]]),
        )
    )
    if not path:
        return value
    target = doc
    for key in path[:-1]:
        target = target[key]
    target[path[-1]] = value
    return doc


@settings(max_examples=40, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.data())
def test_mutated_points_and_head_models_never_escape_as_a_traceback(tmp_path, capsys, astronaut, data):
    from facemime.head import generic_head
    from facemime.io.head_file import head_document

    head = tmp_path / "head.json"
    head.write_text(json.dumps(mutate(head_document(generic_head()), data)))
    out = tmp_path / "h.png"
    out.unlink(missing_ok=True)
    code, _stdout, err = run(capsys, "model-preview", str(head), "--out", str(out))
    assert code in (0, 1) and "Traceback" not in err and "unexpected" not in err, err
    assert code == 0 or not out.exists()


@pytest.fixture(scope="module")
def bad_videos(tmp_path_factory, files):
    """Videos that cannot be tracked: missing, empty, random bytes, a text file, a zero-frame
    MP4 (its header only), a blank picture (no face)."""
    d = tmp_path_factory.mktemp("bad")
    (d / "empty.mp4").write_bytes(b"")
    (d / "random.mp4").write_bytes(np.random.default_rng(0).integers(0, 256, 50_000, dtype=np.uint8).tobytes())
    (d / "text.mp4").write_text("not a video\n" * 100)
    (d / "header.mp4").write_bytes((files / "face.mp4").read_bytes()[:48])
    with VideoWriter(d / "blank.mp4", fps=25) as w:
        for _ in range(5):
            w.write(np.full((128, 128, 3), 90, np.uint8))
    return d


@pytest.mark.parametrize("name", ["missing.mp4", "empty.mp4", "random.mp4", "text.mp4", "header.mp4", "blank.mp4"])
def test_bad_videos_give_one_line_to_every_command(bad_videos, tmp_path, capsys, name):
    video = str(bad_videos / name)
    for args in (
        ["track", video, "--out", str(tmp_path / "t.json"), "--overlay", str(tmp_path / "o.mp4")],
        ["run", video, "--out", str(tmp_path / "o.mp4")],
        ["encode", video, "--out", str(tmp_path / "s.fmstream")],
        ["fit", video, "--out", str(tmp_path / "a.actor")],
    ):
        one_line_error(*run(capsys, *args))
        assert listing(tmp_path) == [], args


@pytest.mark.parametrize("command", ["run", "track"])
def test_a_full_disk_gives_one_line_and_leaves_nothing(shared, tmp_path, command):
    import resource

    def small_files():  # writes beyond 150 kB fail as on a full disk
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (150_000, 150_000))

    args = [sys.executable, "-m", "facemime", command, str(shared / "video" / "lp_d3.mp4")]
    args += (
        ["--out", str(tmp_path / "o.mp4")]
        if command == "run"
        else ["--out", str(tmp_path / "t.json"), "--overlay", str(tmp_path / "o.mp4")]
    )
    proc = subprocess.run(args, preexec_fn=small_files, capture_output=True, text=True, timeout=300)
    one_line_error(proc.returncode, proc.stdout, proc.stderr, "cannot write")
    outputs = ("o.mp4", "o.json") if command == "run" else ("t.json", "o.mp4")
    assert ".part" not in proc.stderr and any(f"{tmp_path / name}:" in proc.stderr for name in outputs), proc.stderr
    assert listing(tmp_path) == []


def test_numbers_too_large_for_a_float_give_one_line(files, tmp_path, capsys):
    huge = "1" + "0" * 400  # valid JSON, but no float holds it
    doc = json.loads((files / "init.json").read_text())
    text = json.dumps(doc).replace(str(doc["contours"]["mouth_outer_upper"][0][0]), huge, 1)
    (tmp_path / "init.json").write_text(text)
    one_line_error(
        *run(
            capsys,
            "track",
            str(files / "face.mp4"),
            "--init",
            str(tmp_path / "init.json"),
            "--out",
            str(tmp_path / "t.json"),
        ),
        "mouth_outer_upper",
    )
    assert listing(tmp_path) == ["init.json"]


# Found by a hostile-input sweep of every command (each case used to end as "a bug", exit 2, or hang).
def edited_actor(src, dst, edit):
    """``src`` with its actor.json changed by ``edit`` (a function of the parsed document)."""
    with zipfile.ZipFile(src) as z, zipfile.ZipFile(dst, "w") as out:
        for info in z.infolist():
            data = z.read(info)
            if info.filename == "actor.json":
                doc = json.loads(data)
                edit(doc)
                data = json.dumps(doc).encode()
            out.writestr(info.filename, data)


def encrypted_actor(src, dst):
    """``src`` with every member marked encrypted (bit 0 of the flags of its local and central
    headers), as zipfile reads an archive it needs a password for."""
    data = bytearray(src.read_bytes())
    for signature, flags in ((b"PK\x03\x04", 6), (b"PK\x01\x02", 8)):
        at = data.find(signature)
        while at >= 0:
            data[at + flags] |= 1
            at = data.find(signature, at + 4)
    dst.write_bytes(bytes(data))


def short_eyes(doc):
    doc["model"]["groups"]["eye_left"] = doc["model"]["groups"]["eye_left"][:4]


def eyes_off_the_texture(doc):
    for v in doc["model"]["groups"]["eye_left"]:
        doc["model"]["uv"][v][0] = 1.3


def huge_scale(doc):
    doc["pose"]["scale"] = 1e300


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (encrypted_actor, "an encrypted archive"),
        (lambda src, dst: edited_actor(src, dst, short_eyes), "eye_left has 4 (needs 8)"),
        (lambda src, dst: edited_actor(src, dst, eyes_off_the_texture), "eyes' texture coordinates"),
        (lambda src, dst: edited_actor(src, dst, huge_scale), "pose out of range"),
    ],
)
def test_actor_files_that_passed_validation_and_then_broke_give_one_line(files, tmp_path, capsys, make, message):
    make(files / "a.actor", tmp_path / "bad.actor")
    track = tmp_path / "t.json"
    one_line_error(
        *run(capsys, "encode", str(files / "face.mp4"), "--actor", str(tmp_path / "bad.actor"), "--out", "x.fmstream"),
        message,
    )
    assert not track.exists()


def test_a_stream_whose_starting_pose_is_out_of_range_gives_one_line(actor, tmp_path, capsys):
    from facemime.codec.params import Basis
    from facemime.codec.stream import MotionEncoder, Settings
    from facemime.types.pose import Pose

    basis = Basis.learn(np.zeros((4, 60, 2)), 2)
    encoder = MotionEncoder(actor, 25.0, (640, 480), basis, Settings(), True, reference=Pose(scale=1e-30))
    frames = [encoder.push(True, [], Pose(scale=1.0, tx=320, ty=240), np.zeros((60, 2))).data for _ in range(4)]
    (tmp_path / "s.fmstream").write_bytes(encoder.start() + b"".join(frames) + encoder.finish())
    code, out, err = run(capsys, "decode", str(tmp_path / "s.fmstream"), "--out", str(tmp_path / "d.mp4"))
    one_line_error(code, out, err, "starting pose is out of range")
    assert listing(tmp_path) == ["s.fmstream"]


def test_a_head_model_index_beyond_any_integer_gives_one_line(tmp_path, capsys):
    (tmp_path / "big.wfm").write_text(
        "# VERTEX LIST:\n3\n0 0 0\n1 0 0\n0 1 0\n# FACE LIST:\n1\n0 1 99999999999999999999999\n"
    )
    code, out, err = run(capsys, "model-preview", str(tmp_path / "big.wfm"), "--out", str(tmp_path / "p.png"))
    one_line_error(code, out, err, "FACE LIST")


def test_a_track_whose_pose_is_out_of_range_gives_one_line(shared, tmp_path, capsys):
    track = tmp_path / "t.json"
    assert run(capsys, "run", str(shared / "video" / "lp_d0.mp4"), "--out", str(tmp_path / "r.mp4"))[0] == 0
    doc = json.loads((tmp_path / "r.json").read_text())
    doc["frames"][5]["pose"]["tx"] = 1e300
    track.write_text(json.dumps(doc))
    for command, out in (("export", "p.glb"), ("encode", "s.fmstream")):
        code, stdout, err = run(capsys, command, str(track), "--out", str(tmp_path / out))
        one_line_error(code, stdout, err, "frame entry 5 has a pose out of range")
        assert not (tmp_path / out).exists()


def test_fit_refuses_points_whose_eyes_coincide(tmp_path, capsys, astronaut):
    points = {
        "format": "facemime.points/1",
        "points": {
            "eye_right_outer": [100, 100], "eye_right_inner": [100, 100], "eye_left_inner": [100, 100],
            "eye_left_outer": [100, 100], "mouth_outer_upper": [[90, 200], [110, 195], [130, 200]],
            "mouth_outer_lower": [[90, 200], [110, 210], [130, 200]],
        },
    }  # fmt: skip
    (tmp_path / "p.json").write_text(json.dumps(points))
    code, out, err = run(capsys, "fit", str(astronaut), "--points", str(tmp_path / "p.json"), "--out", "x.actor")
    one_line_error(code, out, err, "the outer eye corners are 0.0 px apart")


def test_a_call_that_cannot_write_its_recording_stops_at_once(shared, tmp_path):
    (tmp_path / "file").write_text("a file, not a folder")
    done = subprocess.run(
        [sys.executable, "-m", "facemime", "call", str(shared / "video" / "lp_d0.mp4"), "--no-browser", "--port", "0",
         "--record", str(tmp_path / "file" / "c.fmstream")],
        capture_output=True, text=True, timeout=60, input="",
    )  # fmt: skip
    assert done.returncode == 1 and done.stderr.strip().splitlines()[-1].startswith("facemime: error: cannot write")


def test_a_call_of_a_video_shorter_than_its_warm_up_fails_and_records_nothing(shared, tmp_path):
    from facemime.io.video import VideoReader

    with VideoReader(shared / "video" / "lp_d0.mp4") as reader, VideoWriter(tmp_path / "two.mp4", fps=25) as w:
        for _, frame in zip(range(2), reader):
            w.write(frame)
    record = tmp_path / "c.fmstream"
    done = subprocess.run(
        [sys.executable, "-m", "facemime", "call", str(tmp_path / "two.mp4"), "--no-browser", "--port", "0",
         "--record", str(record)],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert done.returncode == 1, done.stderr
    assert done.stderr.strip().splitlines()[-1] == (
        "facemime: error: two.mp4 has 2 frames, fewer than the 50 of warm-up the call analyses before it streams"
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == ["two.mp4"]


def test_a_head_model_with_a_short_nose_is_previewed(tmp_path, capsys):
    """A head of one's own may have as few nose vertices as the checks allow (7): its preview is
    drawn, without the painted nostrils a facemime head's ten-vertex nose has."""
    from facemime.head import generic_head
    from facemime.io.head_file import head_document
    from facemime.types.head import MIN_GROUP_SIZES

    doc = head_document(generic_head())
    doc["groups"]["nose"] = doc["groups"]["nose"][: MIN_GROUP_SIZES["nose"]]
    (tmp_path / "h.json").write_text(json.dumps(doc))
    code, _out, err = run(capsys, "model-preview", str(tmp_path / "h.json"), "--out", str(tmp_path / "p.png"))
    assert code == 0, err
    assert (tmp_path / "p.png").stat().st_size > 0
