"""The types every layer shares, at the bottom of the package: the pose, the head model, the
actor, the eyes' look, the contours and reference points, and 2-D similarities. They import
nothing of facemime but its errors, constants and validators (``facemime._core`` for the
similarity fit)."""

from facemime.types.actor import Actor
from facemime.types.contours import CONTOUR_NAMES, FEATURES
from facemime.types.head import HeadModel, model_iod
from facemime.types.look import Look
from facemime.types.points import ReferencePoints
from facemime.types.pose import Pose, project, rotation_matrix

__all__ = [
    "CONTOUR_NAMES",
    "FEATURES",
    "Actor",
    "HeadModel",
    "Look",
    "Pose",
    "ReferencePoints",
    "model_iod",
    "project",
    "rotation_matrix",
]
