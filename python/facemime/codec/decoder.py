"""The bitstream's receiving side: :class:`MotionDecoder` turns the bytes of a stream (``docs/bitstream.md``)
back into poses, offsets and looks, in pieces of any size; it conceals lost frames with the last
good one and resynchronises at the next intra packet. Decoding is the Rust core's
(``facemime._core.StreamDecoder``); :mod:`facemime.codec.stream` is the sending side.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from facemime import _core
from facemime.animate.deform import Deformer
from facemime.codec.params import (
    LOOK_KINDS,
    POSE_PARAMETERS,
    Basis,
    look_from_extras,
    pose_from_vector,
    samples_from_extras,
    topology_id,
)
from facemime.codec.stream import StreamError
from facemime.io.actor_file import ActorFileError, actor_from_bytes, actor_id
from facemime.limits import pose_in_range
from facemime.types.actor import Actor
from facemime.types.contours import FEATURES
from facemime.types.look import Look
from facemime.types.pose import Pose


@dataclass
class DecodedFrame:
    """One frame out of the decoder: its ``index`` from the stream's start, ``face`` (False: show
    the last face, dimmed), the features ``lost``, ``pose``, (K, 2) ``offsets`` (model units),
    ``concealed``: it was lost or damaged and repeats the last good frame, its ``look``
    (neutral for a version-1 stream, which carries none, and before the first decoded frame), and
    ``samples``: per sample group (eyes, mouth) the index of the actor's sample the stream chose,
    None for the key frame's own (None whole when the stream carries no choice)."""

    index: int
    face: bool
    lost: list[str]
    pose: Pose
    offsets: np.ndarray
    concealed: bool = False
    look: Look = field(default_factory=Look)
    samples: tuple[int | None, ...] | None = None


@dataclass
class StreamInfo:
    """The header's facts: ``fps`` (frames/s), ``size`` (width, height px), frames per packet,
    packets per intra packet, the basis, whether the actor is in the stream, its content hash, the
    model's topology, and ``extras``: the kinds of the extra parameters (``docs/bitstream.md``,
    "Look (version 2)"; kinds 1-6 are the look's values, :data:`~facemime.codec.params.LOOK_KINDS`;
    empty for version 1)."""

    fps: float
    size: tuple[int, int]
    packet_frames: int
    keyframe_packets: int
    basis: Basis
    actor_in_stream: bool
    actor_id: bytes
    topology: bytes = field(repr=False, default=b"")
    extras: tuple[int, ...] = ()

    @property
    def has_look(self) -> bool:
        """Whether the stream carries any of the look's values."""
        return any(k in LOOK_KINDS for k in self.extras)


