"""Packaging and release helpers beside the validation layers (the extension zip, the table of the release matrix);
nothing in harness, checks, benchmarks or the main job imports them."""
