"""``facemime encode`` and ``facemime decode``: a face video to an ``.fmstream`` file, and an
``.fmstream`` file (with the actor it carries or names) to a video of the synthesised face.

Encoding analyses the whole video first (fit, track, head pose, knot offsets), learns the basis
of the knots' motion from this clip (its principal directions; sent once, in the header), picks
each parameter's starting table from the clip, then codes the frames. With a target rate, it
takes the finest quality whose motion fits. With an appearance budget, it reads the video again
and puts appearance updates (:mod:`facemime.codec.appearance`) between the packets. A track
file (``.json``: from ``facemime run``, or expression weights written by hand) is coded from its
recorded motion instead of analysing a video (:func:`track_clip`). Decoding needs only the
stream and, when the stream does not carry it, the actor.
"""

from __future__ import annotations

import io
import time
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from facemime import _core
from facemime.animate.analysis import FrameMotion, analysed
from facemime.animate.deform import Deformer
from facemime.animate.synth import Puppet
from facemime.codec.appearance import AppearanceSender
from facemime.codec.decoder import MotionDecoder
from facemime.codec.params import Basis, pose_vector
from facemime.codec.stream import LADDER, MotionEncoder, Settings
from facemime.errors import InputFileError
from facemime.io.video import VideoReader
from facemime.progress import track as progress
from facemime.shared_constants import SAMPLE_KINDS, SAMPLE_STEP
from facemime.types.actor import Actor
from facemime.types.head import model_iod
from facemime.types.look import Look

SUFFIX = ".fmstream"
#: Largest stream file read, bytes.
MAX_STREAM_BYTES = 1 << 30
#: A stream file is refused when it conceals more than this many frames per frame decoded (and a
#: minute besides): sequence numbers that jump far ahead would otherwise make hours of video.
MAX_CONCEALED_RATIO = 10
#: The largest appearance budget, kbit/s (more is a video codec's business).
MAX_APPEARANCE = 1000.0
#: The most basis vectors any quality uses (the clip's basis is learned once at this size).
MAX_COEFFICIENTS = max(m for _, m in LADDER)


@dataclass
class Clip:
    """A video's analysis: its actor, frame rate (frames/s), size (width, height, pixels),
    per-frame motion, warnings, and the seconds the analysis took."""

    actor: Actor
    fps: float
    size: tuple[int, int]
    motion: list[FrameMotion]
    warnings: list[str]
    seconds: float


def analyse(video: str | Path, actor: Actor | None = None) -> Clip:
    """Fit (or place an actor), track and measure every frame of a video.

    Parameters
    ----------
    video
        Path of the video file (any FFmpeg-readable one).
    actor
        The actor to place on the face; None: one is fitted on the video.

    Returns
    -------
    Clip
        The video's analysis, with the time it took (seconds).
    """
    t0 = time.perf_counter()
    with VideoReader(video) as reader:
        analysis, motion = None, []
        frames = progress(reader, reader.frames or None, "analysing")
        for _, current, m in analysed(frames, str(video), actor=actor, fps=reader.fps):
            analysis = current
            motion.append(m)
        if analysis is None:
            raise InputFileError(f"video {video} has no frames")
        return Clip(
            actor or analysis.actor,
            reader.fps,
            (reader.width, reader.height),
            motion,
            list(analysis.warnings) + list(reader.warnings),
            time.perf_counter() - t0,
        )


def track_clip(track: str | Path, actor: Actor | None = None) -> Clip:
    """The motion of a track file as a clip, on an actor as ``view`` plays it
    (:mod:`facemime.animate.replay`).

    Parameters
    ----------
    track
        Path of the ``facemime.track/1`` file (``.json``).
    actor
        The actor the motion is played on; None: the generic painted head.

    Returns
    -------
    Clip
        The track's size and frame rate, its motion measured on the actor itself, no warnings.
    """
    from facemime.animate.replay import load_replay

    t0 = time.perf_counter()
    replay = load_replay(track, actor)
    if not any(m.face for m in replay.motion):
        raise InputFileError(f"track {track} has no frame with a face")
    return Clip(replay.actor, replay.fps, replay.size, replay.in_actor_units(), [], time.perf_counter() - t0)


def _look(frame: FrameMotion) -> Look:
    # a frame's look; neutral for motion made without one (FrameMotion before it had a look)
    return getattr(frame, "look", None) or Look()