class MotionDecoder:
    """Decodes a stream fed in pieces.

    ``appearance`` collects the payloads of the stream's appearance chunks (updates of the
    actor's texture, ``docs/bitstream.md``, "Appearance"), unparsed, in stream order as they are
    read; ``appearance_after[k]`` is the number of frames the decoder had output (decoded and
    concealed, over all calls of :meth:`push` and :meth:`finish`) before ``appearance[k]`` was
    read, so it falls between those frames and the next.

    Parameters
    ----------
    actor
        The receiver's own copy of the stream's actor: needed when the stream does not carry
        it; refused if it is another actor. None: the stream's.
    from_start
        Whether the bytes start at the stream's start (a file); False for a receiver joining a
        live stream.
    name
        What the stream is called in error messages.
    max_concealed
        For a file: refuse a stream that conceals more than this many frames per frame decoded,
        and a minute besides (a stream whose sequence numbers jump far ahead); None: no limit.
    """

    def __init__(
        self,
        actor: Actor | None = None,
        from_start: bool = True,
        name: str = "the stream",
        max_concealed: float | None = None,
    ):
        self._core = _core.StreamDecoder(from_start)
        self._max_concealed = max_concealed
        self._given, self.name = actor, name
        self.info: StreamInfo | None = None
        self.actor: Actor | None = None
        self._last: DecodedFrame | None = None
        self._magic_seen = False
        self.appearance: list[bytes] = []
        self.appearance_after: list[int] = []
        self._output = 0  # frames output so far, decoded and concealed

    def _read_header(self) -> None:
        h = self._core.header()
        if h is None or (
            self.info is not None
            and h["basis"].tobytes() == self.info.basis.raw.tobytes()
            and h["actor_id"] == self.info.actor_id
            and tuple(h["extras"]) == self.info.extras
        ):
            return
        self.actor = None  # a first header, or a new one: its actor is looked up again
        self.info = StreamInfo(
            h["fps"][0] / h["fps"][1],
            tuple(h["size"]),
            h["packet_frames"],
            h["keyframe_packets"],
            Basis(h["basis"]),
            h["actor_in_stream"],
            h["actor_id"],
            h["topology"],
            tuple(int(k) for k in h["extras"]),
        )

    def _resolve_actor(self) -> None:
        if self.actor is not None or self.info is None:
            return
        data = self._core.actor()
        if self._given is not None:
            if actor_id(self._given) != self.info.actor_id:
                raise StreamError(f"{self.name} was made for another actor than the one given")
            actor = self._given
        elif data is not None:
            try:
                actor = actor_from_bytes(data, f"the actor in {self.name}")
            except ActorFileError as e:
                raise StreamError(str(e)) from None
            if actor_id(actor) != self.info.actor_id:
                raise StreamError(f"the actor in {self.name} does not match its header")
        elif self.info.actor_in_stream:
            return  # the actor chunk has not come yet (or was lost)
        else:
            raise StreamError(f"{self.name} does not carry its actor: give the actor file (--actor)")
        if topology_id(actor.model) != self.info.topology:
            raise StreamError(f"{self.name} was made for another head model than this actor's")
        knots = len(Deformer(actor.model).knots)
        if self.info.basis.raw.shape[1] != 2 * knots:
            raise StreamError(f"{self.name}'s basis does not fit the {knots} knots of its actor")
        self.actor = actor

    def _collect(self, decoded: _core.Decoded) -> _core.Decoded:
        """Takes the appearance payloads out of what the core decoded, noting where they fall."""
        index, concealed, updates = decoded[0], decoded[4], decoded[5]
        for before, payload in updates:
            self.appearance.append(bytes(payload))
            self.appearance_after.append(self._output + int(before))
        self._output += len(index) + int(concealed[:, 1].sum())
        return decoded

    def _frames(self, decoded: _core.Decoded) -> list[DecodedFrame]:
        index, face, lost, values, concealed, _ = decoded
        stats = self._core.stats()
        if (
            self._max_concealed is not None
            and self.info is not None
            and stats["concealed"] > self._max_concealed * stats["frames"] + 60 * self.info.fps
        ):
            raise StreamError(
                f"{self.name} is too damaged to play: {stats['concealed']} frames lost against "
                f"{stats['frames']} decoded"
            )
        out: list[tuple[int, DecodedFrame | None, int]] = []
        info = self.info
        m = len(info.basis.raw) if info is not None else 0
        for i, f, lost_bits, v in zip(index, face, lost, values):
            assert info is not None  # frames come after a header
            look = look_from_extras(info.extras, v[POSE_PARAMETERS + m :]) if info.extras else Look()
            chosen = samples_from_extras(info.extras, v[POSE_PARAMETERS + m :])
            out.append(
                (
                    int(i),
                    DecodedFrame(
                        int(i),
                        bool(f),
                        [n for b, n in enumerate(FEATURES) if lost_bits >> b & 1],
                        pose_from_vector(v[:POSE_PARAMETERS]),
                        info.basis.offsets(v[POSE_PARAMETERS : POSE_PARAMETERS + m]),
                        look=look,
                        samples=chosen,
                    ),
                    0,
                )
            )
        for first, count in concealed:
            out.append((int(first), None, int(count)))
        frames = []
        for first, frame, count in sorted(out, key=lambda t: t[0]):
            if frame is not None:
                frames.append(frame)
                self._last = frame
                continue
            for k in range(count):
                last = self._last
                if last is None:
                    frames.append(DecodedFrame(first + k, False, list(FEATURES), self.reference(), self._rest(), True))
                else:
                    frames.append(
                        DecodedFrame(
                            first + k, last.face, last.lost, last.pose, last.offsets, True, last.look, last.samples
                        )
                    )
        return frames

    def reference(self) -> Pose:
        """The pose the stream's motion starts from.

        Returns
        -------
        Pose
            The header's reference pose (quantised): the source face's pose on its key frame.
        """
        h = self._core.header()
        if h is None:
            raise StreamError(f"{self.name} has no header")
        values = np.array(h["references"][:POSE_PARAMETERS]) * np.array(h["steps"][:POSE_PARAMETERS])
        with np.errstate(over="ignore", under="ignore"):  # judged below
            pose = pose_from_vector(values)
        if not pose_in_range(pose.yaw, pose.pitch, pose.roll, pose.scale, pose.tx, pose.ty):
            raise StreamError(f"{self.name}: the header's starting pose is out of range ({pose})")
        return pose

    def _rest(self) -> np.ndarray:
        assert self.info is not None  # read with the header
        return np.zeros((self.info.basis.raw.shape[1] // 2, 2))

    def _segments(self, decoded: _core.Decoded, again: Callable[[], _core.Decoded]) -> list[DecodedFrame]:
        """The frames of what the core decoded, and of what it has left after a new header (each
        part read with its own header)."""
        frames = []
        while True:
            decoded = self._collect(decoded)
            self._read_header()
            self._resolve_actor()
            frames += self._frames(decoded)
            if not self._core.pending():
                return frames
            decoded = again()

    def push(self, data: bytes) -> list[DecodedFrame]:
        """Reads more of the stream.

        Parameters
        ----------
        data
            The stream's next bytes, a piece of any size.

        Returns
        -------
        list of DecodedFrame
            The frames it completed, in order (concealed ones included).
        """
        self._magic_seen = self._magic_seen or b"FMST" in data
        return self._segments(self._core.push(bytes(data)), lambda: self._core.push(b""))

    def finish(self) -> list[DecodedFrame]:
        """Reads the end of the stream; raises :class:`StreamError` when nothing was decodable.

        Returns
        -------
        list of DecodedFrame
            The frames still pending, in order (concealed ones included).
        """
        frames = self._segments(self._core.finish(), self._core.finish)
        if self.info is None:
            reason = self._core.header_error()
            if reason:
                raise StreamError(f"{self.name}: {reason}")
            if self._magic_seen:
                raise StreamError(f"{self.name}: its header is damaged or cut short; nothing can be decoded")
            raise StreamError(f"{self.name} is not a facemime stream (no header found)")
        if self.actor is None:
            raise StreamError(f"{self.name}'s actor is missing or damaged: give the actor file (--actor)")
        return frames

    @property
    def stats(self) -> dict[str, int]:
        """What the decoder met: packets, lost_packets, late_packets, undecodable, appearance
        (appearance updates collected), damaged_runs, damaged_bytes, frames, concealed."""
        return self._core.stats()
