"""From analysis to synthesis: the analysis of each frame (contours, head pose, eyes), the model
driven by the tracked contours, expressions, motion transfer between actors and replays of track
files; the commands that run them are in :mod:`facemime.app`."""
