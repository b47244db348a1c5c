"""Export of a tracked performance to the tools people animate with: binary glTF 2.0 with morph
targets (:mod:`facemime.export.performance`); the command is :mod:`facemime.app.export`."""

from facemime.export.performance import Performance, glb_bytes, load_performance

__all__ = ["Performance", "glb_bytes", "load_performance"]
