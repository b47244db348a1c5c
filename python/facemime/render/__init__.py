"""Synthesis (docs/method.md §3): orthographic projection, back-face culling, far-to-near order and
per-triangle affine texture mapping, the last three in the Rust core."""

from facemime.render.raster import RenderStats, coverage, fill, render_mesh, render_mesh_into
from facemime.types.pose import Pose, project, rotation_matrix

__all__ = ["Pose", "RenderStats", "coverage", "fill", "project", "render_mesh", "render_mesh_into", "rotation_matrix"]
