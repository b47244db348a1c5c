"""The VMC protocol's messages: their addresses, argument types and order in a frame's bundle, the
head's rotation and translation in Unity's axes, and the receiver's address."""

import numpy as np
import pytest
from pythonosc.osc_bundle import OscBundle

from facemime.animate.arkit import NAMES
from facemime.errors import InvalidInputError
from facemime.live.vmc import HEAD, frame_bundle, parse_address, unity_quaternion, unity_translation
from facemime.types.pose import Pose


def rotate(q, v):
    """v rotated by the unit quaternion q = (x, y, z, w) (the same formula in Unity's axes)."""
    x, y, z, w = q
    m = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )
    return m @ np.asarray(v, float)


def parse(datagram):
    bundle = OscBundle(datagram)
    return [(m.address, m.params, m.dgram) for m in bundle]


def osc_types(dgram):
    """The OSC type tag string of a message's datagram (after its padded address)."""
    start = dgram.index(b",", 1)
    return dgram[start + 1 : dgram.index(b"\0", start)].decode()


def test_a_frame_is_one_bundle_of_the_vmc_messages_in_order_with_their_types():
    values = np.linspace(0.0, 1.0, 52)
    q = unity_quaternion(Pose(yaw=10, pitch=-5, roll=3))
    messages = parse(frame_bundle(values, q, np.array([0.01, -0.02, 0.0]), 2.5))
    addresses = [a for a, _, _ in messages]
    assert addresses == [
        "/VMC/Ext/OK",
        "/VMC/Ext/T",
        "/VMC/Ext/Root/Pos",
        "/VMC/Ext/Bone/Pos",
        *["/VMC/Ext/Blend/Val"] * 52,
        "/VMC/Ext/Blend/Apply",
    ]
    types = [osc_types(d) for _, _, d in messages]
    assert types[:4] == ["i", "f", "sfffffff", "sfffffff"] and set(types[4:56]) == {"sf"} and types[56] == ""
    ok, t, root, head = (p for _, p, _ in messages[:4])
    assert ok == [1] and t == [pytest.approx(2.5)]
    assert root[0] == "root" and root[1:] == pytest.approx([0.01, -0.02, 0.0, 0, 0, 0, 1])
    assert head[0] == HEAD == "Head" and head[1:4] == [0.0, 0.0, 0.0] and head[4:] == pytest.approx(q.tolist())
    blends = [p for a, p, _ in messages if a == "/VMC/Ext/Blend/Val"]
    assert [b[0] for b in blends] == list(NAMES)  # all 52 ARKit names, in ARKit's order
    assert [b[1] for b in blends] == pytest.approx(values.tolist(), abs=1e-7)
    with pytest.raises(InvalidInputError):
        frame_bundle(np.full(52, np.nan), q, np.zeros(3), 0.0)


def test_the_head_turns_the_subjects_own_way_in_unitys_axes():
    """Unity: x to the avatar's right, y up, z forward (where the face looks)."""
    forward, up = (0, 0, 1), (0, 1, 0)
    # a turn to the subject's left (+yaw): the nose to the avatar's left, -x
    nose = rotate(unity_quaternion(Pose(yaw=30)), forward)
    assert nose == pytest.approx([-0.5, 0, np.sqrt(3) / 2])
    # a nod (+pitch, the nose down)
    assert rotate(unity_quaternion(Pose(pitch=20)), forward)[1] == pytest.approx(-np.sin(np.radians(20)))
    # a roll counter-clockwise in the image: the top of the head to the image's left, the
    # subject's right, the avatar's right (+x)
    assert rotate(unity_quaternion(Pose(roll=20)), up)[0] == pytest.approx(np.sin(np.radians(20)))
    q = unity_quaternion(Pose(yaw=12, pitch=-7, roll=25))
    assert np.linalg.norm(q) == pytest.approx(1.0)


def test_the_head_moves_from_its_first_place_in_metres():
    first = Pose(scale=2.0, tx=100.0, ty=80.0)  # 2 pixels a millimetre
    # 10 px to the image's right (the subject's left, the avatar's left: -x) and 4 px up
    moved = unity_translation(Pose(scale=2.2, tx=110.0, ty=76.0), first, 0.001)
    assert moved == pytest.approx([-0.005, 0.002, 0.0])


def test_addresses_are_checked_and_resolved():
    assert parse_address("127.0.0.1:39539") == ("127.0.0.1", 39539)
    assert parse_address("[::1]:9000") == ("::1", 9000)
    assert parse_address("localhost:9000")[1] == 9000
    bad_ports = ("127.0.0.1:²", "127.0.0.1:" + "9" * 5000, "127.0.0.1:" + "\u0663" * 3)  # not ASCII digits, too many
    for bad in (
        "39539",
        "127.0.0.1",
        ":39539",
        "127.0.0.1:0",
        "127.0.0.1:70000",
        "127.0.0.1:port",
        "host.invalid:9",
        *bad_ports,
    ):
        with pytest.raises(InvalidInputError) as e:
            parse_address(bad)
        assert "\n" not in str(e.value) and ("HOST:PORT" in str(e.value) or "cannot be found" in str(e.value))
