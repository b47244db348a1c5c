"""The 52 ARKit blendshapes of a frame: what avatar software (VSeeFace, Warudo, three-vrm, Unity,
Unreal) takes from a face tracker, by name.

Every value is 0..1 and relative to the key frame the actor was fitted on (0: as there). Left and
right are the subject's own, as ARKit's are. They come from three measures:

- the **expression controls** (:mod:`facemime.animate.expressions`): the 27 mouth, jaw, brow and
  lid controls under their own names; of two controls that move the same knots opposite ways
  (``mouthLeft``/``mouthRight``, ``jawLeft``/``jawRight``) only their difference shows, so the
  smaller is taken from both (:data:`OPPOSITES`);
- the **irises** (:class:`facemime.types.look.Look`'s ``iris``, eye widths): ``eyeLook*``, the
  shift along the eye over :data:`LOOK_SIDE`, down over :data:`LOOK_DOWN`, up over
  :data:`LOOK_UP`; the subject's right eye is image-left, so its iris moving image-right looks in
  (towards the nose), the left eye's looks out;
- the **blinks**, not the lid closure as it is: ARKit's ``eyeBlink*`` means shut, and a lid that
  follows the eye looking down closes part of the way (:func:`blinks`): where the quick measures
  see an eye closing, MediaPipe's eye model (:mod:`facemime.networks.eyelids`) looks at its
  lids.

The names in :data:`UNMEASURED` are not measured by the analysis: they are always 0. The
contours show no depth (``jawForward``), cheeks, nose wings or tongue, and neither lid's
narrowing from below (``eyeSquint``) nor widening (``eyeWide``: the eye tracker reads an eye at
most 10% wider than on the key frame, within its noise on renders of the lids raised). Press,
dimple and shrug move the lips as roll, stretch and the lower lip's raise do in a contour.
"""

from __future__ import annotations

import numpy as np

from facemime.animate.box_solver import BoxLeastSquares
from facemime.animate.expressions import MAGNITUDES, Expressions
from facemime.animate.expressions import NAMES as CONTROLS
from facemime.errors import InvalidInputError
from facemime.types.head import HeadModel
from facemime.types.look import Look

