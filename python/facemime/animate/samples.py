"""The actor's own mouth and eyes in the synthesis: per frame, each sample group's sample is
pasted into the texture (:mod:`facemime.types.samples`): the one the stream chose
(``docs/bitstream.md``, "Sample choices"), or, without a choice, the one whose shape is nearest
the frame's. Under an eye sample the irises are not moved (:meth:`Puppet.render
<facemime.animate.synth.Puppet.render>`).

The nearest sample: the smallest Euclidean distance between keys, the look's iris shifts weighed
:data:`IRIS_WEIGHT` times its lid closures (an iris shift of a tenth of the eye's width looks as
different as a lid a half closed); the mouth's key is its knots' offsets, model units. The key
frame itself is a sample of every group, at key zero, that pastes nothing: where the frame's shape
is nearer the key frame's than any sample's, the texture is drawn as it is (the irises moved by
:class:`~facemime.animate.eyes.LookPainter` as without samples). A sample is pasted with its edges
faded into the texture over :data:`~facemime.render.paste.BLEND` texels
(:func:`~facemime.render.paste.paste_faded`), so that no seam shows.

A mouth sample taken from an open mouth also holds its *interior*: the opening between the inner
lips, laid out on a rectangle (:func:`interior_uv`: the upper inner lip along its top edge, the
lower along its bottom, corner to corner left to right). Where the chosen sample has one, the
synthesis draws the opening from it, stretched between the frame's inner lips
(:func:`interior_strip`), instead of a drawn cavity and teeth.
"""

from __future__ import annotations

import numpy as np

from facemime.render.paste import paste_faded
from facemime.shared_constants import IRIS_WEIGHT, LOOK_NAMES
from facemime.types.head import HeadModel, lip_strip
from facemime.types.look import Look
from facemime.types.samples import GROUPS, MOUTH_GROUPS, Samples


def interior_uv(model: HeadModel) -> np.ndarray:
    """Where the inner lips' vertices lie on the interior image.

    Parameters
    ----------
    model
        The head, with the inner lips' groups.

    Returns
    -------
    (N, 2) float64 array
        Per vertex of the model, (u, v) in [0, 1] of the interior image from its top-left corner:
        knot i of the K on the upper inner lip at (i / (K - 1), 0), on the lower at
        (i / (K - 1), 1), one on both (a corner) at (i / (K - 1), 0.5); 0 for the other vertices.
    """
    uv = np.zeros((len(model.vertices), 2))
    upper, lower = model.groups["mouth_inner_upper"], model.groups["mouth_inner_lower"]
    for curve, v in ((upper, 0.0), (lower, 1.0)):
        uv[curve] = np.column_stack([np.linspace(0.0, 1.0, len(curve)), np.full(len(curve), v)])
    shared = np.intersect1d(upper, lower)
    uv[shared, 1] = 0.5
    return uv


def interior_strip(model: HeadModel) -> tuple[np.ndarray, np.ndarray]:
    """The mesh an interior image is drawn on.

    Parameters
    ----------
    model
        The head, with the inner lips' groups.

    Returns
    -------
    uv : (N, 2) float64 array
        :func:`interior_uv`.
    triangles : (M, 3) int64 array
        The strip between the inner lips (:func:`~facemime.types.head.lip_strip`).
    """
    return interior_uv(model), lip_strip(model)


def weigh_eyes(keys: np.ndarray) -> np.ndarray:
    """Eye keys weighed for distances.

    Parameters
    ----------
    keys
        (..., 6) float array: look vectors (:data:`~facemime.shared_constants.LOOK_NAMES`' order).

    Returns
    -------
    (..., 6) float64 array
        The same, the iris shifts multiplied by :data:`IRIS_WEIGHT`.
    """
    return np.asarray(keys, np.float64) * np.where(np.arange(len(LOOK_NAMES)) < 2, 1.0, IRIS_WEIGHT)


def mouth_knots(groups: dict[str, np.ndarray], knots: np.ndarray) -> np.ndarray:
    """Which knots key the mouth's samples.

    Parameters
    ----------
    groups
        The head model's vertex groups.
    knots
        (K,) the model's knots' vertex indices (:attr:`facemime.animate.deform.Deformer.knots`).

    Returns
    -------
    (K,) bool array
        True for the knots on the lips.
    """
    return np.isin(knots, np.concatenate([groups[g] for g in MOUTH_GROUPS]))


