"""Tables that shading code reads: references by name and size, data supplied by the caller.

A traced graph names the tables it reads (``texel`` and ``lut`` nodes carry the table's name and a
channel); it never holds their data.  Whoever evaluates or emits the graph passes a *table set*: a
mapping from name to ``Table`` (``core.lut.lookup.LutSet`` for the baked LUTs, a baked environment's
own table for the world), so the same traced function serves every LUT folder, and a backend reads
exactly the tables it is given.

``bilinear_function(table)`` is how traced code samples a table with bilinear filtering: four Closest
fetches and explicit weights, the rule of ``semantics.sample_bilinear`` written out in nodes; traced
under ``expr.table_filter("linear")`` (Cycles' trees) its body is one ``lut`` read, Image Texture with
Linear interpolation, which Cycles evaluates with the same rule.  EEVEE's
Linear filtering picks mipmaps from the screen-space derivatives of the coordinates, which for a table
indexed by per-pixel values blurred lookups by up to 40% of the table's range (measured); Closest
fetches are exact in both engines.
"""
from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .expr import FLOAT, graph_of, table_filter_mode, topological_order
from .functions import NodeFunction
from .interface import Socket
from .semantics import TABLE_READS


@dataclass(frozen=True, eq=False)
class Table:
    """A (height, width, 4) table read by name.  ``data`` is None for a reference used only to trace;
    ``source`` is a file holding the table (for backends that load it as an image)."""
    name: str
    height: int
    width: int
    data: np.ndarray | None = field(default=None, repr=False)
    source: Path | None = None

    @property
    def shape(self):
        return (self.height, self.width)

    def reference(self):
        """The same table without its data."""
        return Table(self.name, self.height, self.width, None, self.source)

    def require_data(self):
        if self.data is None:
            raise ValueError(f"table {self.name!r} is a reference without data: evaluate with a table set that "
                             "holds it (e.g. core.lut.lookup.LutSet.from_folder)")
        return self.data

    @classmethod
    def from_array(cls, name, data, source=None):
        data = np.asarray(data)
        if data.ndim != 3:
            raise ValueError(f"table {name!r} must be (H, W, C), got shape {data.shape}")
        return cls(name, int(data.shape[0]), int(data.shape[1]), data, source)


def resolve(tables, name):
    """``tables[name]`` with an error that names what is missing."""
    if tables is None:
        raise ValueError(f"the graph reads table {name!r}: pass tables= (a mapping name -> Table)")
    try:
        table = tables[name]
    except KeyError:
        raise KeyError(f"table {name!r} is not in the table set given ({sorted(tables)})") from None
    return table


def table_names(outputs):
    """Names of every table the expressions read, nested function calls included (sorted)."""
    names, seen = set(), set()
    stack = [list(outputs.values()) if isinstance(outputs, Mapping) else list(outputs)]
    while stack:
        for node in topological_order(stack.pop()):
            if node.op in TABLE_READS:
                names.add(node.attr("table"))
            elif node.op == "call":
                key = node.attr("function")
                if key not in seen:
                    seen.add(key)
                    stack.append(list(node.graph.functions[key].outputs.values()))
    return sorted(names)


# --- bilinear filtering from nearest fetches ---------------------------------------------------------

_BILINEAR = {}


def _clamp(g, x, lo, hi):
    return g.make("minimum", (g.make("maximum", (x, lo)), hi))


def _axis(g, t, n):
    """(t0, t1, f): texture coordinates of the two texel centres around t on an axis of n texels and
    the weight of the second, as ``semantics.sample_bilinear`` (EXTEND: clamped to the edge centres)."""
    x = _clamp(g, t * float(n) - 0.5, 0.0, n - 1.0)
    x0 = g.make("minimum", (g.make("floor", (x,)), max(n - 2.0, 0.0)))
    t0 = (x0 + 0.5) / float(n)
    t1 = (x0 + 1.5) / float(n) if n > 1 else t0
    return t0, t1, x - x0


def bilinear_function(table):
    """The node function "RTL LUT <table>": (u, v) -> the four channels, bilinear, EXTEND."""
    key = (table.name, table.shape)
    cached = _BILINEAR.get(key)
    if cached is not None:
        return cached
    h, w = table.shape
    ref = table.reference()

    def body(u, v):
        g = graph_of(u, v)
        if table_filter_mode() == "linear":     # one Image Texture, Linear: the filter in hardware
            return {name: g.read_table(ref, u, v, c, op="lut") for c, name in enumerate("RGBA")}
        u0, u1, fu = _axis(g, u, w)
        v0, v1, fv = _axis(g, v, h)
        # each tap is weighted and accumulated at once (one live tap at a time: Cycles' SVM stack
        # holds 255 floats for a whole material, and a tap read by four later mixes stays live)
        taps = ((u0, v0, (1.0 - fu) * (1.0 - fv)), (u1, v0, fu * (1.0 - fv)),
                (u0, v1, (1.0 - fu) * fv), (u1, v1, fu * fv))
        out = {}
        for c, name in enumerate("RGBA"):
            total = None
            for uu, vv, weight in taps:
                term = g.read_table(ref, uu, vv, c) * weight
                total = term if total is None else total + term
            out[name] = total
        return out

    coord = Socket(FLOAT, 0.5, description="Texture coordinate (texel centres at (i + 0.5)/N)")
    fn = NodeFunction(f"RTL LUT {table.name}", body, {"u": coord, "v": coord},
                      {c: Socket(FLOAT, 0.0, description=f"Channel {c}, bilinear") for c in "RGBA"},
                      f"Bilinear lookup of the {table.name} table (four exact texel fetches; EXTEND)")
    _BILINEAR[key] = fn
    return fn
