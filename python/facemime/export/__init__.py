"""Export of a tracked performance to the tools people animate with: binary glTF 2.0 with morph
targets (:mod:`facemime.export.performance`)."""

from facemime.export.performance import ExportResult, Performance, export_track, glb_bytes, load_performance

__all__ = ["ExportResult", "Performance", "export_track", "glb_bytes", "load_performance"]