#: ARKit's 52 blendshape names, in the order of Apple's ``ARFaceAnchor.BlendShapeLocation`` list
#: (eyes, jaw, mouth, brows, cheeks, nose, tongue): the order of every value vector here.
NAMES: tuple[str, ...] = (
    "eyeBlinkLeft",
    "eyeLookDownLeft",
    "eyeLookInLeft",
    "eyeLookOutLeft",
    "eyeLookUpLeft",
    "eyeSquintLeft",
    "eyeWideLeft",
    "eyeBlinkRight",
    "eyeLookDownRight",
    "eyeLookInRight",
    "eyeLookOutRight",
    "eyeLookUpRight",
    "eyeSquintRight",
    "eyeWideRight",
    "jawForward",
    "jawLeft",
    "jawRight",
    "jawOpen",
    "mouthClose",
    "mouthFunnel",
    "mouthPucker",
    "mouthLeft",
    "mouthRight",
    "mouthSmileLeft",
    "mouthSmileRight",
    "mouthFrownLeft",
    "mouthFrownRight",
    "mouthDimpleLeft",
    "mouthDimpleRight",
    "mouthStretchLeft",
    "mouthStretchRight",
    "mouthRollLower",
    "mouthRollUpper",
    "mouthShrugLower",
    "mouthShrugUpper",
    "mouthPressLeft",
    "mouthPressRight",
    "mouthLowerDownLeft",
    "mouthLowerDownRight",
    "mouthUpperUpLeft",
    "mouthUpperUpRight",
    "browDownLeft",
    "browDownRight",
    "browInnerUp",
    "browOuterUpLeft",
    "browOuterUpRight",
    "cheekPuff",
    "cheekSquintLeft",
    "cheekSquintRight",
    "noseSneerLeft",
    "noseSneerRight",
    "tongueOut",
)
#: The eyes' look directions: measured, with no morph target on facemime's head (its irises are
#: painted in the texture).
LOOKS: tuple[str, ...] = tuple(n for n in NAMES if n.startswith("eyeLook"))
#: Not measured by the analysis: always 0.
UNMEASURED: tuple[str, ...] = (
    "eyeSquintLeft",
    "eyeSquintRight",
    "eyeWideLeft",
    "eyeWideRight",
    "jawForward",
    "mouthDimpleLeft",
    "mouthDimpleRight",
    "mouthShrugLower",
    "mouthShrugUpper",
    "mouthPressLeft",
    "mouthPressRight",
    "cheekPuff",
    "cheekSquintLeft",
    "cheekSquintRight",
    "noseSneerLeft",
    "noseSneerRight",
    "tongueOut",
)
# The iris shifts at a full look, eye widths: the 99th percentiles of the analysis's iris shift
# over the ten shared videos (3,101 frames). Sideways the median of the videos' own (0.07-0.46;
# lp_d3's shut eyes hold stray shifts); down and up over all frames pooled (0.22, 0.13).
#: Iris shift along the eye at ``eyeLookIn``/``eyeLookOut`` = 1, eye widths.
LOOK_SIDE = 0.30
#: Iris shift down at ``eyeLookDown`` = 1, eye widths.
LOOK_DOWN = 0.22
#: Iris shift up at ``eyeLookUp`` = 1, eye widths.
LOOK_UP = 0.13
# Blinks, measured against the Face Mesh references' lid openings on the ten shared videos (shut:
# under 0.35 of frame 0's opening, 405 eye-frames; open and looking down: over 0.6, the iris 0.04
# eye widths down, 905). The quick measures, made every frame, cannot tell the two apart: the eye
# tracker's closure reads a lid that follows the eye down as closing, the landmark pass reads a
# shut lid half shut (its eyes' points are coarse). Averaged, the landmarks' scaled by 2.5, and
# ramped from 0.35 to 0.5 they gave > 0.5 on 355 of the shut eye-frames and < 0.2 on 784 of those
# looking down (lp_d3: 240 of 244, 41 of 76). The eye model's lids tell them apart: its closure
# ramped from 0.4 to 0.475 gives 379 of 405 and 902 of 905 (lp_d3: 228 of 244, 76 of 76), and
# > 0.2 on none of the 5,206 eye-frames open wider than 0.8; the shut frames it misses are eyes
# nearly closed (the ramp from 0.375 gave 383 and 895, lp_d3 231 and 70: an eye looking down
# read as half shut). Its opening is taken over the mean of the two eyes' key-frame openings,
# not each eye's own (lp_d3 so: 224 and 70 from 0.425): a key frame with one eye opened wider
# reads that eye as closing sooner. It costs 3.4 ms an eye (one core), so it looks only at eyes
# whose quick closure is 0.2 or more: 26% of the eye-frames, none of the counts above lost. An eye
# that blinked on the frame before is held shut down to a closure 0.05 lower (the eyes' frames
# on their way open, and the model's wavering about the line, no longer flicker): 388 of 405 and
# 902 of 905 (lp_d3: 234 of 244, 76 of 76); 0.1 lower lost a look down, 0.15 lower 22.
#: The quick closure (the eye tracker's and the landmarks' mean) at which a blink starts (0) and
#: is full (1), where the eye model did not look.
BLINK_FROM, BLINK_TO = 0.35, 0.5
#: The landmark pass's closure is multiplied by this before it is averaged with the eye tracker's.
LANDMARK_SCALE = 2.5
#: The eye model looks at an eye whose quick closure is at least this.
LID_GATE = 0.2
#: The eye model's closure at which a blink starts (0) and is full (1).
LID_FROM, LID_TO = 0.4, 0.475
#: For an eye that blinked (``eyeBlink`` 0.5 or more) on the frame before, the eye model's ramp
#: starts this much lower.
LID_HOLD = 0.05
#: Pairs of controls that move the same knots opposite ways.
OPPOSITES = (("mouthLeft", "mouthRight"), ("jawLeft", "jawRight"))
# Face Mesh points of the nose's bridge and the chin's tip, and of the inner lips' middles.
_BRIDGE, _CHIN = 168, 152
_LIPS = (13, 14)
# Face Mesh points of each eye (subject's right first, as Look.closure): the corners, then the
# upper and lower lids' middles.
_EYE_POINTS = ((33, 133, 159, 145), (362, 263, 386, 374))


