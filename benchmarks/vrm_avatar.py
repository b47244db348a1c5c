"""The VRM avatar of ``facemime export --out NAME.vrm`` driven as ``facemime live --vmc`` drives
it, rendered by three-vrm: the picture ``docs/live_vrm.png``.

For a shared video (default lp_d3): ``facemime fit`` on its first frame gives the actor and
``facemime run`` with it the track; ``facemime export`` writes the ``.vrm``. ``facemime live``
(:class:`facemime.app.live.Live`, the video unpaced) sends the video over VMC to a receiver of our
own on 127.0.0.1, which keeps every frame's bundle: the head's rotation, the root's translation and
ARKit's 52 values, as VMC software gets them. Three frames are chosen from what was received: a
neutral one (the least turn and values), the one turned most (largest ``|yaw|``) and the one
with the jaw open widest (largest ``jawOpen``); ``--extra`` adds rows at frames of one's choice
(lp_d3's 90, eyes open and looking down, and 120, shut: the blinks told apart).
three-vrm in headless Chromium (``web/test/vrm-page.mjs``, as ``tests/export/test_vrm.py`` drives
it) renders each from the front; the avatar faces the camera, so the subject's left is the picture's right, as in the
video. Each row of the sheet: the video frame, cropped to the region the avatar's picture shows
(the face's box in the first frame, grown by the same margin) | the avatar.

    python benchmarks/vrm_avatar.py [--data ../shared/data] [--video lp_d3] [--out docs/live_vrm.png]
                                    [--extra 90,120]

Needs Node with ``web/node_modules`` (``npm ci`` in web/) and Debian's chromium. Prints the
.vrm's size and the frames chosen; last, one JSON line with every figure.
"""

from __future__ import annotations

import argparse
import base64
import json
import shutil
import socket
import subprocess
import tempfile
import time
from pathlib import Path

import cv2
import numpy as np
from pythonosc.osc_bundle import OscBundle

from facemime.animate.motion_file import read_motion
from facemime.app.export import export_track
from facemime.app.fit import fit_file
from facemime.app.live import Live
from facemime.app.run import run_video
from facemime.export import load_performance
from facemime.io.actor_file import load_actor
from facemime.io.video import VideoReader
from facemime.shared_constants import BACKGROUND
from facemime.types.pose import Pose

ROOT = Path(__file__).resolve().parents[1]
WEB = ROOT / "web"
#: The margin around the face's box in both pictures, a fraction of its larger side.
MARGIN = 0.3
#: Chromium's flags for a closed network (as the browser tests').
CHROMIUM_ARGS = ["--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-background-networking"]


def received_frames(video: Path) -> list[dict]:
    """Every frame ``facemime live`` sends for ``video`` (unpaced), as a receiver on 127.0.0.1
    gets it, in the test page's form: ``head`` (x, y, z, w) and ``root`` (metres), Unity's axes,
    and ``values`` (name -> 0..1)."""
    receiver = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    receiver.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 1 << 24)
    receiver.bind(("127.0.0.1", 0))
    receiver.settimeout(1.0)
    datagrams: list[bytes] = []
    with Live(str(video), f"127.0.0.1:{receiver.getsockname()[1]}", paced=False) as live:
        live.run(lambda stats: datagrams.append(receiver.recv(65536)))  # each frame's bundle as it is sent
    receiver.close()
    frames = []
    for d in datagrams:
        messages = {m.address: m.params for m in OscBundle(d) if m.address != "/VMC/Ext/Blend/Val"}
        values = {m.params[0]: m.params[1] for m in OscBundle(d) if m.address == "/VMC/Ext/Blend/Val"}
        head, root = messages["/VMC/Ext/Bone/Pos"], messages["/VMC/Ext/Root/Pos"]
        frames.append({"head": list(head[4:8]), "root": list(root[1:4]), "values": values})
    return frames


def yaw_of(head: list[float]) -> float:
    """The turn (degrees, + to the subject's left) of a head rotation sent in Unity's axes."""
    x, y, z, w = head[0], -head[1], -head[2], head[3]  # back to the model's axes
    return float(np.degrees(np.arctan2(2 * (w * y + x * z), 1 - 2 * (x * x + y * y))))


def chosen_frames(frames: list[dict]) -> dict[str, int]:
    """The frames shown: ``neutral`` (least turn in degrees / 10 plus the largest value),
    ``turned`` (largest ``|yaw|``), ``open`` (largest ``jawOpen``)."""
    yaw = np.array([yaw_of(f["head"]) for f in frames])
    calm = np.abs(yaw) / 10 + np.array([max(f["values"].values()) for f in frames])
    return {
        "neutral": int(np.argmin(calm)),
        "turned": int(np.argmax(np.abs(yaw))),
        "open": int(np.argmax([f["values"]["jawOpen"] for f in frames])),
    }


def face_crop(picture: np.ndarray, vertices: np.ndarray, first: Pose, size: int) -> np.ndarray:
    """The square of ``picture`` the avatar's picture shows: the box of the face unturned at the
    first frame's scale and place, its larger side grown by :data:`MARGIN` on both sides;
    ``size`` pixels a side."""
    x = vertices[:, 0] * first.scale + first.tx
    y = -vertices[:, 1] * first.scale + first.ty
    cx, cy = (x.min() + x.max()) / 2, (y.min() + y.max()) / 2
    half = max(np.ptp(x), np.ptp(y)) * (1 + 2 * MARGIN) / 2
    s = size / (2 * half)  # output pixels per video pixel; pixel centres at integers on both sides
    affine = np.array([[s, 0, size / 2 - 0.5 - s * cx], [0, s, size / 2 - 0.5 - s * cy]])
    return cv2.warpAffine(picture, affine, (size, size), flags=cv2.INTER_AREA, borderValue=BACKGROUND)


