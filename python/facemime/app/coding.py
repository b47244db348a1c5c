"""`facemime encode` and `facemime decode`: a video (or a track file) analysed and written as a
motion stream, and a stream synthesised back into a video (the stream itself is
:mod:`facemime.codec.stream`, its clips :mod:`facemime.codec.clip`)."""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from facemime.animate.deform import Deformer
from facemime.animate.synth import Puppet
from facemime.codec.appearance import Appearance
from facemime.codec.clip import (
    MAX_APPEARANCE,
    MAX_COEFFICIENTS,
    MAX_CONCEALED_RATIO,
    SUFFIX,
    Clip,
    analyse,
    encode_clip,
    member_bytes,
    read_stream,
    track_clip,
    with_appearance,
)
from facemime.codec.decoder import MotionDecoder
from facemime.codec.params import Basis
from facemime.codec.samples import build_samples, choose_samples
from facemime.codec.stream import LADDER, Settings, StreamError
from facemime.errors import InvalidInputError
from facemime.io.actor_file import load_actor
from facemime.io.outputs import check_outputs, write_bytes
from facemime.io.video import CODECS, VideoWriter
from facemime.progress import track as progress
from facemime.render.raster import fill
from facemime.shared_constants import BACKGROUND, NO_FACE_DIM
from facemime.types.head import model_iod


@dataclass
class EncodeResult:
    """What :func:`encode_video` wrote: frames, the quality used, bytes of the header (with the
    basis), of the actor (0 when only named; its scene's image ``scene_bytes`` and its sample
    library ``samples_bytes`` of them), of the motion (packets), of the appearance updates and how
    many, and seconds (analysis, coding)."""

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
    samples_bytes: int = 0

    @property
    def motion_kbit_s(self) -> float:
        """The motion's rate, kbit/s."""
        return self.motion_bytes * 8 / 1000 / (self.frames / self.fps)

    @property
    def appearance_kbit_s(self) -> float:
        """The appearance updates' rate, kbit/s (their chunks, framing included)."""
        return self.appearance_bytes * 8 / 1000 / (self.frames / self.fps)


def encode_video(
    video: str | Path,
    out: str | Path,
    actor: str | Path | None = None,
    settings: Settings = Settings(),
    rate: float | None = None,
    carry_actor: bool | None = None,
    force: bool = False,
    appearance: float = 0.0,
    samples: bool = True,
) -> EncodeResult:
    """Analyse a video and write its motion as a stream (``docs/bitstream.md``).

    Parameters
    ----------
    video
        The video to analyse; one ending in ``.json`` is a track file whose motion is coded
        instead (:func:`~facemime.codec.clip.track_clip`), at its size and frame rate.
    out
        The stream file to write; its name must end in ``.fmstream``. Refused when it exists
        (unless ``force``) or is one of the inputs.
    actor
        An ``.actor`` file the receiver holds: the stream names it. None fits one on the first
        frame (for a track file, takes the generic painted head), and the stream carries it.
    settings
        How the stream is coded: quality 0-10, seconds between intra packets, seconds of frames
        per packet (default :class:`~facemime.codec.stream.Settings`: quality 5, 1 s, 0.5 s).
    rate
        The motion's target rate, kbit/s: the finest quality that fits is taken and
        ``settings.quality`` ignored (a warning when even the coarsest does not fit). None:
        ``settings.quality``.
    carry_actor
        Put the actor in the stream; None: only when ``actor`` was not given.
    force
        Write over an existing ``out``.
    appearance
        kbit/s for appearance updates (the face's look sent again where it changes), 0 to 1000;
        0: none (a track file has no appearance).
    samples
        Send, with the actor the stream carries, a library of the face's own mouth and eyes
        chosen from the video (:mod:`facemime.codec.samples`); the receiver draws them instead of
        a drawn mouth interior and moved irises. Ignored for a track file or an actor not carried.

    Returns
    -------
    EncodeResult
        What was written: frames, the quality used, bytes of each part, seconds and warnings.
    """
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
    chosen, (header, actor_chunk, packets), short = _at_rate(clip, settings, carry, basis, rate, duration)
    if samples and carry and not from_track:
        decoder = MotionDecoder()
        decoded = decoder.push(header + actor_chunk + b"".join(packets)) + decoder.finish()
        assert decoder.actor is not None  # the stream carries it
        library = build_samples(video, decoder.actor, decoded)
        if library is not None:
            choices = choose_samples(video, replace(decoder.actor, samples=library), decoded)
            clip = replace(clip, actor=replace(clip.actor, samples=library))
            # the choices take some of the rate: the quality is chosen again with them
            chosen, (header, actor_chunk, packets), short = _at_rate(
                clip, settings, carry, basis, rate, duration, choices
            )
    warnings += short
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
        member_bytes(actor_chunk, "scene."),
        sent,
        updates,
        member_bytes(actor_chunk, "samples"),
    )


def _at_rate(
    clip: Clip,
    settings: Settings,
    carry: bool,
    basis: Basis,
    rate: float | None,
    duration: float,
    choices: list[tuple[int | None, ...]] | None = None,
) -> tuple[Settings, tuple[bytes, bytes, list[bytes]], list[str]]:
    """The clip coded at ``settings`` or, given a ``rate`` (kbit/s of packets), at the finest
    quality whose packets fit it; the settings used, the stream's parts, and a warning when even
    the coarsest does not fit."""
    if rate is None:
        return settings, encode_clip(clip, settings, carry, basis, choices), []
    for quality in reversed(range(len(LADDER))):
        chosen = replace(settings, quality=quality)
        parts = encode_clip(clip, chosen, carry, basis, choices)
        needed = sum(map(len, parts[2])) * 8 / 1000 / duration
        if needed <= rate:
            return chosen, parts, []
    return chosen, parts, [f"the coarsest quality needs {needed:.2f} kbit/s, more than the {rate:g} asked for"]


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


def decode_stream(
    stream: str | Path, out: str | Path, actor: str | Path | None = None, force: bool = False, mask_only: bool = False
) -> DecodeResult:
    """Decode a stream and write the synthesised picture as a video, at the stream's frame rate
    and size. Frames without a face show the last face dimmed; lost frames repeat the last good
    one.

    Parameters
    ----------
    stream
        The ``.fmstream`` file to decode.
    out
        The video to write, ``.mp4`` (H.264) or ``.webm`` (VP9). Refused when it exists (unless
        ``force``) or is one of the inputs.
    actor
        The ``.actor`` file the stream names, when it does not carry its actor; None otherwise.
    force
        Write over an existing ``out``.
    mask_only
        Show the face alone on a plain backdrop (0-255 RGB :data:`BACKGROUND`), not in its actor's
        scene; it is shown so also when the actor has no scene.

    Returns
    -------
    DecodeResult
        Frames written and concealed, the decoder's counts, seconds, appearance updates applied
        and refused.
    """
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
    assert info is not None and target is not None  # both come with the first decoded frame
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
                puppet.render(f.pose, f.offsets, (w, h), out=image, look=f.look, samples=f.samples)
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
