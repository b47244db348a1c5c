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
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from facemime import _core
from facemime.animate.analysis import FrameMotion, start_analysis
from facemime.animate.deform import Deformer
from facemime.animate.synth import Puppet
from facemime.codec.appearance import Appearance, AppearanceSender
from facemime.codec.params import Basis, pose_vector
from facemime.codec.stream import LADDER, MotionDecoder, MotionEncoder, Settings, StreamError
from facemime.errors import InputFileError, InvalidInputError
from facemime.io.actor_file import load_actor
from facemime.io.outputs import check_outputs, write_bytes
from facemime.io.video import CODECS, VideoReader, VideoWriter
from facemime.progress import track as progress
from facemime.render.texture_map import fill
from facemime.shared_constants import BACKGROUND, NO_FACE_DIM
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
class EncodeResult:
    """What :func:`encode_video` wrote: frames, the quality used, bytes of the header (with the
    basis), of the actor (0 when only named; its scene's image ``scene_bytes`` of them), of the
    motion (packets), of the appearance updates and how many, and seconds (analysis, coding)."""

    frames: int
    fps: float
    quality: int
    header_bytes: int
    actor_bytes: int
    motion_bytes: int
    seconds: dict[str, float] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)
    scene_bytes: int = 0
    appearance_bytes: int = 0
    appearance_updates: int = 0

    @property
    def motion_kbit_s(self) -> float:
        """The motion's rate, kbit/s."""
        return self.motion_bytes * 8 / 1000 / (self.frames / self.fps)

    @property
    def appearance_kbit_s(self) -> float:
        """The appearance updates' rate, kbit/s (their chunks, framing included)."""
        return self.appearance_bytes * 8 / 1000 / (self.frames / self.fps)


@dataclass
class Clip:
    """A video's analysis: its actor, frame rate, size (width, height) and per-frame motion."""

    actor: Actor
    fps: float
    size: tuple[int, int]
    motion: list[FrameMotion]
    warnings: list[str]
    seconds: float


