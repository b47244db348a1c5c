"""Tracking mouth and eyebrow contours through a video with STB-snakes (docs/method.md §1).

The public entry point is :class:`facemime.track.Tracker`, fed one frame at a time.
"""

from facemime.track.knots import FrameResult
from facemime.track.params import TrackerParams
from facemime.track.tracker import Tracker

__all__ = ["FrameResult", "Tracker", "TrackerParams"]
