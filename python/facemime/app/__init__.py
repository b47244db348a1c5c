"""The application layer: one module per command, each a plain function with typed arguments that
the command line (:mod:`facemime.cli`) and the Python API (:mod:`facemime`) both call. A command
reads its inputs, runs the layers below on them and writes its outputs all or none
(:mod:`facemime.io.outputs`)."""
