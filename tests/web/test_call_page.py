"""``facemime call`` with the receiver page in headless Chromium: two pages join a live call of a
shared video, one receiving every packet, one dropping a share of them on purpose (``?drop=``);
both decode what the Python decoder decodes from the call's recording, and the lossy one
conceals, asks for intra packets and resynchronises."""

import subprocess
import sys

import numpy as np

from facemime.codec.params import pose_from_vector
from facemime.codec.stream import MotionDecoder


def test_two_pages_receive_a_live_call_one_of_them_losing_packets(browser, shared, tmp_path):
    record = tmp_path / "call.fmstream"
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "facemime",
            "call",
            str(shared / "video" / "mt_yongen.mp4"),
            "--port",
            "0",
            "--no-browser",
            "--record",
            str(record),
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    try:
        url = proc.stdout.readline().strip()
        assert url.startswith("http://127.0.0.1:"), proc.stderr.read()
        whole, lossy = browser.new_page(), browser.new_page()
        whole.goto(url)
        lossy.goto(url + "?drop=0.1&seed=3")
        _, err = proc.communicate(timeout=120)
        assert proc.returncode == 0, err
        for page in (whole, lossy):
            page.wait_for_function("() => document.getElementById('message').textContent.includes('ended')")
        got = {
            name: (
                page.evaluate("() => window.facemime.frames"),
                page.evaluate("() => window.facemime.stats()"),
                page.inner_text("#hud"),
            )
            for name, page in (("whole", whole), ("lossy", lossy))
        }
    finally:
        if proc.poll() is None:
            proc.kill()
    decoder = MotionDecoder()
    expected = decoder.push(record.read_bytes()) + decoder.finish()
    m = len(decoder.info.basis.raw)

    def same(shown: dict, f) -> bool:
        v = np.array(shown["values"])
        return (
            (shown["index"], shown["face"]) == (f.index, f.face)
            and pose_from_vector(v[:6]) == f.pose
            and np.array_equal(decoder.info.basis.offsets(v[6 : 6 + m]), f.offsets)
        )

    frames, stats, hud = got["whole"]
    brief = {k: stats.get(k) for k in ("drawn", "dropped", "lost_packets", "concealed", "intraRequests", "setupMs")}
    assert len(frames) == len(expected) == 218, brief  # mt_yongen's 268 frames less 2 s of warm-up
    assert all(same(s, f) and not s["concealed"] for s, f in zip(frames, expected)), brief
    assert stats["drawn"] == 218 and [i for i, _ in stats["latencies"]] == list(range(218)), brief
    assert "0 frames concealed" in hud, hud

    frames, stats, hud = got["lossy"]
    brief = {k: stats.get(k) for k in ("drawn", "dropped", "lost_packets", "concealed", "intraRequests", "setupMs")}
    assert stats["dropped"] >= 2 and stats["lost_packets"] >= 1 and stats["concealed"] >= 2, brief
    assert f"{stats['concealed']} frames concealed" in hud, (hud, brief)
    # it asked for an intra packet on joining and after losses, and every frame it did not
    # conceal is the recording's frame, the last ones among them (resynchronised)
    assert stats["intraRequests"] >= 2, brief
    by_index = {f.index: f for f in expected}
    decoded = [s for s in frames if not s["concealed"]]
    assert all(same(s, by_index[s["index"]]) for s in decoded), brief
    assert len(decoded) + stats["concealed"] == len(frames) and decoded[-1]["index"] >= 200, brief
