from dataclasses import replace

import numpy as np

from facemime.animate.analysis import Analysis
from facemime.animate.synth import key_frame, scene_mesh, synthesize
from facemime.app.demo import SIZE, astronaut_photo
from facemime.fit.actor import fit_actor
from facemime.io.video import VideoReader
from facemime.metrics import group_nme
from facemime.types.contours import GROUPS, from_face_mesh
from facemime.types.pose import project

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


def _rendered_turn(yaws, pitches):
    """The astronaut (the demo's actor) rendered in her scene at her fitted pose turned by
    ``yaws`` and ``pitches`` (degrees, one pair a frame), 512 x 512."""
    actor = fit_actor(astronaut_photo(), "astronaut.jpg")[0]
    scene = scene_mesh(actor)
    key = key_frame(actor, scene)
    rest = actor.pose
    return [
        synthesize(
            actor,
            actor.model.vertices,
            replace(rest, yaw=rest.yaw + y, pitch=rest.pitch + p),
            SIZE,
            scene=scene,
            key=key,
        )
        for y, p in zip(yaws, pitches)
    ]


def test_a_rendered_head_turned_and_held_is_measured_turned_and_stays_turned():
    """The pose owes nothing to a reference here: the actor is rendered at known turns (a yaw to
    20 degrees held, then a nod to 12 degrees held) and the analysis's pose, relative to its first
    frame, must follow them, with no pull back towards frontal while held."""
    yaws = [0.0] * 3 + [4.0 * k for k in range(1, 6)] + [20.0] * 12 + [20.0] * 12
    pitches = [0.0] * 20 + [3.0 * k for k in range(1, 5)] + [12.0] * 8
    frames = _rendered_turn(yaws, pitches)
    analysis = Analysis(frames[0], "rendered", fps=25)
    first = analysis.last.pose
    measured = np.array(
        [[m.pose.yaw - first.yaw, m.pose.pitch - first.pitch] for m in map(analysis.update, frames[1:])]
    )
    held_yaw = measured[9:19, 0]  # frames 10-19: yaw 20, pitch 0
    held_nod = measured[-6:]  # yaw 20, pitch 12
    # measured: the yaw held at 17.3-17.5 and the nod at 10.7-10.9, the yaw reading 13.9-14.1 during
    # it (the rendered head's shape is the generic mesh's, the landmarks' depth a real face's); the
    # flow-based pose read the held yaw as -3.7 degrees (turned the wrong way) and the nod as -0.6
    assert np.abs(held_yaw - 17.4).max() < 1.5 and np.ptp(held_yaw) < 0.5
    assert np.abs(held_nod[:, 1] - 10.8).max() < 1.5 and np.ptp(held_nod[:, 0]) < 0.5
    assert held_nod[:, 0].min() > 12.0