def nearest(keys: np.ndarray, key: np.ndarray) -> int | None:
    """The sample nearest a shape, or None where the key frame is nearer.

    Parameters
    ----------
    keys
        (S, D) float array: the samples' keys, as weighed for distances.
    key
        (D,) float array: the frame's key, weighed the same way.

    Returns
    -------
    int or None
        The index of the nearest sample (the first of equals); None when the key frame (key zero)
        is at least as near.
    """
    d = np.linalg.norm(keys - key, axis=1)
    k = int(np.argmin(d))
    return None if np.linalg.norm(key) <= d[k] else k


class SamplePainter:
    """Pastes an actor's samples into its texture, frame by frame.

    Parameters
    ----------
    samples
        The actor's sample library.
    groups
        The actor's head model's vertex groups.
    knots
        (K,) the model's knots' vertex indices (:attr:`facemime.animate.deform.Deformer.knots`).
    """

    def __init__(self, samples: Samples, groups: dict[str, np.ndarray], knots: np.ndarray):
        self.samples = samples
        self._mouth = mouth_knots(groups, knots)
        self._keys = {g.name: weigh_eyes(g.keys) if g.name == "eyes" else g.keys for g in samples.groups}
        self._work: np.ndarray | None = None

    def choose(
        self, offsets: np.ndarray, look: Look, sent: tuple[int | None, ...] | None = None
    ) -> dict[str, int | None]:
        """Each group's sample for a frame.

        Parameters
        ----------
        offsets
            (K, 2) float array: the frame's knot offsets in the actor's model units.
        look
            The frame's look.
        sent
            The samples the stream chose for the frame, per group of
            :data:`~facemime.types.samples.GROUPS` (None: the key frame's); an index beyond a
            group's samples draws none. None: chosen by the shapes, the :func:`nearest` key.

        Returns
        -------
        dict of str -> int or None
            Group name -> the sample pasted (None: the key frame's, nothing pasted).
        """
        if sent is not None:
            sizes = {g.name: len(g.keys) for g in self.samples.groups}
            return {n: k if k is not None and k < sizes.get(n, 0) else None for n, k in zip(GROUPS, sent)}
        frame_keys = {"eyes": weigh_eyes(look.vector()), "mouth": np.asarray(offsets, np.float64)[self._mouth].ravel()}
        return {
            name: nearest(keys, frame_keys[name]) if keys.shape[1] == len(frame_keys[name]) else None
            for name, keys in self._keys.items()
        }

    def paint(self, texture: np.ndarray, chosen: dict[str, int | None]) -> tuple[np.ndarray, np.ndarray | None]:
        """The texture with a frame's samples pasted in, and the mouth's interior.

        Parameters
        ----------
        texture
            (H, W, 3) uint8 RGB: the texture the frame is drawn with otherwise (not changed); where
            the eyes' sample is pasted, its irises need not be moved.
        chosen
            Group name -> the sample pasted (:meth:`choose`).

        Returns
        -------
        texture : (H, W, 3) uint8 array
            ``texture`` itself when no sample is pasted, else a working copy with the samples,
            valid until the next call.
        interior : (h, w, 3) uint8 array or None
            The chosen mouth sample's interior (:func:`interior_uv`); None where it has none or no
            mouth sample is chosen.
        """
        mouth, k = self.samples.group("mouth"), chosen.get("mouth")
        interior = None if mouth is None or mouth.interiors is None or k is None else mouth.interiors[k]
        if all(k is None for k in chosen.values()):
            return texture, interior
        if self._work is None or self._work.shape != texture.shape:
            self._work = np.empty_like(texture)
        np.copyto(self._work, texture)
        for group in self.samples.groups:
            k = chosen.get(group.name)
            if k is not None:
                for (x, y, _, _), image in zip(group.boxes, group.images[k]):
                    paste_faded(self._work, image, int(x), int(y))
        return self._work, interior
