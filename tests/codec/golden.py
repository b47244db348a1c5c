"""The golden stream: a small stream of made-up parameters, checked in with the values it
decodes to, so that a change of the format (or of the encoder's output) is caught.

    python -m tests.codec.golden   # rewrites data/golden.fmstream and data/golden.json
"""

import json
from pathlib import Path

import numpy as np

from facemime import _core

DATA = Path(__file__).resolve().parent / "data"
STREAM, EXPECTED = DATA / "golden.fmstream", DATA / "golden.json"
FRAMES = 40
STEPS = [0.5, 0.5, 0.5, 0.004, 0.5, 0.5, 2.0, 2.0, 2.0, 2.0]


def encoder() -> _core.StreamEncoder:
    """The golden stream's encoder: 25 fps, 320x240, 5 frames per packet, an intra packet every 4."""
    basis = (np.arange(4 * 6).reshape(4, 6) * 1111 - 12000).astype(np.int16)
    return _core.StreamEncoder((25, 1), (320, 240), b"golden!!", 5, 4, STEPS, [0, 0, 0, 173, 320, 240, 0, 0, 0, 0],
                               [5, 5, 5, 3, 7, 7, 6, 6, 6, 6], basis, bytes(range(32)), False, 0.3)


def frames() -> list[tuple[bool, int, np.ndarray]]:
    """(face, lost bits, values) per frame: a head turning and drifting, coefficients swinging,
    frames 17-19 without a face, a lost brow on frame 30; one value escapes its table."""
    t = np.arange(FRAMES)
    pose = [10 * np.sin(t / 6), 3 * np.cos(t / 9), t / 10, np.log(2.0) + t / 2000, 160 + 2 * t, 120 - t]
    values = np.column_stack(pose + [12 * np.sin(t / 3), 5 * np.cos(t / 4), t % 7 - 3.0, np.where(t == 25, 90.0, 0.0)])
    return [(not 17 <= i <= 19, 8 if i == 30 else 0, values[i]) for i in range(FRAMES)]


def encode() -> bytes:
    enc = encoder()
    out = [enc.header_chunk()]
    for face, lost, v in frames():
        out.append(enc.push(face, lost, v)[1] or b"")
    out.append(enc.finish() or b"")
    return b"".join(out)


if __name__ == "__main__":
    data = encode()
    dec = _core.StreamDecoder(True)
    index, face, lost, values, _ = dec.push(data)
    STREAM.write_bytes(data)
    rows = [json.dumps({"index": int(i), "face": bool(f), "lost": int(b), "values": v.tolist()})
            for i, f, b, v in zip(index, face, lost, values)]
    EXPECTED.write_text('{"frames": [\n' + ",\n".join(rows) + "\n]}\n")
    print(f"{STREAM}: {len(data)} bytes")
