"""An expression IR for the shading math: written once, evaluated by several backends.

This package is the bottom layer of the project: it imports nothing of the project above it.

Shading functions in ``core`` are written with Python operators and ``core.shading_ops``.  Called
with numpy arrays they compute directly; called with ``Expr`` inputs (``trace``) the same code builds a
graph whose operations are Blender shader nodes' (Math, Vector Math, Mix, Image Texture), with
Blender's semantics.

- ``semantics``      the one table of operations and their rules (safe divide, clamped acos, ...)
- ``expr``           the Expr type, hash-consing, constant folding, traced functions
- ``functions``      ``NodeFunction``: a shading function that is also a (nested) node group
- ``interface``      socket descriptions (what an artist sees on a group)
- ``tables``         table references, table sets, bilinear filtering from texel fetches
- ``numpy_backend``  evaluation of a graph with Blender's semantics (float32 by default)
"""
from .expr import Expr, Graph, is_expr, trace

__all__ = ["Expr", "Graph", "is_expr", "trace"]