def caption(width: int, text: str) -> np.ndarray:
    """A strip with ``text`` in light grey on the backdrop."""
    strip = np.full((26, width, 3), BACKGROUND, np.uint8)
    cv2.putText(strip, text, (8, 18), cv2.FONT_HERSHEY_SIMPLEX, 0.5, (225, 225, 225), 1, cv2.LINE_AA)
    return strip


def render(vrm: bytes, frames: list[dict], size: int) -> list[np.ndarray]:
    """three-vrm's pictures of the avatar posed by each VMC frame (RGB)."""
    from playwright.sync_api import sync_playwright

    subprocess.run([shutil.which("npm"), "run", "--silent", "build-vrm-page"], cwd=WEB, check=True)
    script = (WEB / ".test-build" / "vrm-page.js").read_text()
    executable = shutil.which("chromium") or shutil.which("chromium-browser")
    out, errors = [], []
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=executable, args=CHROMIUM_ARGS)
        page = browser.new_page()
        page.on("pageerror", lambda e: errors.append(str(e)))
        page.set_content("<!doctype html><html><body></body></html>")
        page.add_script_tag(content=script)
        options = {"width": size, "height": size, "margin": MARGIN, "background": list(BACKGROUND)}
        page.evaluate("([b, o]) => loadVrm(b, o)", [base64.b64encode(vrm).decode(), options])
        for f in frames:
            png = page.evaluate("(f) => applyVmc(f)", f)["png"]
            data = np.frombuffer(base64.b64decode(png.split(",", 1)[1]), np.uint8)
            out.append(cv2.cvtColor(cv2.imdecode(data, cv2.IMREAD_COLOR), cv2.COLOR_BGR2RGB))
        browser.close()
    if errors:
        raise RuntimeError(f"the test page failed: {errors}")
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    parser.add_argument("--video", default="lp_d3")
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "live_vrm.png")
    parser.add_argument("--size", type=int, default=240, help="pixels a side of each picture")
    parser.add_argument("--extra", default="", help="more frames to show, comma-separated")
    args = parser.parse_args()
    extra = [int(t) for t in args.extra.split(",") if t]
    video = args.data / "video" / f"{args.video}.mp4"
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        t0 = time.perf_counter()
        fit_file(video, work / f"{args.video}.actor")
        run_video(video, work / "run.mp4", work / f"{args.video}.actor")
        export = export_track(work / "run.json", work / f"{args.video}.vrm", work / f"{args.video}.actor")
        seconds = time.perf_counter() - t0
        vrm = export.path.read_bytes()
        perf = load_performance(work / "run.json", load_actor(work / f"{args.video}.actor"))
        _, _, records = read_motion(work / "run.json")
    poses = [Pose(**r["pose"]) for r in records]
    sent = received_frames(video)
    if len(sent) != len(records):
        raise RuntimeError(f"live sent {len(sent)} frames of the video's {len(records)}")
    if any(not 0 <= t < len(sent) for t in extra):
        raise SystemExit(f"--extra: frames are 0 to {len(sent) - 1}")
    chosen = chosen_frames(sent)
    names = ["neutral", "turned", "open"] + ["asked"] * len(extra)
    rows_at = [chosen[k] for k in ("neutral", "turned", "open")] + extra
    pictures = render(vrm, [sent[t] for t in rows_at], args.size)
    wanted = set(rows_at)
    frames: dict[int, np.ndarray] = {}
    with VideoReader(video) as reader:
        for n, picture in enumerate(reader):
            if n in wanted:
                frames[n] = picture
            if len(frames) == len(wanted):
                break
    rows = [caption(2 * args.size, f"{args.video}: video | VRM avatar in three-vrm, as live sent it")]
    figures = []
    for what, t, avatar in zip(names, rows_at, pictures):
        f = {"row": what, "frame": t, "yaw": round(yaw_of(sent[t]["head"]), 1)}
        f.update({k: round(float(sent[t]["values"][k]), 3) for k in ("jawOpen", "eyeBlinkLeft", "eyeBlinkRight")})
        figures.append(f)
        blinks = f"blink {f['eyeBlinkRight']:.2f} {f['eyeBlinkLeft']:.2f}"
        text = f"{what}: frame {t}, yaw {f['yaw']:+.0f} deg, jawOpen {f['jawOpen']:.2f}, {blinks}"
        rows.append(caption(2 * args.size, text))
        rows.append(np.hstack([face_crop(frames[t], perf.actor.model.vertices, poses[0], args.size), avatar]))
    sheet = np.vstack(rows)
    ok, png = cv2.imencode(".png", cv2.cvtColor(sheet, cv2.COLOR_RGB2BGR), [cv2.IMWRITE_PNG_COMPRESSION, 9])
    assert ok
    args.out.write_bytes(png.tobytes())
    print(f"{args.video}: fit, run and export in {seconds:.1f} s; the .vrm {len(vrm):,} bytes")
    for f in figures:
        print(
            f"  {f['row']:8s} frame {f['frame']:4d}: yaw {f['yaw']:+6.1f} deg, jawOpen {f['jawOpen']:.3f},"
            f" eyeBlink right {f['eyeBlinkRight']:.3f} left {f['eyeBlinkLeft']:.3f}"
        )
    print(f"wrote {args.out} ({len(png):,} bytes)")
    print(json.dumps({"video": args.video, "vrm_bytes": len(vrm), "png_bytes": len(png), "rows": figures}))


if __name__ == "__main__":
    main()