def landmark_openings(landmarks: np.ndarray) -> np.ndarray:
    """Each eye's opening in the Face Mesh landmarks.

    Parameters
    ----------
    landmarks
        (468, 2+) float array: the Face Mesh landmarks, (x, y) pixels first.

    Returns
    -------
    (2,) float64 array
        Per eye (the subject's right first), the distance between its lids' middles over its
        width (corner to corner).
    """
    p = np.asarray(landmarks, np.float64)[:, :2]
    ends = [(up, low, a, b) for a, b, up, low in _EYE_POINTS]
    return np.array(
        [np.linalg.norm(p[u] - p[d]) / max(float(np.linalg.norm(p[b] - p[a])), 1e-9) for u, d, a, b in ends]
    )


def chin_drop(landmarks: np.ndarray, key: np.ndarray) -> float:
    """How far the chin has dropped from its place on the key frame, in the Face Mesh landmarks.

    The distance from the nose's bridge to the chin, in 3-D (the landmarks' depth included, so a
    nod does not shorten it) and over the eyes' outer corners' distance (so coming nearer does
    not lengthen it), against the key frame's.

    Parameters
    ----------
    landmarks
        (468, 3) float array: the frame's Face Mesh landmarks, (x, y) pixels and depth.
    key
        (468, 3) float array: the key frame's.

    Returns
    -------
    float
        The drop in units of the key frame's mouth width (corner to corner); negative: raised.
    """

    def ratios(p: np.ndarray) -> tuple[float, float]:
        iod = max(float(np.linalg.norm(p[263] - p[33])), 1e-9)
        return float(np.linalg.norm(p[_CHIN] - p[_BRIDGE])) / iod, float(np.linalg.norm(p[291] - p[61])) / iod

    now, (then, mouth) = ratios(np.asarray(landmarks, np.float64)), ratios(np.asarray(key, np.float64))
    return (now[0] - then) / max(mouth, 1e-9)


def jaw_opening(landmarks: np.ndarray, key: np.ndarray) -> float:
    """How far the jaw is open from closed lips, in the Face Mesh landmarks: the chin's drop from
    the key frame (:func:`chin_drop`) plus the gap the key frame had between the inner lips'
    middles, so that a key frame with the mouth open does not make that opening the jaw's zero.

    Parameters
    ----------
    landmarks
        (468, 3) float array: the frame's Face Mesh landmarks, (x, y) pixels and depth.
    key
        (468, 3) float array: the key frame's.

    Returns
    -------
    float
        Mouth widths of the key frame.
    """
    k = np.asarray(key, np.float64)
    gap = float(np.linalg.norm(k[_LIPS[0]] - k[_LIPS[1]])) / max(float(np.linalg.norm(k[291] - k[61])), 1e-9)
    return chin_drop(landmarks, key) + gap


def quick_closures(closure: np.ndarray, landmark_closure: np.ndarray | None = None) -> np.ndarray:
    """Each eye's closure by the measures made every frame: the eye tracker's and the landmark
    pass's, averaged.

    Parameters
    ----------
    closure
        (2,) float array: the eye tracker's closures (:class:`~facemime.types.look.Look`'s; right
        eye first).
    landmark_closure
        (2,) float array: 1 - the landmarks' :func:`landmark_openings` over the key frame's, or
        None (or NaN per eye) where not measured: the eye tracker's alone then.

    Returns
    -------
    (2,) float64 array
        Right eye, left eye: the mean of the eye tracker's closure and :data:`LANDMARK_SCALE`
        times the landmarks' (the eye tracker's alone where those are not measured).
    """
    c = np.asarray(closure, np.float64)
    if landmark_closure is None:
        return c
    lm = np.asarray(landmark_closure, np.float64)
    return np.where(np.isfinite(lm), (c + LANDMARK_SCALE * lm) / 2.0, c)


