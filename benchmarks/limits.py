"""The input policy's cost: for each limit, an input just above it is made and given to the
command that reads it, in a fresh process; printed are the wall time and the peak memory of that
process (Python's start and the imports included, printed first), and its one line.

    python benchmarks/limits.py

Ends with one JSON line.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from tests.cli.test_hostile import bomb_actor, huge_png  # noqa: E402


def measure(args: list[str], env: dict[str, str] | None = None) -> dict:
    """Wall seconds, peak RSS (MB, by GNU time) and the last stderr line of ``facemime ARGS``."""
    t0 = time.perf_counter()
    proc = subprocess.run(
        ["/usr/bin/time", "-f", "%M", sys.executable, "-m", "facemime", *args],
        capture_output=True,
        text=True,
        env={**os.environ, **(env or {})},
    )
    seconds = time.perf_counter() - t0
    *lines, peak_kb = [line for line in proc.stderr.strip().splitlines() if not line.startswith("Command exited")]
    return {
        "seconds": seconds,
        "peak_mb": int(peak_kb) / 1024,
        "code": proc.returncode,
        "message": lines[-1] if lines else "",
    }


def main() -> None:
    results = {}
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        huge_png(d / "huge.png", side=10001)  # 100,020,001 pixels: just over 100,000,000
        (d / "big.json").write_bytes(b" " * ((64 << 20) + 1))
        (d / "deep.json").write_text("[" * 100_000 + "]" * 100_000)
        bomb_actor(d / "bomb.actor")
        with open(d / "big.fmstream", "wb") as f:
            f.truncate((1 << 30) + 1)
        side = 448  # 200,704 vertices: just over 200,000
        lines = (
            ["# VERTEX LIST:", str(side * side)] + ["0 0 0"] * (side * side) + ["# FACE LIST:", "0", "# END OF FILE:"]
        )
        (d / "big.wfm").write_text("\n".join(lines))
        with open(d / "huge.wfm", "wb") as f:
            f.truncate((256 << 20) + 1)
        video = ROOT.parent / "shared" / "data" / "video" / "lp_d0.mp4"
        cases = {
            "image pixels (100,020,001 > 100,000,000)": ["fit", str(d / "huge.png"), "--out", str(d / "a.actor")],
            "JSON bytes (64 MiB + 1)": ["track", str(video), "--init", str(d / "big.json"), "--out", str(d / "t.json")],
            "JSON nesting (100,000 levels)": [
                "track",
                str(video),
                "--init",
                str(d / "deep.json"),
                "--out",
                str(d / "t.json"),
            ],
            "actor member that lies (256 MiB inflated)": [
                "run",
                str(video),
                "--actor",
                str(d / "bomb.actor"),
                "--out",
                str(d / "o.mp4"),
            ],
            "stream bytes (1 GiB + 1)": ["decode", str(d / "big.fmstream"), "--out", str(d / "o.mp4")],
            "model vertices (200,704 > 200,000)": ["model-preview", str(d / "big.wfm"), "--out", str(d / "m.png")],
            "model file bytes (256 MiB + 1)": ["model-preview", str(d / "huge.wfm"), "--out", str(d / "m.png")],
        }
        baseline = measure(["model-preview", "--help"])
        print(
            f"{'input':45s} {'seconds':>8s} {'peak MB':>8s}   message   (python and facemime's CLI alone: "
            f"{baseline['seconds']:.2f} s)"
        )
        for name, args in cases.items():
            r = results[name] = measure(args)
            print(f"{name:45s} {r['seconds']:8.2f} {r['peak_mb']:8.0f}   exit {r['code']}: {r['message']}", flush=True)
    print(json.dumps({"baseline": baseline, **results}))


if __name__ == "__main__":
    main()
