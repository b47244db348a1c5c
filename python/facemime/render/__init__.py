"""Synthesis (docs/method.md §3): back-face culling, far-to-near order and per-triangle affine
texture mapping, in the Rust core, of vertices projected by :func:`facemime.types.pose.project`;
the scene around the face and views of a head."""

from facemime.render.raster import RenderStats, coverage, fill, render_mesh, render_mesh_into

__all__ = ["RenderStats", "coverage", "fill", "render_mesh", "render_mesh_into"]