def blinks(
    closure: np.ndarray,
    landmark_closure: np.ndarray | None = None,
    lid_closure: np.ndarray | None = None,
    held: np.ndarray | None = None,
) -> np.ndarray:
    """ARKit's ``eyeBlinkRight``/``eyeBlinkLeft`` of a frame's lid closures.

    Parameters
    ----------
    closure
        (2,) float array: the eye tracker's closures (:class:`~facemime.types.look.Look`'s; right
        eye first).
    landmark_closure
        (2,) float array: the landmarks' closures, as :func:`quick_closures` takes them, or None.
    lid_closure
        (2,) float array: the eye model's closures (1 - its opening over the key frame's, the
        two eyes' mean), NaN per eye where it did not look; or None where it looked at neither.
    held
        (2,) bool array: the eyes that blinked on the frame before (their ramp on the eye model's
        closure starts :data:`LID_HOLD` lower), or None: neither.

    Returns
    -------
    (2,) float64 array
        Right eye, left eye, 0..1: the eye model's closure ramped from :data:`LID_FROM` to
        :data:`LID_TO` where it looked; elsewhere the :func:`quick_closures` ramped from
        :data:`BLINK_FROM` to :data:`BLINK_TO`.
    """
    quick = np.clip((quick_closures(closure, landmark_closure) - BLINK_FROM) / (BLINK_TO - BLINK_FROM), 0.0, 1.0)
    if lid_closure is None:
        return quick
    lid = np.asarray(lid_closure, np.float64)
    if held is not None:
        lid = lid + LID_HOLD * np.asarray(held, bool)
    return np.where(np.isfinite(lid), np.clip((lid - LID_FROM) / (LID_TO - LID_FROM), 0.0, 1.0), quick)


def looks(iris: np.ndarray) -> dict[str, float]:
    """The ``eyeLook*`` values of a frame's iris shifts.

    Parameters
    ----------
    iris
        (2, 2) float array: per eye (the subject's right first), the iris's (u, v) shift, eye
        widths (u image-left to image-right along the eye, v down).

    Returns
    -------
    dict of str to float
        The eight :data:`LOOKS` names, 0..1.
    """
    i = np.asarray(iris, np.float64)
    out = {}
    for eye, side, inward in ((0, "Right", 1.0), (1, "Left", -1.0)):
        u, v = i[eye]
        out[f"eyeLookIn{side}"] = min(max(inward * u / LOOK_SIDE, 0.0), 1.0)
        out[f"eyeLookOut{side}"] = min(max(-inward * u / LOOK_SIDE, 0.0), 1.0)
        out[f"eyeLookDown{side}"] = min(max(v / LOOK_DOWN, 0.0), 1.0)
        out[f"eyeLookUp{side}"] = min(max(-v / LOOK_UP, 0.0), 1.0)
    return out


def arkit_values(
    controls: np.ndarray,
    iris: np.ndarray,
    landmark_closure: np.ndarray | None = None,
    lid_closure: np.ndarray | None = None,
    held: np.ndarray | None = None,
) -> np.ndarray:
    """A frame's 52 ARKit values.

    Parameters
    ----------
    controls
        (E,) float array: the frame's expression weights in the order of
        :data:`facemime.animate.expressions.NAMES` (its blinks the eye tracker's closures).
    iris
        (2, 2) float array: the frame's iris shifts (:class:`~facemime.types.look.Look`'s).
    landmark_closure
        (2,) float array or None: the landmark pass's closures, as :func:`blinks` takes them.
    lid_closure
        (2,) float array or None: the eye model's closures, as :func:`blinks` takes them.
    held
        (2,) bool array or None: the eyes that blinked on the frame before (:func:`blinks`).

    Returns
    -------
    (52,) float64 array
        0..1 in the order of :data:`NAMES`; :data:`UNMEASURED` are 0.
    """
    w = np.asarray(controls, np.float64)
    if w.shape != (len(CONTROLS),):
        raise InvalidInputError(f"expression weights must have shape ({len(CONTROLS)},), got {w.shape}")
    named = dict(zip(CONTROLS, w.tolist()))
    for a, b in OPPOSITES:
        both = min(named[a], named[b])
        named[a], named[b] = named[a] - both, named[b] - both
    closure = np.array([named["eyeBlinkRight"], named["eyeBlinkLeft"]])
    named["eyeBlinkRight"], named["eyeBlinkLeft"] = blinks(closure, landmark_closure, lid_closure, held).tolist()
    named.update(looks(iris))
    return np.array([named.get(n, 0.0) for n in NAMES])


