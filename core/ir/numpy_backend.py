"""Evaluate IR graphs with numpy, reproducing Blender's node semantics (Cycles SVM).

The semantics follow Cycles' ``kernel/svm/math_util.h`` (float32): Divide returns 0 for a zero
divisor; Power returns 0 for a negative base with a fractional exponent; Square Root of a
negative is 0; Inverse Square Root of a non-positive is 0; Logarithm of a non-positive is 0;
Arccosine / Arcsine clamp their input to [-1, 1]; Vector Math Normalize of a zero vector is
zero; Power of a zero base with a negative exponent is 0 (measured with Cycles 5.0.1: numpy
gives +-inf there; tests/blender/test_node_conformance.py).  Shading code guards its inputs so that EEVEE (which differs on inverse sqrt and
arccos/arcsin outside the domain) computes the same values; see core/shading_ops.py.
"""
from __future__ import annotations

import numpy as np

from .expr import Expr


def _safe_div(a, b):
    out = np.zeros(np.broadcast_shapes(a.shape, b.shape), dtype=np.result_type(a, b))
    np.divide(a, b, out=out, where=np.broadcast_to(b != 0, out.shape))
    return out


def _safe_pow(a, b):
    a, b = np.broadcast_arrays(a, b)
    bad = ((a < 0) & (b != np.floor(b))) | ((a == 0) & (b < 0))
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        out = np.power(np.where(bad, 1.0, a).astype(a.dtype), b)
    return np.where(bad, 0.0, out).astype(a.dtype)


def _positive(f, a):
    out = np.zeros(a.shape, dtype=a.dtype)
    np.copyto(out, f(np.where(a > 0, a, 1).astype(a.dtype)), where=a > 0)
    return out


def _dot(a, b):
    return np.sum(a * b, axis=-1)


def _normalize(v):
    n = np.sqrt(_dot(v, v))[..., None]
    return _safe_div(v, np.broadcast_to(n, v.shape))


_SCALAR = {
    "add": lambda a, b: a + b,
    "subtract": lambda a, b: a - b,
    "multiply": lambda a, b: a * b,
    "divide": _safe_div,
    "power": _safe_pow,
    "sqrt": lambda a: np.sqrt(np.maximum(a, 0)),
    "inverse_sqrt": lambda a: _positive(lambda x: 1 / np.sqrt(x), a),
    "exponent": lambda a: np.exp(a),
    "log2": lambda a: _positive(np.log2, a),
    "minimum": np.minimum,
    "maximum": np.maximum,
    "less_than": lambda a, b: (a < b).astype(a.dtype),
    "greater_than": lambda a, b: (a > b).astype(a.dtype),
    "absolute": np.abs,
    "floor": np.floor,
    "arccosine": lambda a: np.arccos(np.clip(a, -1, 1)),
    "arcsine": lambda a: np.arcsin(np.clip(a, -1, 1)),
    "sine": np.sin,
    "cosine": np.cos,
    "tangent": np.tan,
    "arctan2": np.arctan2,
    "select": lambda c, a, b: np.where(c != 0, a, b),
    "vselect": lambda c, a, b: np.where((c != 0)[..., None], a, b),
    "combine": lambda x, y, z: np.stack(np.broadcast_arrays(x, y, z), axis=-1),
    "x": lambda v: v[..., 0],
    "y": lambda v: v[..., 1],
    "z": lambda v: v[..., 2],
    "vadd": lambda a, b: a + b,
    "vsubtract": lambda a, b: a - b,
    "vscale": lambda v, s: v * s[..., None],
    "vmultiply": lambda a, b: a * b,
    "dot": _dot,
    "cross": lambda a, b: np.cross(*np.broadcast_arrays(a, b)),
    "length": lambda v: np.sqrt(_dot(v, v)),
    "normalize": _normalize,
}


def apply_op(op, values, attrs):
    """One operation on numpy arrays (all of one float dtype)."""
    with np.errstate(over="ignore", under="ignore", invalid="ignore", divide="ignore"):
        return np.asarray(_SCALAR[op](*values))


def evaluate(outputs, inputs, dtype=np.float32):
    """Evaluate Expr ``outputs`` (one or a tuple) for ``inputs`` (name -> array, broadcast).

    Computes in ``dtype`` (float32 like Cycles, or float64 for reference).
    """
    single = isinstance(outputs, Expr)
    outs = (outputs,) if single else tuple(outputs)
    cache = {}
    for node in topological_order(outs):
        if node.op in ("const", "vconst"):
            cache[node.id] = np.asarray(node.attr("value"), dtype=dtype)
        elif node.op in ("input", "vinput"):
            cache[node.id] = np.asarray(inputs[node.attr("name")], dtype=dtype)
        elif node.op == "call":
            fn = node.graph.functions[node.attr("function")]
            args = {name: cache[a.id] for (name, _), a in zip(fn.inputs, node.args)}
            names = list(fn.outputs)
            values = evaluate(tuple(fn.outputs[n] for n in names), args, dtype)
            cache[node.id] = dict(zip(names, values))
        elif node.op == "output":
            cache[node.id] = cache[node.args[0].id][node.attr("name")]
        elif node.op == "texel":
            u, v = (cache[a.id] for a in node.args)
            table = np.asarray(node.graph.luts[node.attr("table")])
            h, w = table.shape[:2]
            i = np.clip(np.floor(np.asarray(u, np.float64) * w), 0, w - 1).astype(np.int64)
            j = np.clip(np.floor(np.asarray(v, np.float64) * h), 0, h - 1).astype(np.int64)
            cache[node.id] = table[j, i][..., node.attr("channel")].astype(dtype)
        elif node.op == "lut":
            from ..lut.lookup import sample_bilinear

            u, v = (cache[a.id] for a in node.args)
            table = node.graph.luts[node.attr("table")]
            cache[node.id] = sample_bilinear(table, u, v)[..., node.attr("channel")].astype(dtype)
        else:
            cache[node.id] = apply_op(node.op, [cache[a.id] for a in node.args], node.attrs).astype(dtype, copy=False)
    result = tuple(cache[o.id] for o in outs)
    return result[0] if single else result


def topological_order(outputs):
    """Nodes reachable from ``outputs``, each after its arguments (iterative DFS)."""
    order, seen = [], set()
    stack = [(o, False) for o in reversed(outputs)]
    while stack:
        node, expanded = stack.pop()
        if node.id in seen:
            continue
        if expanded:
            seen.add(node.id)
            order.append(node)
            continue
        stack.append((node, True))
        stack.extend((a, False) for a in reversed(node.args) if a.id not in seen)
    return order


def node_count(outputs):
    """Operations (excluding inputs and constants) a graph needs: what a node group would hold
    (a function call counts once, as its Group node; its outputs count nothing)."""
    outs = (outputs,) if isinstance(outputs, Expr) else tuple(outputs)
    return sum(1 for n in topological_order(outs) if n.op not in ("const", "vconst", "input", "vinput", "output"))


def flat_node_count(outputs):
    """Operations with every function call expanded (what one flat tree would hold)."""
    outs = (outputs,) if isinstance(outputs, Expr) else tuple(outputs)
    total = 0
    for n in topological_order(outs):
        if n.op == "call":
            fn = n.graph.functions[n.attr("function")]
            total += flat_node_count(tuple(fn.outputs.values()))
        elif n.op not in ("const", "vconst", "input", "vinput", "output"):
            total += 1
    return total
