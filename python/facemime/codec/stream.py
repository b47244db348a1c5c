"""The bitstream's sending side: :class:`MotionEncoder` turns each analysed frame's head pose,
knot offsets and (optionally) look into packets (:mod:`facemime.codec.decoder` is the receiving
side). Packets, prediction, quantisation and entropy coding are the Rust core's
(``facemime._core.StreamEncoder`` / ``StreamDecoder``); the format is ``docs/bitstream.md``.

A sender and a receiver can run live: the encoder hands out each packet as soon as its frames
are in, and the decoder takes bytes in pieces of any size, conceals lost frames with the last
good one and resynchronises at the next intra packet.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np

from facemime import _core
from facemime.codec.params import (
    LOOK_KINDS,
    POSE_PARAMETERS,
    Basis,
    look_from_extras,
    pose_from_vector,
    pose_vector,
    samples_from_extras,
    topology_id,
)
from facemime.errors import FacemimeError, InvalidInputError
from facemime.io.actor_file import actor_bytes, actor_id
from facemime.shared_constants import SAMPLE_KINDS, SAMPLE_STEP
from facemime.types.actor import Actor
from facemime.types.contours import FEATURES
from facemime.types.look import Look
from facemime.types.pose import Pose

#: The quality a stream gets unless told otherwise (0 = coarsest ... 10 = finest).
DEFAULT_QUALITY = 5
#: Per quality: the factor on the steps below, and the basis coefficients sent. Quality 5 is the
#: finest whose motion stays under 2 kbit/s on every shared video (``benchmarks/codec.py``).
LADDER = (
    (2.83, 4),
    (2.0, 6),
    (1.68, 8),
    (1.41, 10),
    (1.19, 12),
    (1.0, 16),
    (0.71, 16),
    (0.5, 20),
    (0.35, 24),
    (0.25, 28),
    (0.18, 32),
)
#: Quantiser steps at factor 1: yaw, pitch, roll (degrees), ln scale, tx, ty (px), and the
#: basis coefficients (model units). The synthesised face's fidelity is sensitive to the pose:
#: on lp_d0, steps of 1 degree and 1 px cost 0.008 in face SSIM, 0.7 degrees 0.0055, 0.5 degrees
#: 0.001; halving the coefficients' step from 3 (2 mm changed it by less than 0.001 anywhere).
POSE_STEPS = (0.5, 0.5, 0.5, 0.004, 0.5, 0.5)
COEFFICIENT_STEP = 3.0
#: Quantiser steps at factor 1 of the look's values (``facemime.types.look``, in the order of
#: its NAMES): eye closure (share of the key frame's opening), iris u and v (eye widths).
LOOK_STEPS = (1 / 16, 1 / 16, 0.02, 0.02, 0.02, 0.02)


class StreamError(FacemimeError, ValueError):
    """A stream cannot be decoded: not a facemime stream, another model, no header, damage."""


@dataclass(frozen=True)
class Settings:
    """How a stream is coded. ``quality``: 0-10 (:data:`LADDER`); ``keyframe``: seconds between
    intra packets; ``packet``: seconds of frames per packet (at most 32 frames; shorter packets
    mean less delay and more bytes of framing); ``coefficients``: basis vectors (default: the
    quality's); ``hysteresis``: quantiser steps a value may wander before it is sent anew;
    ``texture``: WebP quality of the actor's texture in the stream."""

    quality: int = DEFAULT_QUALITY
    keyframe: float = 1.0
    packet: float = 0.5
    coefficients: int | None = None
    hysteresis: float = 0.3
    texture: int = 80

    def __post_init__(self) -> None:
        if self.quality not in range(len(LADDER)):
            raise InvalidInputError(f"quality must be an integer 0-10, got {self.quality}")
        if not (np.isfinite(self.keyframe) and 0 < self.keyframe <= 3600):
            raise InvalidInputError(f"the keyframe interval must be within (0, 3600] seconds, got {self.keyframe}")
        if not (np.isfinite(self.packet) and 0 < self.packet <= self.keyframe):
            raise InvalidInputError(f"the packet duration must be within (0, keyframe], got {self.packet}")
        if self.coefficients is not None and not 0 <= self.coefficients <= 249:
            raise InvalidInputError(f"coefficients must be within 0-249, got {self.coefficients}")
        if not 1 <= self.texture <= 100:
            raise InvalidInputError(f"texture quality must be within 1-100, got {self.texture}")

    @property
    def basis_size(self) -> int:
        """Basis coefficients per frame."""
        return LADDER[self.quality][1] if self.coefficients is None else self.coefficients

    def steps(self, coefficients: int, look: bool = False) -> list[float]:
        """Quantiser step per parameter (``docs/bitstream.md``, "Parameters").

        Parameters
        ----------
        coefficients
            Basis coefficients per frame.
        look
            Whether the look's six values follow the coefficients.

        Returns
        -------
        list of float
            6 + ``coefficients`` (+ 6 with ``look``) steps: yaw, pitch, roll (degrees), ln scale,
            tx, ty (pixels), the coefficients (model units), the look's closures (shares of the
            key frame's opening) and iris shifts (eye widths).
        """
        scale = LADDER[self.quality][0]
        return [s * scale for s in POSE_STEPS + (COEFFICIENT_STEP,) * coefficients + (LOOK_STEPS if look else ())]

    def framing(self, fps: float) -> tuple[int, int]:
        """The stream's packets at a frame rate.

        Parameters
        ----------
        fps
            The video's frame rate, frames/s.

        Returns
        -------
        frames : int
            Frames per packet (P), 1-32.
        keyframe : int
            Packets from one intra packet to the next (K), 1-65535.
        """
        frames = int(min(32, max(1, round(self.packet * fps))))
        return frames, int(min(65535, max(1, round(self.keyframe * fps / frames))))


def _fps_fraction(fps: float) -> tuple[int, int]:
    f = Fraction(float(fps)).limit_denominator(1001)
    if not 0 < f <= 1000:
        raise InvalidInputError(f"frame rate {fps} is not within (0, 1000] frames/s")
    return f.numerator, f.denominator


def _lost_bits(lost: Sequence[str]) -> int:
    return sum(1 << i for i, f in enumerate(FEATURES) if f in lost)


@dataclass
class EncodedFrame:
    """What the receiver will decode for a frame: its pose, (K, 2) offsets (model units) and
    look (neutral when the stream carries none), the samples chosen (None when the stream carries
    no choice), and the bytes this frame completed (a packet, or nothing)."""

    pose: Pose
    offsets: np.ndarray
    data: bytes
    look: Look = field(default_factory=Look)
    samples: tuple[int | None, ...] | None = None


class MotionEncoder:
    """Encodes one face's motion, frame by frame.

    Parameters
    ----------
    actor
        The actor the motion is measured on: its model's topology and content hash go in the
        header.
    fps
        The video's frame rate, frames/s (within (0, 1000]).
    size
        (width, height) of the video, pixels.
    basis
        The coefficients' basis (learned from the clip, :meth:`Basis.learn`).
    settings
        How the stream is coded.
    carry_actor
        Whether the actor itself follows the header, its texture as WebP.
    classes
        Per parameter, the spread class (0-15) of its starting table
        (``facemime._core.choose_classes``); None: a middle class (6) for all.
    reference
        The pose intra frames are coded from; None: the actor's.
    look
        Whether the stream carries each frame's :class:`~facemime.types.look.Look` (format
        version 2); without it the stream is version 1 and the receiver decodes a neutral look.
    actor_data
        The carried actor's file bytes when already made
        (:func:`~facemime.io.actor_file.actor_bytes` with a WebP texture: a live sender makes
        them before its stream starts, as they take a few hundred milliseconds); None: made here.
    samples
        Whether the stream carries each frame's choice of the actor's mouth and eye samples
        (extra kinds :data:`~facemime.shared_constants.SAMPLE_KINDS`, format version 2; an index
        is one step, so ``settings.hysteresis`` must be under 0.5).
    """

    def __init__(
        self,
        actor: Actor,
        fps: float,
        size: tuple[int, int],
        basis: Basis,
        settings: Settings = Settings(),
        carry_actor: bool = True,
        classes: Sequence[int] | None = None,
        reference: Pose | None = None,
        look: bool = False,
        actor_data: bytes | None = None,
        samples: bool = False,
    ):
        self.settings, self.basis, self.look, self.samples = settings, basis, bool(look), bool(samples)
        m = len(basis.raw)
        if self.samples and settings.hysteresis >= 0.5:
            raise InvalidInputError(
                f"sample choices are sent with a hysteresis under 0.5 steps, got {settings.hysteresis:g}"
            )
        steps = settings.steps(m, self.look) + ([SAMPLE_STEP] * len(SAMPLE_KINDS) if self.samples else [])
        extras = (list(LOOK_KINDS) if self.look else []) + (list(SAMPLE_KINDS) if self.samples else [])
        ref = pose_vector(reference or actor.pose)
        references = [int(round(v / s)) for v, s in zip(ref, steps)] + [0] * (m + len(extras))
        if classes is not None and len(classes) != len(steps):
            raise InvalidInputError(f"classes must have one entry per parameter ({len(steps)}), got {len(classes)}")
        frames, keyframes = settings.framing(fps)
        self._core = _core.StreamEncoder(
            _fps_fraction(fps),
            (int(size[0]), int(size[1])),
            topology_id(actor.model),
            frames,
            keyframes,
            steps,
            references,
            list(classes) if classes is not None else [6] * len(steps),
            basis.raw,
            actor_id(actor),
            carry_actor,
            settings.hysteresis,
            extras,
        )
        if not carry_actor:
            actor_data = b""
        elif actor_data is None:
            actor_data = actor_bytes(actor, "webp", settings.texture)
        self.actor_data = actor_data

    def start(self) -> bytes:
        """The stream's first bytes.

        Returns
        -------
        bytes
            The header chunk, followed by the actor chunk when the actor is carried.
        """
        return self.header + (_core.actor_chunk(self.actor_data) if self.actor_data else b"")

    @property
    def header(self) -> bytes:
        """The header chunk alone (what a sender repeats to a receiver that joins)."""
        return self._core.header_chunk()

    def push(
        self,
        face: bool,
        lost: Sequence[str],
        pose: Pose,
        offsets: np.ndarray,
        look: Look | None = None,
        samples: Sequence[int | None] | None = None,
    ) -> EncodedFrame:
        """Adds a frame.

        Parameters
        ----------
        face
            Whether the frame shows a face; False: the pose, offsets and look are not sent.
        lost
            The features the tracker lost, names of :data:`facemime.types.contours.FEATURES`
            (``mouth_outer``, ``mouth_inner``, ``brow_left``, ``brow_right``).
        pose
            The head pose.
        offsets
            (K, 2) float array: the knots' offsets (x to the subject's left, y up), model units.
        look
            The frame's look; None: neutral. Only an encoder made with ``look=True`` sends one
            that is not neutral.
        samples
            Per sample group (eyes, mouth), the index of the sample the receiver draws (None:
            the key frame's own); None: none. Only an encoder made with ``samples=True`` sends
            them.

        Returns
        -------
        EncodedFrame
            What the receiver will decode for the frame, and the packet it completed, if any.
        """
        look_values = (Look() if look is None else look).vector()
        if not np.all(np.isfinite(look_values)):
            raise InvalidInputError(f"the look's values must be finite, got {look_values.tolist()}")
        if not self.look and np.any(look_values != 0):
            raise InvalidInputError("this encoder's stream carries no look: make it with look=True to send one")
        m = len(self.basis.raw)
        chosen = [0.0 if k is None else float(k + 1) for k in samples or [None] * len(SAMPLE_KINDS)]
        if len(chosen) != len(SAMPLE_KINDS) or any(c < 0 for c in chosen):
            raise InvalidInputError(f"samples are {len(SAMPLE_KINDS)} indices ≥ 0 or None, got {samples}")
        if not self.samples and any(chosen):
            raise InvalidInputError("this encoder's stream carries no sample choice: make it with samples=True")
        values = np.concatenate(
            [pose_vector(pose), self.basis.coefficients(offsets)]
            + ([look_values] if self.look else [])
            + ([np.array(chosen)] if self.samples else [])
        )
        recon, packet = self._core.push(bool(face), _lost_bits(lost), values)
        coded = recon[POSE_PARAMETERS + m :]
        kinds = (LOOK_KINDS if self.look else ()) + (tuple(SAMPLE_KINDS) if self.samples else ())
        return EncodedFrame(
            pose_from_vector(recon[:POSE_PARAMETERS]),
            self.basis.offsets(recon[POSE_PARAMETERS : POSE_PARAMETERS + m]),
            packet or b"",
            look_from_extras(kinds, coded) if self.look else Look(),
            samples_from_extras(kinds, coded),
        )

    def request_intra(self) -> None:
        """Makes the next packet an intra packet, whatever its number (a live receiver that
        joined, or lost a packet, asks for one); the regular schedule goes on as before."""
        self._core.request_intra()

    def finish(self) -> bytes:
        """Ends the stream.

        Returns
        -------
        bytes
            The last packet chunk; b"" when no frame is pending.
        """
        return self._core.finish() or b""
