"""The validation and measurement package of RT Lookdev: everything the main job, the benchmarks and the
tests reuse to render, compare and report (not shipped in the extension zip).

It sits above the add-on (it drives the bpy layer to build scenes) and below ``scripts/`` (thin
command-line entry points) and ``tests/``.  Import it as ``rt_lookdev.validation``: ``scripts/env.sh``
installs the checkout in editable mode (pyproject.toml), so no ``sys.path`` edits are needed.

Four layers, each importing only those before it (tests/core/test_layers.py; docs/architecture.md, "The
validation package"):

- ``harness``     the library: scenes and sphere meshes, measurement settings, renders and pass reading, the
                  ground truth's closures, metrics, image I/O, the GL runner, outputs, the entry signature
- ``checks``      gated comparisons with a truth: the suite, the world suite, energy, the rough-diffuse
                  furnace, the lookdev twin, robustness, the demo
- ``benchmarks``  the writers of docs/benchmarks/
- ``main_job``    the main job (``scripts/main.sh``): every step and the report

and beside them ``tools`` (the extension zip, the release matrix), which none of them imports.
"""
