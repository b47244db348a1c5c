"""The tracker's settings (:class:`TrackerParams`) and the energy weights of its curves.

Distances are pixels of the tracked frame, (x, y) with the origin at the centre of the top-left
pixel, y down.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

OPERATORS = ("directional", "magnitude")
#: The mouth gets another solver pass only when a knot moved this fraction of a pass's reach.
FAST = 0.6
#: Fraction of the inner mouth's sideways drift from the centre of the outer mouth removed per frame.
CENTRING = 0.3
#: The inner mouth's width may shrink to this fraction of its rest width before it counts as lost.
NARROWEST = 0.25
#: A match (a brow found again, the mouth's region followed) that puts a knot coordinate this
#: many solver reaches (δ0/(1−σ)) from where the knots were moves them; a nearer one tells the
#: snakes nothing new.
AGREE = 1.0


@dataclass(frozen=True)
class CurveWeights:
    """Energy weights of a curve (docs/method.md §1): tension α, rigidity β (both against the rest
    shape), temporal smoothness τ, image contrast ρ, temporal brightness γ, and the weights of
    the luma and colour (red − green) derivatives in H (their signs come from the edge's
    polarity, :data:`facemime.types.contours.POLARITY`)."""

    alpha: float
    beta: float
    tau: float
    rho: float = 1.0
    gamma: float = 0.0
    luma: float = 1.0
    chroma: float = 0.0


@dataclass(frozen=True)
class TrackerParams:
    """Tracker settings: the defaults were tuned on the shared videos (``benchmarks/accuracy.py``);
    why each has its value, with the measurements, is in ``docs/tracker.md`` (the settings).

    Distances are pixels of the tracked frame; "a reach" is what one solver pass moves a knot
    coordinate at most, δ0/(1−σ) (:attr:`reach`).

    Attributes
    ----------
    mouth, mouth_inner, brows : CurveWeights
        Energy weights of the outer mouth's, the inner mouth's and the brows' curves.
    operator : {"directional", "magnitude"}
        The image derivative of the edge term H.
    points_per_segment : int
        Samples of the image field between two knots.
    delta0, sigma : float
        The sign-descent solver's first step (px) and its decay per step.
    iterations : int
        Solver steps per pass at most.
    tol : float
        A feature stops early once its energy changes by less than this between steps (0: never).
    smoothing : float
        Gaussian sigma (px) of the image before its derivatives.
    lip_keep : float
        Each lip keeps at least this fraction of its first-frame thickness.
    gap_weight, brow_weight : float
        Weights of those minimum gaps and of each brow's upper-to-lower thickness.
    mouth_knots, brow_knots : int or None
        Knots per curve (None: the start's own points).
    motion, knot_flow : bool
        Compensate the head's motion; start each knot where the optical flow carries it.
    lost_response : float
        A feature is lost when its edge response falls below this fraction of the first frame's.
    calibration_passes : int
        Solver runs on the first frame that measure how far the edges lie from the given contours.
    mouth_affine : float
        How far each mouth feature's rest shape follows the affine change of its knots (0..1).
    mouth_passes : int
        Solver passes per frame for the mouth at most (another only after a knot moved
        :data:`FAST` of a reach).
    lip_reach, lip_step : float
        Lip-edge search along a lost knot's normal: ± this fraction of the mouth's width; the
        smallest edge, in skin standard deviations per px (:mod:`facemime.track.lips`; 0: off).
    brow_search : float
        A brow whose response falls below this fraction is matched again (:mod:`facemime.track.brows`; 0: off).
    inner_search : int
        A lost inner mouth is tried 1 to this many reaches up and down the face (0: off).
    mouth_patch : float
        Below this fraction of mouth knots followed by the flow, the mouth's region is matched
        (:mod:`facemime.track.mouth`; 0: off).
    mouth_relocate : int
        A mouth lost this many frames in a row is looked for by its lip colour (0: off).
    face_width : float or None
        A face wider than this (brows' outer width, px) is tracked on shrunk frames
        (:mod:`facemime.track.scale`; None: never).
    """

    mouth: CurveWeights = CurveWeights(alpha=30.0, beta=24.0, tau=2.0, rho=1.0, gamma=0.0, chroma=0.5)
    mouth_inner: CurveWeights = CurveWeights(alpha=8.0, beta=12.0, tau=2.0, rho=1.0, gamma=0.0, luma=0.5, chroma=1.0)
    brows: CurveWeights = CurveWeights(alpha=30.0, beta=24.0, tau=2.0, rho=1.0, gamma=0.0, chroma=0.0)
    operator: str = "directional"
    points_per_segment: int = 3
    delta0: float = 1.5
    sigma: float = 0.75
    iterations: int = 15
    tol: float = 0.0
    smoothing: float = 1.5
    lip_keep: float = 0.5
    gap_weight: float = 0.5
    brow_weight: float = 0.05
    mouth_knots: int | None = None
    brow_knots: int | None = None
    motion: bool = True
    knot_flow: bool = True
    lost_response: float = 0.1
    calibration_passes: int = 3
    mouth_affine: float = 0.7
    mouth_passes: int = 2
    lip_reach: float = 0.3
    lip_step: float = 0.3
    brow_search: float = 0.3
    inner_search: int = 3
    mouth_patch: float = 0.5
    mouth_relocate: int = 1
    face_width: float | None = 240.0

    @property
    def reach(self) -> float:
        """The farthest a solver pass moves a knot coordinate, δ0/(1−σ) px."""
        return self.delta0 / (1.0 - self.sigma)

    def with_(self, **changes: Any) -> TrackerParams:
        """A copy with some settings changed.

        Parameters
        ----------
        **changes
            Field name -> new value, for any of the fields above (an unknown name raises
            ``TypeError``).

        Returns
        -------
        TrackerParams
            A new instance; this one is unchanged.
        """
        return replace(self, **changes)
