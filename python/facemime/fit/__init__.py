"""Fitting the generic head to one person (docs/method.md §2): reference points found
automatically (or given, :mod:`facemime.types.points`), placement and elastic adjustment, texture
smearing, and the resulting actor."""

from facemime.fit.adjust import Fit, fit_model, frontal_pose
from facemime.fit.auto import AutoPoints, auto_points

__all__ = ["AutoPoints", "Fit", "auto_points", "fit_model", "frontal_pose"]
