"""Fitting the generic head to one person (docs/method.md §2): reference points (from a file or found
automatically), placement and elastic adjustment, texture smearing, and the resulting actor."""

from facemime.fit.adjust import Fit, fit_model, frontal_pose
from facemime.fit.auto import AutoPoints, auto_points
from facemime.types.points import GROUPS, NAMES, REQUIRED, ReferencePoints, check_points, model_chain

__all__ = [
    "GROUPS",
    "NAMES",
    "REQUIRED",
    "AutoPoints",
    "Fit",
    "ReferencePoints",
    "auto_points",
    "check_points",
    "fit_model",
    "frontal_pose",
    "model_chain",
]
