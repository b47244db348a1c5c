"""The VMC protocol (Virtual Motion Capture, https://protocol.vmc.info): a face's motion as OSC
messages over UDP to avatar software (VSeeFace, Warudo, VNyan, EVMC4U in Unity, VMC4UE in
Unreal), one OSC bundle a frame, built with python-osc.

A frame's bundle holds, in this order:

- ``/VMC/Ext/OK`` (int 1): a model is loaded and sending;
- ``/VMC/Ext/T`` (float): seconds since the sender started;
- ``/VMC/Ext/Root/Pos`` (string ``root``, float px py pz, float qx qy qz qw): the head's
  translation from its place on the first frame, metres, the rotation none; the depth is not
  measured (pz 0);
- ``/VMC/Ext/Bone/Pos`` (string ``Head``, float px py pz, float qx qy qz qw): the head's
  rotation from frontal (the pose's, absolute: the key frame's own turn included), the position
  0 (a sender of a head's rotation does not know the avatar's neck length: a receiver applies
  rotations only, as VSeeFace's and Warudo's do for a face tracker);
- ``/VMC/Ext/Blend/Val`` (string, float) for each of ARKit's 52 names
  (:data:`facemime.animate.arkit.NAMES`), 0..1, the names VSeeFace's "perfect sync" and
  Warudo's ARKit blendshapes use;
- ``/VMC/Ext/Blend/Apply``: the values take effect together.

Axes are Unity's, as the protocol's: left-handed, x to the avatar's right, y up, z forward (the
way the face looks). facemime's model axes (x to the subject's left, y up, z towards the camera)
map to them by negating x, so a rotation's quaternion (x, y, z, w) becomes (x, -y, -z, w). The
motion is the subject's own (turning to their left turns the avatar to its left), not mirrored.
"""

from __future__ import annotations

import ipaddress
import socket

import numpy as np
from pythonosc.osc_bundle_builder import IMMEDIATELY, OscBundleBuilder
from pythonosc.osc_message import OscMessage
from pythonosc.osc_message_builder import OscMessageBuilder

from facemime.animate.arkit import NAMES
from facemime.errors import InvalidInputError
from facemime.export.animation import node_keys
from facemime.types.pose import Pose

#: Where ``facemime live`` sends by default: VSeeFace's VMC receiver's default port on this machine.
DEFAULT_ADDRESS = "127.0.0.1:39539"
#: The bone the head's rotation is sent for (Unity's ``HumanBodyBones`` name).
HEAD = "Head"


def parse_address(text: str) -> tuple[str, int]:
    """A ``HOST:PORT`` address, resolved.

    Parameters
    ----------
    text
        ``HOST:PORT``: a host name or IPv4 address, or an IPv6 one in brackets
        (``[::1]:39539``), and a port 1-65535.

    Returns
    -------
    host : str
        The host's numeric address (the first the resolver gives).
    port : int
        The port.
    """
    host, sep, port_text = text.rpartition(":")
    if host.startswith("[") and host.endswith("]"):
        host = host[1:-1]
    digits = port_text.isascii() and port_text.isdigit() and len(port_text) <= 5
    if not sep or not host or not digits or not 1 <= int(port_text) <= 65535:
        raise InvalidInputError(f"the VMC address must be HOST:PORT with a port 1-65535, got {text!r}")
    port = int(port_text)
    try:
        ipaddress.ip_address(host)
        return host, port
    except ValueError:
        pass
    try:
        found = socket.getaddrinfo(host, port, type=socket.SOCK_DGRAM)
    except (OSError, UnicodeError) as e:
        raise InvalidInputError(f"the VMC address's host {host!r} cannot be found ({e})") from None
    return str(found[0][4][0]), port


def unity_quaternion(pose: Pose) -> np.ndarray:
    """The head's rotation in Unity's axes.

    Parameters
    ----------
    pose
        The head's pose (degrees, :func:`facemime.types.pose.rotation_matrix`).

    Returns
    -------
    (4,) float64 array
        (x, y, z, w), a unit quaternion.
    """
    q = node_keys(np.array([[pose.yaw, pose.pitch, pose.roll, 1.0, 0.0, 0.0]]), 1.0)[1][0]
    return np.array([q[0], -q[1], -q[2], q[3]])


