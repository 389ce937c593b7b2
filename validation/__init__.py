"""The validation and measurement package of RT Lookdev: everything the main job, the benchmarks and the
tests reuse to render, compare and report (not shipped in the extension zip).

It sits above the add-on (it drives the bpy layer to build scenes) and below ``scripts/`` (thin
command-line entry points) and ``tests/``.  Import it as ``rt_lookdev.validation``: ``scripts/env.sh``
installs the checkout in editable mode (pyproject.toml), so no ``sys.path`` edits are needed.

- ``render_setup``     the Cycles and EEVEE measurement settings (no bounces, no filter, exact pixels)
- ``engines``          render with Cycles / EEVEE to EXR passes and compare per pixel
- ``conformance``      node groups vs the numpy backend on input grids (tests/blender)
- ``suite_cases``      the validation suite's cases, scenes, numpy evaluation, ground truth and metrics
- ``suite``            the validation suite: runs every case, gates, writes the report
- ``world_cases``      the world validation's scenes, closures and brute-force references
- ``world_suite``      the world validation: runs every studio HDRI, gates, writes the report
- ``energy_render``    the Cycles white-furnace render check of the GGX energy tables
- ``demo_measure``     the demo scene measured: node counts, Cycles time, EEVEE vs Cycles
- ``main_job``         the main job (``scripts/main.sh``): every step and the report
- ``*_benchmark``      the benchmarks writing docs/benchmarks/
- ``report``, ``png``  EXR / PNG / CSV / HTML output
- ``published_ltc``    the published GGX LTC table of selfshadow/ltc_code (comparison only, not shipped)
- ``extension_zip``    validate the manifest and build the extension zip with Blender's tool
"""
