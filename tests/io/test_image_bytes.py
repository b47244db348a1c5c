"""Images from bytes: a damaged one is None, and the image library says nothing on stderr."""

import struct
import zlib

import cv2
import numpy as np

from facemime.io.image_bytes import decode_rgb


def test_an_image_decodes_to_rgb():
    rgb = np.zeros((4, 6, 3), np.uint8)
    rgb[..., 0] = 200  # red
    data = cv2.imencode(".png", cv2.cvtColor(rgb, cv2.COLOR_RGB2BGR))[1].tobytes()
    assert np.array_equal(decode_rgb(data), rgb)


def _chunk(kind: bytes, body: bytes) -> bytes:
    return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))


def test_a_damaged_image_is_none_and_the_library_prints_nothing(capfd):
    # a PNG whose header says 64 x 64 RGB and whose pixel data holds one row: libpng complains
    short = (
        b"\x89PNG\r\n\x1a\n"
        + _chunk(b"IHDR", struct.pack(">IIBBBBB", 64, 64, 8, 2, 0, 0, 0))
        + _chunk(b"IDAT", zlib.compress(bytes(1 + 64 * 3)))
        + _chunk(b"IEND", b"")
    )
    for data in (b"", b"not an image", short):
        assert decode_rgb(data) is None
    assert capfd.readouterr().err == ""