def unity_translation(pose: Pose, first: Pose, metres_per_unit: float) -> np.ndarray:
    """The head's translation from its place on the first frame, in Unity's axes.

    Parameters
    ----------
    pose
        The head's pose now.
    first
        Its pose on the first frame: its scale converts pixels to model units.
    metres_per_unit
        Metres per model unit of the head (0.001 for millimetres).

    Returns
    -------
    (3,) float64 array
        Metres: x to the avatar's right, y up, z 0 (the depth is not measured).
    """
    rows = np.array([[0.0, 0.0, 0.0, p.scale, p.tx, p.ty] for p in (first, pose)])
    t = node_keys(rows, metres_per_unit)[0][1]
    return np.array([-t[0], t[1], 0.0])


def _message(address: str, *args: str | int | float) -> OscMessage:
    m = OscMessageBuilder(address)
    for a in args:
        m.add_arg(a, "f" if isinstance(a, float) else ("i" if isinstance(a, int) else "s"))
    return m.build()


def frame_bundle(values: np.ndarray, rotation: np.ndarray, translation: np.ndarray, seconds: float) -> bytes:
    """One frame's OSC bundle (the module docstring lists its messages).

    Parameters
    ----------
    values
        (52,) float array: ARKit's values in the order of :data:`~facemime.animate.arkit.NAMES`,
        0..1.
    rotation
        (4,) float array: the head's rotation, Unity's axes (:func:`unity_quaternion`).
    translation
        (3,) float array: the head's translation, metres, Unity's axes (:func:`unity_translation`).
    seconds
        Seconds since the sender started.

    Returns
    -------
    bytes
        The bundle's datagram (time tag "immediately").
    """
    v = np.asarray(values, np.float64)
    if v.shape != (len(NAMES),) or not np.isfinite(v).all():
        raise InvalidInputError(f"a frame's ARKit values must be {len(NAMES)} finite numbers, got shape {v.shape}")
    bundle = OscBundleBuilder(IMMEDIATELY)
    p, q = [float(x) for x in translation], [float(x) for x in rotation]
    for m in (
        _message("/VMC/Ext/OK", 1),
        _message("/VMC/Ext/T", float(seconds)),
        _message("/VMC/Ext/Root/Pos", "root", *p, 0.0, 0.0, 0.0, 1.0),
        _message("/VMC/Ext/Bone/Pos", HEAD, 0.0, 0.0, 0.0, *q),
        *(_message("/VMC/Ext/Blend/Val", name, float(x)) for name, x in zip(NAMES, v)),
        _message("/VMC/Ext/Blend/Apply"),
    ):
        bundle.add_content(m)
    return bytes(bundle.build().dgram)


class VmcSender:
    """A UDP socket that sends frame bundles to one VMC receiver.

    Parameters
    ----------
    address
        ``HOST:PORT`` (:func:`parse_address`).
    """

    def __init__(self, address: str):
        self.host, self.port = parse_address(address)
        family = socket.AF_INET6 if ":" in self.host else socket.AF_INET
        self._socket = socket.socket(family, socket.SOCK_DGRAM)
        if family == socket.AF_INET:  # a broadcast address reaches every receiver of the network
            self._socket.setsockopt(socket.SOL_SOCKET, socket.SO_BROADCAST, 1)

    @property
    def address(self) -> str:
        """The receiver as ``HOST:PORT`` (an IPv6 host in brackets)."""
        return f"[{self.host}]:{self.port}" if ":" in self.host else f"{self.host}:{self.port}"

    def send(self, datagram: bytes) -> None:
        """Send one datagram (a receiver not listening loses it: UDP says nothing).

        Parameters
        ----------
        datagram
            The bytes, e.g. a :func:`frame_bundle`.
        """
        try:
            self._socket.sendto(datagram, (self.host, self.port))
        except OSError as e:  # e.g. no route to the host
            raise InvalidInputError(f"cannot send to the VMC receiver {self.address}: {e.strerror or e}") from None

    def close(self) -> None:
        self._socket.close()