class ArkitSolver:
    """The 52 ARKit values of an analysis's frames, one at a time.

    Where the frame's landmarks measured the chin (:func:`jaw_opening`), ``jawOpen`` is the jaw's
    opening over the control's magnitude, and the lower lip's motion that the solve had put in
    ``jawOpen`` and ``mouthLowerDown*`` is solved again for the two ``mouthLowerDown*`` alone
    once the jaw's share is taken out: the lips' contours alone cannot tell a jaw that opens from
    a lower lip pulled down (their patterns are nearly one), the chin can. An eye that blinked on
    the frame before is held shut a little longer (:func:`blinks`' ``held``).

    Parameters
    ----------
    model
        The analysed actor's head model (its expression controls are solved from its knots).
    """

    def __init__(self, model: HeadModel):
        expressions = Expressions.of(model)
        self._solver = expressions.solver()
        self._jaw = CONTROLS.index("jawOpen")
        self._lower = [CONTROLS.index("mouthLowerDownLeft"), CONTROLS.index("mouthLowerDownRight")]
        self._patterns = expressions.patterns[[self._jaw, *self._lower]].reshape(3, -1)  # (3, 2K)
        lower = self._patterns[1:]
        self._lower_gram = lower @ lower.T
        #: The last frame's expression controls as the lips' solve has them (no jaw from the chin),
        #: in the order of :data:`facemime.animate.expressions.NAMES`: what a track file's
        #: ``weights`` hold.
        self.controls = np.zeros(len(CONTROLS))
        self._blinked = np.zeros(2, bool)  # the eyes that blinked on the last frame
        self._blinks = [NAMES.index("eyeBlinkRight"), NAMES.index("eyeBlinkLeft")]

    def step(
        self,
        offsets: np.ndarray,
        look: Look,
        landmark_closure: np.ndarray | None = None,
        landmark_jaw: float | None = None,
        lid_closure: np.ndarray | None = None,
    ) -> np.ndarray:
        """The next frame's values.

        Parameters
        ----------
        offsets
            (K, 2) float array: the frame's knot offsets, model units.
        look
            The frame's eyes.
        landmark_closure
            (2,) float array or None: the landmark pass's closures (:func:`blinks`).
        landmark_jaw
            The landmarks' :func:`jaw_opening`, mouth widths, or None where not measured: the jaw
            then as the lips' solve has it.
        lid_closure
            (2,) float array or None: the eye model's closures (:func:`blinks`).

        Returns
        -------
        (52,) float64 array
            0..1 in the order of :data:`NAMES`.
        """
        w = self._solver.step(offsets, look.closure)
        self.controls = w.copy()
        if landmark_jaw is not None and np.isfinite(landmark_jaw):
            jaw = min(max(landmark_jaw / MAGNITUDES["jawOpen"], 0.0), 1.0)
            mouth = w[[self._jaw, *self._lower]] @ self._patterns  # the lower lip's motion in the three
            rest = mouth - jaw * self._patterns[0]
            w[self._jaw] = jaw
            w[self._lower] = BoxLeastSquares(self._lower_gram, 0.0).step(self._patterns[1:] @ rest)
        values = arkit_values(w, look.iris, landmark_closure, lid_closure, self._blinked)
        self._blinked = values[self._blinks] >= 0.5
        return values