def analyse(video: str | Path, actor: Actor | None = None) -> Clip:
    """Fit (or place ``actor``), track and measure every frame of ``video``."""
    t0 = time.perf_counter()
    with VideoReader(video) as reader:
        analysis, motion = None, []
        for frame in progress(reader, reader.frames or None, "analysing"):
            if analysis is None:
                analysis = start_analysis(frame, str(video), actor=actor, fps=reader.fps)
                motion.append(analysis.last)
            else:
                motion.append(analysis.update(frame))
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
    """The motion of the ``facemime.track/1`` file ``track`` as a clip, on ``actor`` (default:
    the generic painted head) as ``view`` plays it (:mod:`facemime.animate.replay`): the track's
    size and frame rate, its motion measured on the actor itself."""
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
    clip: Clip, settings: Settings, carry_actor: bool, basis: Basis | None = None
) -> tuple[bytes, bytes, list[bytes]]:
    """The stream of an analysed clip: (header, actor chunk or b"", packets). ``basis``: the
    clip's (default: learned from it, at the settings' size). The stream carries the frames'
    looks (format version 2) when a frame with a face has a look that is not neutral; otherwise
    it is a version-1 stream."""
    faces = [m for m in clip.motion if m.face]
    m = settings.basis_size
    if basis is None:
        basis = Basis.learn(np.array([f.offsets for f in faces]).reshape(len(faces), -1, 2), m)
    basis = Basis(basis.raw[:m])
    look = any(np.any(_look(f).vector() != 0) for f in faces)
    steps = settings.steps(m, look)
    values = np.array(
        [
            np.concatenate([pose_vector(f.pose), basis.coefficients(f.offsets)] + ([_look(f).vector()] if look else []))
            for f in faces
        ]
    )
    classes = _core.choose_classes(steps, settings.hysteresis, values.reshape(len(faces), len(steps)))
    enc = MotionEncoder(
        clip.actor, clip.fps, clip.size, basis, settings, carry_actor, classes, reference=clip.motion[0].pose, look=look
    )
    packets = [enc.push(f.face, f.lost, f.pose, f.offsets, _look(f) if look else None).data for f in clip.motion]
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
    """``packets`` with appearance updates (:mod:`facemime.codec.appearance`) of at most
    ``budget`` kbit/s put before the packet holding each update's first frame: ``video`` is read
    again, each frame laid onto the texture through what the receiver draws (the stream decoded
    here). Returns the chunks and the sender (its texture is the receiver's at the end)."""
    decoder = MotionDecoder(None if actor_chunk else clip.actor)
    decoded = decoder.push(header + actor_chunk + b"".join(packets)) + decoder.finish()
    held = decoder.actor  # the actor as the receiver holds it: its texture as the stream carries it
    puppet = Puppet(held, Deformer(held.model).feature_sizes(), model_iod(held.model), mask_only=True)
    sender = AppearanceSender(held.model, held.texture, budget, clip.fps)
    per_packet = settings.framing(clip.fps)[0]
    before: dict[int, list[bytes]] = {}
    with VideoReader(video) as reader:
        for i, (frame, f) in enumerate(zip(progress(reader, len(decoded), "appearance"), decoded)):
            if f.face and not f.concealed:
                payload = sender.update(i, frame, puppet.vertices(f.offsets, look=f.look), puppet.pose(f.pose))
                if payload is not None:
                    before.setdefault(i // per_packet, []).append(_core.appearance_chunk(payload))
    return [c for k, p in enumerate(packets) for c in before.get(k, []) + [p]], sender


def encode_video(
    video: str | Path,
    out: str | Path,
    actor: str | Path | None = None,
    settings: Settings = Settings(),
    rate: float | None = None,
    carry_actor: bool | None = None,
    force: bool = False,
    appearance: float = 0.0,
) -> EncodeResult:
    """Analyse ``video`` and write the stream ``out`` (``.fmstream``); a ``video`` ending in
    ``.json`` is a track file whose motion is coded instead (:func:`track_clip`). ``actor``: an
    ``.actor`` file the receiver holds (the stream names it; default: fit one on the first frame,
    or for a track file the generic painted head, and the stream carries it). ``rate``: the
    motion's target, kbit/s: the finest quality that fits (``settings.quality`` is then ignored).
    ``carry_actor``: put the actor in the stream (default: only when it was not given).
    ``appearance``: kbit/s for appearance updates (0: none; a track file has no appearance)."""
    out = Path(out)
    if out.suffix.lower() != SUFFIX:
        raise InvalidInputError(f"the stream must end in {SUFFIX}, got {out.name!r}")
    if rate is not None and not (np.isfinite(rate) and rate > 0):
        raise InvalidInputError(f"the target rate must be a positive number of kbit/s, got {rate}")
    if not (np.isfinite(appearance) and 0 <= appearance <= MAX_APPEARANCE):
        raise InvalidInputError(f"the appearance budget must be 0-{MAX_APPEARANCE:g} kbit/s, got {appearance}")
    from_track = Path(video).suffix.lower() == ".json"
    if from_track and appearance > 0:
        raise InvalidInputError(f"appearance updates are taken from a video, and {video} is a track file")
    check_outputs([out], force, inputs=[video, actor])
    given = load_actor(actor) if actor is not None else None
    carry = given is None if carry_actor is None else carry_actor
    clip = track_clip(video, given) if from_track else analyse(video, given)
    t0 = time.perf_counter()
    faces = [m.offsets for m in clip.motion if m.face]
    basis = Basis.learn(np.array(faces).reshape(len(faces), -1, 2), MAX_COEFFICIENTS)
    warnings = list(clip.warnings)
    duration = len(clip.motion) / clip.fps
    if rate is None:
        chosen = settings
        header, actor_chunk, packets = encode_clip(clip, settings, carry, basis)
    else:
        for quality in reversed(range(len(LADDER))):
            chosen = replace(settings, quality=quality)
            header, actor_chunk, packets = encode_clip(clip, chosen, carry, basis)
            if sum(map(len, packets)) * 8 / 1000 / duration <= rate:
                break
        else:
            warnings.append(
                f"the coarsest quality needs {sum(map(len, packets)) * 8 / 1000 / duration:.2f} kbit/s, "
                f"more than the {rate:g} asked for"
            )
    motion_bytes, updates, sent = sum(map(len, packets)), 0, 0
    if appearance > 0:
        chunks, sender = with_appearance(video, clip, header, actor_chunk, packets, chosen, appearance)
        sent, updates = sum(map(len, chunks)) - motion_bytes, sender.updates
        packets = chunks
    write_bytes(out, header + actor_chunk + b"".join(packets))
    seconds = {"analysis": clip.seconds, "coding": time.perf_counter() - t0}
    return EncodeResult(
        len(clip.motion),
        clip.fps,
        chosen.quality,
        len(header),
        len(actor_chunk),
        motion_bytes,
        seconds,
        warnings,
        scene_bytes(actor_chunk),
        sent,
        updates,
    )


def scene_bytes(actor_chunk: bytes) -> int:
    """Bytes of the scene image inside a stream's actor chunk (``docs/bitstream.md``: tag, seq,
    LEB128 length, payload = the actor file, CRC-32); 0 without a chunk or a scene."""
    if not actor_chunk:
        return 0
    at = 3
    while actor_chunk[at] & 0x80:  # the length's bytes
        at += 1
    with zipfile.ZipFile(io.BytesIO(actor_chunk[at + 1 : -4])) as z:
        return sum(i.compress_size for i in z.infolist() if i.filename.startswith("scene."))


@dataclass
class DecodeResult:
    """What :func:`decode_stream` did: frames written, frames concealed, the decoder's counts
    (see :attr:`MotionDecoder.stats`), and the appearance updates applied and refused (their
    image did not decode, or lay outside the texture)."""

    frames: int
    concealed: int
    stats: dict[str, int]
    seconds: float
    appearance_updates: int = 0
    appearance_refused: int = 0


def read_stream(path: str | Path) -> bytes:
    """The bytes of a stream file (one-line errors for a missing, unreadable or huge file)."""
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


def decode_stream(
    stream: str | Path, out: str | Path, actor: str | Path | None = None, force: bool = False, mask_only: bool = False
) -> DecodeResult:
    """Decode ``stream`` and write the synthesised picture to ``out`` (.mp4 or .webm) at the
    stream's frame rate and size: the face in its actor's scene, or alone with ``mask_only`` (or
    when the actor has no scene). ``actor``: the ``.actor`` file the stream names when it does
    not carry it. Frames without a face show the last face dimmed; lost frames repeat the last
    good one."""
    out = Path(out)
    if out.suffix.lower() not in CODECS:
        raise InvalidInputError(f"the output video must end in .mp4 or .webm, got {out.name!r}")
    check_outputs([out], force, inputs=[stream, actor])
    t0 = time.perf_counter()
    data = read_stream(stream)
    decoder = MotionDecoder(
        load_actor(actor) if actor is not None else None, name=str(stream), max_concealed=MAX_CONCEALED_RATIO
    )
    frames = decoder.push(data) + decoder.finish()
    if decoder.stats["frames"] == 0:
        raise StreamError(f"{stream}: no frame could be decoded ({decoder.stats['damaged_bytes']} damaged bytes)")
    info, target = decoder.info, decoder.actor
    puppet = Puppet(
        target, Deformer(target.model).feature_sizes(), model_iod(target.model), decoder.reference(), mask_only
    )
    w, h = info.size
    image, shown = np.empty((h, w, 3), np.uint8), np.empty((h, w, 3), np.uint8)
    updates = Appearance(target.texture, decoder.appearance, decoder.appearance_after)
    with VideoWriter(out, info.fps) as writer:
        for f in progress(frames, len(frames), "decoding"):
            if updates.due(f.index):
                puppet.retexture(updates.texture)
            if not f.concealed:
                if puppet.scene is None:
                    fill(image, BACKGROUND)
                puppet.render(f.pose, f.offsets, (w, h), out=image, look=f.look)
                shown[:] = image if f.face else (image * NO_FACE_DIM).astype(np.uint8)
            writer.write(shown)
    return DecodeResult(
        len(frames),
        decoder.stats["concealed"],
        decoder.stats,
        time.perf_counter() - t0,
        updates.applied,
        updates.refused,
    )
