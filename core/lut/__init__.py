"""Lookup tables: layout (``catalog``), EXR storage (``exr_io``), baking (``bake``), sampling (``lookup``).

Every table's layout is documented in docs/luts.md; ``catalog.TABLES`` is the code's copy.
"""
