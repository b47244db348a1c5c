"""Model-based coding: a face's motion as a bitstream of a couple of kilobits a second
(``docs/bitstream.md``). :mod:`params` maps pose and offsets to the coded parameters,
:mod:`stream` encodes and decodes frame by frame, :mod:`clip` analyses a video into a clip and
encodes it, :mod:`appearance` sends the face's look again; the commands are
:mod:`facemime.app.coding`."""
