"""An expression IR for the shading math: written once, evaluated by several backends.

Shading functions in ``core`` are written with Python operators and ``core.shading_ops``.
Called with numpy arrays they compute directly; called with ``Expr`` inputs (``trace``) the
same code builds a graph whose operations are Blender shader nodes' (Math, Vector Math, Mix,
Image Texture), with Blender's semantics: the numpy backend (``numpy_backend``) evaluates a
graph as Cycles would, and a node-group backend emits it as Blender nodes (issue 4).

- ``expr``           the Expr type, the operation table, hash-consing, constant folding
- ``numpy_backend``  evaluation of a graph with Blender Math-node semantics (float32 by default)
"""
from .expr import Expr, Graph, is_expr, trace  # noqa: F401
