"""Tracking mouth and eyebrow contours through a video with STB-snakes (docs/method.md §1).

The public entry point is :class:`facemime.track.Tracker`, fed one frame at a time.
"""

from facemime.track.tracker import FrameResult, Tracker, TrackerParams
from facemime.types.contours import CONTOUR_NAMES, FEATURES

__all__ = ["CONTOUR_NAMES", "FEATURES", "FrameResult", "Tracker", "TrackerParams"]
