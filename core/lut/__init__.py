"""Lookup tables: layout (``catalog``), EXR storage (``exr_io``), sampling (``lookup``); baked by ``core.lut_bake``.

Every table's layout is documented in docs/luts.md; ``catalog.TABLES`` is the code's copy.
"""
