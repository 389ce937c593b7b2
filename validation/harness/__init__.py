"""The library every check and benchmark builds on: scenes, measurement settings, renders, closures, metrics, image I/O,
the GL runner, outputs and the entry signature.  Imports no check, benchmark or tool."""
