"""From analysis to synthesis: head pose per frame, the model driven by the tracked contours,
motion transfer between actors, and whole-video runs."""
