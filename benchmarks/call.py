"""``facemime call`` end to end: the live sender on shared videos and the receiver page in
headless Chromium (Debian's ``chromium``, software GL), on this machine.

Per video, ``facemime call VIDEO --port 0 --no-browser --record`` plays the file at its own pace;
the page (``http://127.0.0.1:PORT/``) joins during the sender's warm-up and draws every frame as
it comes. Reported:

- **rate**: the motion's kbit/s on the WebSocket after the actor (the packets), and the header
  and actor bytes once;
- **latency**: from a frame's arrival at the sender (when it was due, at the video's pace) to its
  picture drawn in the page (WebGL finished), median and 95th percentile over the clip after its
  first second; apart, the page's set-up of the actor and the worst latency in that first second;
- **speed**: the page's time to draw a frame (geometry, mouth interior, WebGL, finished), mean
  and 95th percentile, and the headroom: the frame interval over the mean draw time;
- **exactness**: the page's decoded parameters against ``MotionDecoder`` on the recording;
- **loss** (``--drop``, default 0.05): the same with the page dropping that share of the packets
  (a seeded generator): packets lost, frames concealed, intra packets asked for.

    python benchmarks/call.py [--data ../shared/data] [--videos mt_sun,lp_d3] [--drop 0.05]   # default: all ten

Prints a table and, last, one JSON line with every figure.
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from playwright.sync_api import sync_playwright

from facemime.codec.decoder import MotionDecoder

ROOT = Path(__file__).resolve().parents[1]
ARGS = [
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
]


def one_call(browser, video: Path, record: Path, drop: float) -> dict:
    proc = subprocess.Popen(
        [sys.executable, "-m", "facemime", "call", str(video), "--port", "0", "--no-browser", "--record", str(record)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        url = proc.stdout.readline().strip()
        if not url.startswith("http"):
            raise RuntimeError(f"call did not start: {proc.stderr.read()}")
        page = browser.new_page()
        page.goto(url + (f"?drop={drop}&seed=7" if drop else ""))
        _out, err = proc.communicate(timeout=600)
        page.wait_for_function("() => document.getElementById('message').textContent.includes('ended')", timeout=10_000)
        stats = page.evaluate("() => window.facemime.stats()")
        frames = page.evaluate("() => window.facemime.frames")
        page.close()
    finally:
        if proc.poll() is None:
            proc.kill()
    data = record.read_bytes()
    decoder = MotionDecoder()
    expected = decoder.push(data) + decoder.finish()
    exact = None
    if not drop:
        m = len(decoder.info.basis.raw)
        exact = len(frames) == len(expected) and all(
            g["index"] == f.index
            and g["face"] == f.face
            and np.array_equal(decoder.info.basis.offsets(np.array(g["values"])[6 : 6 + m]), f.offsets)
            for g, f in zip(frames, expected)
        )
    summary = err.strip().splitlines()[-1] if err.strip() else ""  # the sender's: rate, bytes, requests
    # the stream's first second apart: the page sets the actor up then (its irises found on the
    # texture), and the frames that came meanwhile wait for it
    fps0 = stats["header"]["fps"][0] / stats["header"]["fps"][1]
    lat = np.array([ms for index, ms in stats["latencies"] if index >= fps0])
    start = [ms for index, ms in stats["latencies"] if index < fps0]
    draw = np.array(stats["drawTimes"])
    fps = stats["header"]["fps"][0] / stats["header"]["fps"][1]
    return {
        "frames": len(frames),
        "fps": fps,
        "summary": summary,
        "exact": exact,
        "latency_median_ms": float(np.median(lat)) if len(lat) else None,
        "latency_p95_ms": float(np.percentile(lat, 95)) if len(lat) else None,
        "start_latency_max_ms": max(start) if start else None,
        "setup_ms": stats["setupMs"],
        "draw_mean_ms": float(draw.mean()),
        "draw_p95_ms": float(np.percentile(draw, 95)),
        "headroom": 1000 / fps / float(draw.mean()),
        "lost_packets": stats.get("lost_packets"),
        "concealed": stats.get("concealed"),
        "dropped": stats["dropped"],
        "intra_requests": stats["intraRequests"],
    }


def ms(v: float | None) -> str:
    return "-" if v is None else f"{v:.1f} ms"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--data", type=Path, default=ROOT.parent / "shared" / "data")
    ap.add_argument("--videos", default="lp_d0,lp_d12,lp_d3,lp_d6,mt_sun,mt_yongen,st_aoc,st_kh,vr_1,vr_2")
    ap.add_argument("--drop", type=float, default=0.05)
    args = ap.parse_args()
    figures = {}
    with sync_playwright() as p, tempfile.TemporaryDirectory() as tmp:
        browser = p.chromium.launch(executable_path=shutil.which("chromium"), args=ARGS)
        for name in args.videos.split(","):
            for drop in (0.0, args.drop):
                t0 = time.perf_counter()
                r = one_call(browser, args.data / "video" / f"{name}.mp4", Path(tmp) / f"{name}-{drop}.fmstream", drop)
                figures[f"{name}@{drop}"] = r
                print(
                    f"{name:10s} drop {drop:.2f}: {r['frames']} frames, latency median "
                    f"{ms(r['latency_median_ms'])} p95 {ms(r['latency_p95_ms'])} (first second: set-up "
                    f"{ms(r['setup_ms'])}, worst {ms(r['start_latency_max_ms'])}), draw {r['draw_mean_ms']:.2f} ms "
                    f"(p95 {r['draw_p95_ms']:.2f}; headroom {r['headroom']:.0f}x), lost {r['lost_packets']} packets, "
                    f"concealed {r['concealed']}, intra asked {r['intra_requests']}, exact {r['exact']} "
                    f"[{time.perf_counter() - t0:.0f} s]\n    sender: {r['summary']}",
                    flush=True,
                )
        browser.close()
    print(json.dumps(figures))


if __name__ == "__main__":
    main()