def encode_clip(
    clip: Clip,
    settings: Settings,
    carry_actor: bool,
    basis: Basis | None = None,
    samples: list[tuple[int | None, ...]] | None = None,
) -> tuple[bytes, bytes, list[bytes]]:
    """The stream of an analysed clip.

    The stream carries the frames' looks (format version 2) when a frame with a face has a look
    that is not neutral; otherwise it is a version-1 stream.

    Parameters
    ----------
    clip
        The analysed clip.
    settings
        How the stream is coded.
    carry_actor
        Whether the actor follows the header in the stream.
    basis
        The clip's basis, cut to the settings' :attr:`~facemime.codec.stream.Settings.basis_size`
        vectors; None: learned from the clip's frames with a face.
    samples
        Per frame of the clip, the actor's samples the receiver draws, per group (eyes, mouth;
        :func:`facemime.codec.samples.choose_samples`), sent with each frame; None: not sent (the
        receiver chooses by the shapes).

    Returns
    -------
    header : bytes
        The header chunk.
    actor : bytes
        The actor chunk, or b"" when the actor is not carried.
    packets : list of bytes
        The packet chunks, in order.
    """
    faces = [m for m in clip.motion if m.face]
    m = settings.basis_size
    if basis is None:
        basis = Basis.learn(np.array([f.offsets for f in faces]).reshape(len(faces), -1, 2), m)
    basis = Basis(basis.raw[:m])
    look = any(np.any(_look(f).vector() != 0) for f in faces)
    steps = settings.steps(m, look)
    chosen = [np.array([0.0 if k is None else k + 1.0 for k in c]) for c in samples] if samples is not None else None
    steps += [SAMPLE_STEP] * len(SAMPLE_KINDS) if chosen is not None else []
    values = np.array(
        [
            np.concatenate(
                [pose_vector(f.pose), basis.coefficients(f.offsets)]
                + ([_look(f).vector()] if look else [])
                + ([chosen[i]] if chosen is not None else [])
            )
            for i, f in enumerate(clip.motion)
            if f.face
        ]
    )
    classes = _core.choose_classes(steps, settings.hysteresis, values.reshape(len(faces), len(steps)))
    enc = MotionEncoder(
        clip.actor,
        clip.fps,
        clip.size,
        basis,
        settings,
        carry_actor,
        classes,
        reference=clip.motion[0].pose,
        look=look,
        samples=samples is not None,
    )
    packets = [
        enc.push(
            f.face, f.lost, f.pose, f.offsets, _look(f) if look else None, None if samples is None else samples[i]
        ).data
        for i, f in enumerate(clip.motion)
    ]
    packets.append(enc.finish())
    start = enc.start()
    return enc.header, start[len(enc.header) :], [p for p in packets if p]


def with_appearance(
    video: str | Path,
    clip: Clip,
    header: bytes,
    actor_chunk: bytes,
    packets: list[bytes],
    settings: Settings,
    budget: float,
) -> tuple[list[bytes], AppearanceSender]:
    """A stream's packets with appearance updates (:mod:`facemime.codec.appearance`), each put
    before the packet holding its first frame.

    The video is read again, each frame laid onto the texture through what the receiver draws
    (the stream decoded here).

    Parameters
    ----------
    video
        Path of the video the clip was analysed from.
    clip
        Its analysis.
    header
        The stream's header chunk.
    actor_chunk
        The stream's actor chunk; b"": the stream does not carry the actor (``clip.actor`` is
        the receiver's).
    packets
        The stream's packet chunks, in order (:func:`encode_clip`).
    settings
        The settings the stream was coded with.
    budget
        The updates' rate, at most, kbit/s.

    Returns
    -------
    chunks : list of bytes
        The packets with the appearance chunks among them.
    sender : AppearanceSender
        The sender: its texture is the receiver's at the end.
    """
    decoder = MotionDecoder(None if actor_chunk else clip.actor)
    decoded = decoder.push(header + actor_chunk + b"".join(packets)) + decoder.finish()
    held = decoder.actor  # the actor as the receiver holds it: its texture as the stream carries it
    puppet = Puppet(held, Deformer(held.model).feature_sizes(), model_iod(held.model), mask_only=True)
    boxes = None if held.samples is None else np.vstack([g.boxes for g in held.samples.groups])
    sender = AppearanceSender(held.model, held.texture, budget, clip.fps, boxes)
    per_packet = settings.framing(clip.fps)[0]
    before: dict[int, list[bytes]] = {}
    with VideoReader(video) as reader:
        for i, (frame, f) in enumerate(zip(progress(reader, len(decoded), "appearance"), decoded)):
            if f.face and not f.concealed:
                payload = sender.update(i, frame, puppet.vertices(f.offsets, look=f.look), puppet.pose(f.pose))
                if payload is not None:
                    before.setdefault(i // per_packet, []).append(_core.appearance_chunk(payload))
    return [c for k, p in enumerate(packets) for c in before.get(k, []) + [p]], sender


def member_bytes(actor_chunk: bytes, prefix: str) -> int:
    """Bytes of some members of the actor file inside a stream's actor chunk.

    Parameters
    ----------
    actor_chunk
        The whole chunk (``docs/bitstream.md``, "Chunks" and "Actor": tag, seq, LEB128 length,
        payload = the actor file, CRC-32), or b"".
    prefix
        The members counted: those whose names start with it (``"scene."``: the scene's image;
        ``"samples"``: the sample library).

    Returns
    -------
    int
        Their compressed bytes in the actor file; 0 without a chunk or such members.
    """
    if not actor_chunk:
        return 0
    at = 3
    while actor_chunk[at] & 0x80:  # the length's bytes
        at += 1
    with zipfile.ZipFile(io.BytesIO(actor_chunk[at + 1 : -4])) as z:
        return sum(i.compress_size for i in z.infolist() if i.filename.startswith(prefix))


def read_stream(path: str | Path) -> bytes:
    """The bytes of a stream file (one-line errors for a missing, unreadable or huge file).

    Parameters
    ----------
    path
        Path of the ``.fmstream`` file; at most :data:`MAX_STREAM_BYTES` bytes.

    Returns
    -------
    bytes
        The file's contents.
    """
    path = Path(path)
    if not path.is_file():
        raise InputFileError(f"stream {path} does not exist" if not path.exists() else f"stream {path} is not a file")
    size = path.stat().st_size
    if size > MAX_STREAM_BYTES:
        raise InputFileError(f"stream {path} is {size} bytes, more than the {MAX_STREAM_BYTES} allowed")
    try:
        return path.read_bytes()
    except OSError as e:
        raise InputFileError(f"cannot read {path}: {e.strerror or e}") from None
