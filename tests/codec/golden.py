"""The golden streams: small streams of made-up parameters, checked in with the values they
decode to, so that a change of the format (or of the encoder's output) is caught. ``golden`` is
a version-1 stream (no extras); ``golden_v2`` a version-2 stream whose frames carry a look
(extras of kinds 1-6, ``docs/bitstream.md``, "Look").

    python -m tests.codec.golden   # rewrites data/golden{,_v2}.fmstream and data/golden{,_v2}.json
"""

import json
from pathlib import Path

import numpy as np

from facemime import _core

DATA = Path(__file__).resolve().parent / "data"
STREAM, EXPECTED = DATA / "golden.fmstream", DATA / "golden.json"
FRAMES = 40
STEPS = [0.5, 0.5, 0.5, 0.004, 0.5, 0.5, 2.0, 2.0, 2.0, 2.0]

STREAM_V2, EXPECTED_V2 = DATA / "golden_v2.fmstream", DATA / "golden_v2.json"
FRAMES_V2 = 30
#: The look's kinds (eye closure right, left; iris right u, v; iris left u, v).
EXTRAS_V2 = list(range(1, 7))
#: Pose, two coefficients, then the look's steps of facemime.codec.stream.LOOK_STEPS.
STEPS_V2 = [0.5, 0.5, 0.5, 0.004, 0.5, 0.5, 3.0, 3.0, 1 / 16, 1 / 16, 0.02, 0.02, 0.02, 0.02]


def encoder() -> _core.StreamEncoder:
    """The golden stream's encoder: 25 fps, 320x240, 5 frames per packet, an intra packet every 4."""
    basis = (np.arange(4 * 6).reshape(4, 6) * 1111 - 12000).astype(np.int16)
    return _core.StreamEncoder(
        (25, 1),
        (320, 240),
        b"golden!!",
        5,
        4,
        STEPS,
        [0, 0, 0, 173, 320, 240, 0, 0, 0, 0],
        [5, 5, 5, 3, 7, 7, 6, 6, 6, 6],
        basis,
        bytes(range(32)),
        False,
        0.3,
    )


def frames() -> list[tuple[bool, int, np.ndarray]]:
    """(face, lost bits, values) per frame: a head turning and drifting, coefficients swinging,
    frames 17-19 without a face, a lost brow on frame 30; one value escapes its table."""
    t = np.arange(FRAMES)
    pose = [10 * np.sin(t / 6), 3 * np.cos(t / 9), t / 10, np.log(2.0) + t / 2000, 160 + 2 * t, 120 - t]
    values = np.column_stack(pose + [12 * np.sin(t / 3), 5 * np.cos(t / 4), t % 7 - 3.0, np.where(t == 25, 90.0, 0.0)])
    return [(not 17 <= i <= 19, 8 if i == 30 else 0, values[i]) for i in range(FRAMES)]


def encoder_v2() -> _core.StreamEncoder:
    """The version-2 golden stream's encoder: 30 fps, 160x120, 4 frames per packet, an intra
    packet every 3, two coefficients and the six look values."""
    basis = (np.arange(2 * 6).reshape(2, 6) * 2345 - 13000).astype(np.int16)
    references = [0, 0, 0, 173, 160, 120] + [0] * 8
    classes = [5, 5, 5, 3, 7, 7, 6, 6] + [4, 4, 3, 3, 3, 3]
    return _core.StreamEncoder(
        (30, 1),
        (160, 120),
        b"golden02",
        4,
        3,
        STEPS_V2,
        references,
        classes,
        basis,
        bytes(range(32, 64)),
        False,
        0.3,
        EXTRAS_V2,
    )


def frames_v2() -> list[tuple[bool, int, np.ndarray]]:
    """(face, lost bits, values) per frame: a nodding head, the mouth moving, the eyes looking
    left then right, a blink on frames 9-11 (both eyes shut in one frame: the closure escapes
    its table), the right eye wide open on frames 20-23; frames 14-15 without a face, the
    mouth's outer contour lost on frame 7."""
    t = np.arange(FRAMES_V2, dtype=np.float64)
    pose = [2 * np.sin(t / 5), 6 * np.sin(t / 4), np.zeros_like(t), np.log(2.0) + t / 3000, 80 + t, 60 - t / 2]
    blink = np.select([t == 9, t == 10, t == 11], [1.0, 0.9, 0.3], 0.0)
    right = blink - np.where((t >= 20) & (t <= 23), 0.35, 0.0)
    look = [right, blink, 0.15 * np.sin(t / 4), 0.04 * np.cos(t / 3), 0.14 * np.sin(t / 4) + 0.01, 0.04 * np.cos(t / 3)]
    values = np.column_stack(pose + [8 * np.sin(t / 3), 4 * np.cos(t / 5)] + look)
    return [(not 14 <= i <= 15, 2 if i == 7 else 0, values[i]) for i in range(FRAMES_V2)]


def encode(version: int = 1) -> bytes:
    enc = encoder() if version == 1 else encoder_v2()
    out = [enc.header_chunk()]
    for face, lost, v in frames() if version == 1 else frames_v2():
        out.append(enc.push(face, lost, v)[1] or b"")
    out.append(enc.finish() or b"")
    return b"".join(out)


def write(version: int) -> None:
    """Encodes the golden stream of ``version`` and writes it with the values it decodes to."""
    stream, expected = (STREAM, EXPECTED) if version == 1 else (STREAM_V2, EXPECTED_V2)
    data = encode(version)
    dec = _core.StreamDecoder(True)
    index, face, lost, values, *_ = dec.push(data)
    stream.write_bytes(data)
    rows = [
        json.dumps({"index": int(i), "face": bool(f), "lost": int(b), "values": v.tolist()})
        for i, f, b, v in zip(index, face, lost, values)
    ]
    extras = f'"extras": {json.dumps(dec.header()["extras"])},\n' if version > 1 else ""
    expected.write_text("{" + extras + '"frames": [\n' + ",\n".join(rows) + "\n]}\n")
    print(f"{stream}: {len(data)} bytes")


if __name__ == "__main__":
    write(1)
    write(2)
