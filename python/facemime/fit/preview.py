"""The fit preview: the adjusted wireframe over the photo next to the textured actor rendered
frontally and turned ±30° (yaw), one PNG-ready (H, W, 3) uint8 RGB image."""

from __future__ import annotations

import cv2
import numpy as np

from facemime.render.head_view import draw_wireframe, render_head
from facemime.types.actor import Actor
from facemime.types.pose import Pose, project

YAWS = (-30.0, 0.0, 30.0)


def preview_sheet(actor: Actor, photo: np.ndarray, cell: int = 360) -> np.ndarray:
    """The preview of an actor fitted on a photo.

    Parameters
    ----------
    actor
        The fitted actor; its pose maps its model onto ``photo``.
    photo
        (H, W, 3) uint8 RGB: the photo the actor was fitted on.
    cell
        Side of each square panel, pixels.

    Returns
    -------
    (cell, 4 * cell, 3) uint8 array
        RGB, four panels left to right: the photo around the face with the adjusted wireframe,
        then the textured actor at yaw -30, 0 and +30 degrees (:data:`YAWS`).
    """
    m = actor.model
    points = project(m.vertices, actor.pose)[0]
    lo, hi = points.min(axis=0), points.max(axis=0)
    half = 0.62 * (hi - lo).max()
    cx, cy = (lo + hi) / 2
    # The face's square neighbourhood of the photo, scaled to the cell, wireframe on top.
    zoom = cell / (2 * half)
    affine = np.array([[zoom, 0, cell / 2 - zoom * cx], [0, zoom, cell / 2 - zoom * cy]])
    panel = cv2.warpAffine(
        photo, affine, (cell, cell), flags=cv2.INTER_AREA, borderMode=cv2.BORDER_CONSTANT, borderValue=(36, 36, 40)
    )
    draw_wireframe(panel, points * zoom + affine[:, 2], m.triangles, (40, 230, 90))
    panels = [panel]
    for yaw in YAWS:
        pose = Pose.framing(m.vertices, (cell, cell), 0.86, yaw=yaw)
        panels.append(render_head(m, actor.texture, pose, (cell, cell), background=(36, 36, 40)))
    return np.hstack(panels)
