"""The eight tracked contours and the four features they form.

Contours are open curves ordered image-left to image-right (../data/README.md of the shared
data; the project's interchange format). "left"/"right" are the subject's own sides.
The upper and lower curves of each mouth contour share their two corner points.
"""

from __future__ import annotations

#: Contour name -> feature it belongs to, in the order of the interchange format.
CONTOUR_NAMES = (
    "mouth_outer_upper",
    "mouth_outer_lower",
    "mouth_inner_upper",
    "mouth_inner_lower",
    "brow_left_upper",
    "brow_left_lower",
    "brow_right_upper",
    "brow_right_lower",
)

#: Feature name -> its (upper, lower) contours.
FEATURES = {
    "mouth_outer": ("mouth_outer_upper", "mouth_outer_lower"),
    "mouth_inner": ("mouth_inner_upper", "mouth_inner_lower"),
    "brow_left": ("brow_left_upper", "brow_left_lower"),
    "brow_right": ("brow_right_upper", "brow_right_lower"),
}

#: Reporting groups of the NME metric -> their contours.
GROUPS = {
    "mouth_outer": FEATURES["mouth_outer"],
    "mouth_inner": FEATURES["mouth_inner"],
    "brows": FEATURES["brow_left"] + FEATURES["brow_right"],
}

#: Edge polarity of each contour: the sign of the luma change going *down* across it
#: (-1: brighter above, darker below) and of the red-minus-green change.
POLARITY = {
    "mouth_outer_upper": (-1.0, +1.0),  # skin above, darker and redder lip below
    "mouth_outer_lower": (+1.0, -1.0),  # redder lip above, brighter skin below
    "mouth_inner_upper": (-1.0, -1.0),  # lip above, dark mouth opening / lip line below
    "mouth_inner_lower": (+1.0, +1.0),  # dark opening above, lip below
    "brow_left_upper": (-1.0, 0.0),  # skin above, dark brow below
    "brow_left_lower": (+1.0, 0.0),
    "brow_right_upper": (-1.0, 0.0),
    "brow_right_lower": (+1.0, 0.0),
}
