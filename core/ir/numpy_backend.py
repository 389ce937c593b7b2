"""Evaluate IR graphs with numpy, reproducing Blender's node semantics (Cycles SVM, float32).

Every operation computes its rule from the one table of semantics (``semantics.OPERATIONS``): Divide
returns 0 for a zero divisor, Square Root of a negative is 0, Arccosine clamps its input, Normalize of
a zero vector is zero, and so on (the list, with Cycles' source, is in ``semantics``).  Tables are read
through the table set the caller passes (``tables``: name -> ``tables.Table`` holding data), with the
texel-centre and EXTEND rules of ``semantics.texel_fetch`` / ``sample_bilinear``.
"""
from __future__ import annotations

import numpy as np

from .expr import Expr, topological_order
from .semantics import LEAVES, apply, sample_bilinear, texel_fetch
from .tables import resolve


def evaluate(outputs, inputs, dtype=np.float32, tables=None):
    """Evaluate Expr ``outputs`` (one or a tuple) for ``inputs`` (name -> array, broadcast).

    Computes in ``dtype`` (float32 like Cycles, or float64 for reference).  ``tables``: the table set
    (name -> ``tables.Table`` with data) for graphs that read tables.
    """
    single = isinstance(outputs, Expr)
    outs = (outputs,) if single else tuple(outputs)
    cache = {}
    for node in topological_order(outs):
        if node.op in ("const", "vconst"):
            cache[node.id] = np.asarray(node.attr("value"), dtype=dtype)
        elif node.op in ("input", "vinput"):
            name = node.attr("name")
            if name not in inputs:
                raise KeyError(f"no value for input {name!r}")
            cache[node.id] = np.asarray(inputs[name], dtype=dtype)
        elif node.op == "call":
            fn = node.graph.functions[node.attr("function")]
            args = {name: cache[a.id] for (name, _), a in zip(fn.inputs, node.args)}
            names = list(fn.outputs)
            values = evaluate(tuple(fn.outputs[n] for n in names), args, dtype, tables)
            cache[node.id] = dict(zip(names, values))
        elif node.op == "output":
            cache[node.id] = cache[node.args[0].id][node.attr("name")]
        elif node.op in ("texel", "lut"):
            u, v = (cache[a.id] for a in node.args)
            data = resolve(tables, node.attr("table")).require_data()
            read = texel_fetch if node.op == "texel" else sample_bilinear
            cache[node.id] = read(data, u, v)[..., node.attr("channel")].astype(dtype)
        else:
            cache[node.id] = apply(node.op, [cache[a.id] for a in node.args]).astype(dtype, copy=False)
    result = tuple(cache[o.id] for o in outs)
    return result[0] if single else result


def node_count(outputs):
    """Operations (excluding inputs and constants) a graph needs: what a node group would hold
    (a function call counts once, as its Group node; its outputs count nothing)."""
    outs = (outputs,) if isinstance(outputs, Expr) else tuple(outputs)
    return sum(1 for n in topological_order(outs) if n.op not in LEAVES + ("output",))


def flat_node_count(outputs):
    """Operations with every function call expanded (what one flat tree would hold)."""
    outs = (outputs,) if isinstance(outputs, Expr) else tuple(outputs)
    total = 0
    for n in topological_order(outs):
        if n.op == "call":
            fn = n.graph.functions[n.attr("function")]
            total += flat_node_count(tuple(fn.outputs.values()))
        elif n.op not in LEAVES + ("output",):
            total += 1
    return total
