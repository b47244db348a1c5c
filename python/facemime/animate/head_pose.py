"""The head pose of a video, followed frame by frame beside the contour tracker.

Each frame's pose comes from the Face Mesh landmarks: one landmark pass, on the crop the last
frame's landmarks frame (no detection), aligned to the key frame's
(:class:`facemime.animate.landmark_pose.LandmarkPose`) and smoothed
(:class:`~facemime.animate.landmark_pose.PoseFilter`). Where the pass finds no face in its crop,
the pose is measured on the rigid points the tracker's optical flow follows
(:class:`facemime.animate.pose.PoseTracker`); where those are lost too, it moves by the head's
step in the image and is anchored again by a fit of the actor's model at most once in
:data:`ANCHOR_EVERY` frames. When the tracker restarts on a face found anew, the pose starts again
from the model fitted to that face's landmarks.
"""

from __future__ import annotations

import time
from dataclasses import replace

import numpy as np

from facemime.animate.landmark_pose import LandmarkPose, PoseFilter
from facemime.animate.pose import PoseTracker
from facemime.errors import InvalidInputError, NoFaceError
from facemime.fit.actor import find_points, fit_actor
from facemime.fit.adjust import fit_model
from facemime.head.generic import generic_head
from facemime.networks.finder import follow_face
from facemime.networks.mesh import reference_points
from facemime.track.motion import HeadMotion
from facemime.track.redetect import FaceTracker
from facemime.track.scale import ScaledMotion
from facemime.types.head import HeadModel
from facemime.types.pose import Pose

#: Frames at least between two fits of the actor that anchor a pose carried by the head's step.
#: On lp_d6 and lp_d12 (PSNR of the re-synthesised face, mean of the two): a fit on every such
#: frame 20.67 dB (10 frames/s for lp_d12's run on one core), at most one in 15 or 30 frames the
#: same (30: 47 frames/s), one in 90 20.30 dB; never, 17.5 dB (the carried pose drifts: lp_d12's
#: nose tip 0.16 IOD off in the median, 0.07 with these fits). Marking the face lost and
#: restarting the tracker from a fit on each such frame, as this analysis first did, gave 20.19 dB
#: at 12 frames/s, the contours 0.06 IOD off.
ANCHOR_EVERY = 30


class PoseFollower:
    """Follows the head pose of one face through a video, frame by frame after the tracker.

    Parameters
    ----------
    frame
        (H, W, 3) uint8 RGB: the key frame, on which ``pose`` was fitted.
    landmarks
        (468, 3) float array: the key frame's Face Mesh landmarks, (x, y) pixels and depth.
    model
        The head model whose pose is followed (the actor's).
    pose
        The model's pose on the key frame (the fitted actor's).
    tracker
        The contour tracker of the same video, started on the key frame: its optical flow's rigid
        points and its restarts are followed.
    fps
        The video's frame rate, frames/s (at least 1 is used): the pose filter's time step.
    """

    def __init__(
        self, frame: np.ndarray, landmarks: np.ndarray, model: HeadModel, pose: Pose, tracker: FaceTracker, fps: float
    ):
        # the reference measured as every later frame's is (one pass on the crop the landmarks
        # frame), not as the fit's (two passes averaged): the two differ by a constant offset
        key = follow_face(frame, landmarks)
        self.key_landmarks: np.ndarray = landmarks if key is None else key
        self._landmarks: np.ndarray | None = self.key_landmarks
        self.landmarks: np.ndarray | None = None  # the last update's landmarks: None where it measured none
        self._model = model
        self._landmark_pose = LandmarkPose(self._landmarks, pose, model.vertices, model.triangles)
        self._fps = max(float(fps), 1.0)
        self._smooth = PoseFilter(self._fps)
        self._smooth(pose)
        if tracker.motion is None:
            raise InvalidInputError("the head pose is followed on the tracker's head motion: its settings turn it off")
        self._tracker = tracker
        self._follower = tracker.tracker
        self.fit_seconds = 0.0  # seconds spent fitting the model again (restarts and anchors)
        self._follow(pose)

    @classmethod
    def on_face(cls, frame: np.ndarray, name: str, tracker: FaceTracker, fps: float) -> PoseFollower:
        """Follow the pose of the largest face of ``frame``, with the generic head fitted to it.

        Parameters
        ----------
        frame
            (H, W, 3) uint8 RGB: the key frame, the face roughly frontal.
        name
            Names the frame in the :class:`~facemime.errors.NoFaceError` raised where it shows
            no face.
        tracker
            The contour tracker of the same video, started on ``frame``.
        fps
            The video's frame rate, frames/s.

        Returns
        -------
        PoseFollower
            Following the generic head, its proportions adjusted to the face as ``fit`` adjusts
            them (so that the pose is the one ``run`` measures with the actor fitted there).
        """
        found, _ = find_points(frame, name)
        head = generic_head()
        fit = fit_model(head, found.points)
        return cls(frame, found.face.landmarks, replace(head, vertices=fit.vertices), fit.pose, tracker, fps)

    @property
    def pose(self) -> Pose:
        """The current frame's head pose."""
        return self._flow.pose

    @property
    def _motion(self) -> HeadMotion | ScaledMotion:
        """The tracker's head-motion follower (its current one: a restart makes a new one)."""
        motion = self._tracker.motion
        assert motion is not None  # checked in the constructor; a restart keeps the settings
        return motion

    def _follow(self, pose: Pose) -> None:
        """Follow the pose from ``pose`` on, on the rigid points of the current frame."""
        self._flow = PoseTracker(self._model.vertices, self._model.triangles, pose, self._motion)
        self._since_anchor = 0

    def update(self, frame: np.ndarray, face_before: bool, face: bool) -> Pose:
        """Measure the pose on the frame the tracker has just updated on.

        Parameters
        ----------
        frame
            (H, W, 3) uint8 RGB: the current frame.
        face_before
            Whether the previous frame had the face; without it the pose is not measured (it
            stays until the tracker restarts on a face found anew).
        face
            Whether the tracker has the face on this frame: a pose carried by the head's step is
            anchored by a fit only then.

        Returns
        -------
        Pose
            The frame's pose (also :attr:`pose`).
        """
        measured, self.landmarks = True, None
        if self._tracker.tracker is not self._follower:  # restarted on a face found anew: new rigid points
            t0 = time.perf_counter()
            self._follower = self._tracker.tracker
            self._landmarks = landmarks = self._tracker.landmarks
            assert landmarks is not None  # a restart is on a face the landmark model found
            self._follow(fit_model(self._model, reference_points(landmarks)).pose)
            self._smooth = PoseFilter(self._fps)  # the face came back: no smoothing across the gap
            self._smooth(self.pose)
            self.fit_seconds += time.perf_counter() - t0
        elif face_before:
            # The pose is measured on the landmarks, or, where the crop shows no face, on the rigid
            # points the flow follows, or moved by the head's step without them.
            found = None if self._landmarks is None else follow_face(frame, self._landmarks)
            if found is not None:
                self._landmarks = self.landmarks = found
                self._flow.follow(self._smooth(self._landmark_pose.measure(found)), self._motion)
            else:
                measured = self._flow.update(self._motion)
        self._since_anchor += 1
        if face and not measured and self._since_anchor >= ANCHOR_EVERY:
            t0 = time.perf_counter()
            try:
                self._follow(fit_actor(frame, "frame", model=self._model)[0].pose)
            except NoFaceError:  # the carried pose stays until the next attempt
                self._since_anchor = 0
            self.fit_seconds += time.perf_counter() - t0
        return self.pose
