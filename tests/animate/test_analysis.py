import numpy as np

from facemime.animate.analysis import Analysis
from facemime.io.video import VideoReader
from facemime.metrics import group_nme
from facemime.render.projection import project
from facemime.track.contours import GROUPS, from_face_mesh

NOSE_TIP = 4  # Face Mesh point


def test_the_face_is_kept_through_a_fast_hand_held_head_motion(shared):
    """lp_d12's head shakes too fast and blurred for the rigid points' flow in about one frame
    in eight (the head's step then comes from the coarse fallback, which drops the points): the
    face is kept and its contours tracked on, where re-fitting the actor and restarting the
    tracker each time left the contours 0.06 IOD off; the pose, carried by the step and
    anchored by a fit now and then, keeps the nose tip on the face."""
    z = np.load(shared / "video" / "lp_d12.landmarks.npz")
    with VideoReader(shared / "video" / "lp_d12.mp4") as reader:
        frames = list(reader)
    analysis = Analysis(frames[0], "lp_d12")
    nose = analysis.actor.model.vertices[[analysis.actor.model.groups["nose"][6]]]
    errors, nose_errors = [], []
    for i, frame in enumerate(frames[1:], 1):
        motion = analysis.update(frame)
        assert motion.face, i
        ref, iod = from_face_mesh(z["landmarks"][i]), float(z["iod"][i])
        errors.append([group_nme(motion.contours, ref, GROUPS[g], iod) for g in ("mouth_outer", "brows")])
        nose_errors.append(np.hypot(*(project(nose, motion.pose)[0][0] - z["landmarks"][i, NOSE_TIP, :2])) / iod)
    assert analysis.frames_without_face == 0
    # Measured: mouth outer 0.022, brows 0.023 (restarting from fits: 0.059, 0.040).
    assert np.mean(errors, axis=0).max() < 0.03
    # Measured: 0.107 IOD in the median, 0.42 at most, with the actor fitted on the face
    # landmarks' points (0.058 and 0.30 without their face outline, which fits lp_d6 and vr_1
    # better; 0.069 and 0.26 with the earlier cascade points; the step alone: 0.16, 0.37).
    assert np.median(nose_errors) < 0.12 and max(nose_errors) < 0.45
