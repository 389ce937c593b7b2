"""Expressions: a DAG of Blender-node operations with sharing, folding and type checks.

Every ``Expr`` belongs to a ``Graph``, which interns nodes by (operation, arguments,
attributes): building the same subexpression twice returns the same node, so common
subexpressions are shared for free.  An operation whose arguments are all constants is
evaluated at once (constant folding, with the backend's own semantics), and a ``select``
with a constant condition keeps only the live branch (dead-branch removal), so a material
with sheen 0 carries no sheen nodes.

Kinds: "float" (Math node socket), "vector" (Vector Math socket).  Comparisons give floats
0/1, as Blender's Compare/Greater Than do.  Python control flow on an Expr is refused
(``__bool__`` raises): write ``select`` instead.
"""
from __future__ import annotations

import hashlib
import itertools

import numpy as np

from .semantics import CALL, FLOAT, LEAVES, OPERATIONS, TABLE_READS, VECTOR, apply

#: operation -> (argument kinds, result kind), from the one table of semantics (``semantics``).
OPS = {name: (operation.args, operation.result) for name, operation in OPERATIONS.items()}

_FOLDING = {"enabled": True}


class folding:
    """``with folding(False):`` traces without constant folding, identities or dead-branch
    removal (hash-consing stays): for measuring what folding saves.  Node functions keep one traced
    body per setting (``functions.NodeFunction.function``)."""

    def __init__(self, enabled):
        self.enabled, self.previous = bool(enabled), None

    def __enter__(self):
        self.previous = _FOLDING["enabled"]
        _FOLDING["enabled"] = self.enabled
        return self

    def __exit__(self, *exc):
        _FOLDING["enabled"] = self.previous
        return False


def folding_enabled():
    return _FOLDING["enabled"]


#: How traced code samples a table bilinearly (``shading_ops.lut_sample``): "fetch4" writes the filter
#: out as four Closest fetches and their weights (exact in every engine; EEVEE's Linear filtering would
#: pick mipmaps from screen-space derivatives), "linear" emits one ``lut`` read (an Image Texture node
#: with Linear interpolation: Cycles' exact bilinear filter, docs/blender.md).
TABLE_FILTERS = ("fetch4", "linear")
_TABLE_FILTER = {"mode": "fetch4"}


class table_filter:
    """``with table_filter("linear"):`` traces table lookups as single Linear reads (for Cycles' trees).
    Node functions keep one traced body per setting, as for ``folding``."""

    def __init__(self, mode):
        if mode not in TABLE_FILTERS:
            raise ValueError(f"table filter {mode!r}: expected one of {TABLE_FILTERS}")
        self.mode, self.previous = mode, None

    def __enter__(self):
        self.previous = _TABLE_FILTER["mode"]
        _TABLE_FILTER["mode"] = self.mode
        return self

    def __exit__(self, *exc):
        _TABLE_FILTER["mode"] = self.previous
        return False


def table_filter_mode():
    return _TABLE_FILTER["mode"]


class Graph:
    """Interns expressions; one graph per traced function."""

    def __init__(self):
        self.nodes = {}
        self.tables = {}        # table name -> tables.Table (a reference: the data is the caller's)
        self.functions = {}     # Function.key -> Function called from this graph
        self._ids = itertools.count()

    def call(self, function, args):
        """Outputs (dict name -> Expr) of ``function`` applied to ``args`` (dict input name -> value).

        A call is one node of this graph (a Group node in Blender); the function's own graph is
        shared by every call, in any graph.  Outputs that the function folded to constants are
        returned as constants here."""
        missing = [n for n, _ in function.inputs if n not in args]
        extra = set(args) - {n for n, _ in function.inputs}
        if missing or extra:
            raise ValueError(f"call of {function.name}: missing {missing}, unknown {sorted(extra)}")
        lifted = tuple(self.lift(args[n]) for n, _ in function.inputs)
        for (n, kind), a in zip(function.inputs, lifted):
            if a.kind != kind:
                raise TypeError(f"call of {function.name}: input {n!r} is {kind}, got {a.kind}")
        self.functions[function.key] = function
        key = ("call", tuple(a.id for a in lifted), (("function", function.key),))
        node = self.nodes.get(key)
        if node is None:
            node = Expr(self, next(self._ids), "call", lifted, key[2], CALL)
            self.nodes[key] = node
        results = {}
        for name, out in function.outputs.items():
            if out.is_const:
                results[name] = self.const(out.attr("value")) if out.kind == FLOAT else self.vconst(out.attr("value"))
                continue
            okey = ("output", (node.id,), (("name", name),))
            onode = self.nodes.get(okey)
            if onode is None:
                onode = Expr(self, next(self._ids), "output", (node,), okey[2], out.kind)
                self.nodes[okey] = onode
            results[name] = onode
        return results

    def make(self, op, args=(), attrs=()):
        if op not in OPS:
            raise ValueError(f"unknown IR operation {op!r}")
        kinds, result = OPS[op]
        args = tuple(self.lift(a) for a in args)
        if len(args) != len(kinds) or any(a.kind != k for a, k in zip(args, kinds)):
            raise TypeError(f"{op}: expected {kinds}, got {tuple(a.kind for a in args)}")
        folded = _simplify(self, op, args) if _FOLDING["enabled"] else None
        if folded is not None:
            return folded
        key = (op, tuple(a.id for a in args), attrs)
        node = self.nodes.get(key)
        if node is None:
            node = Expr(self, next(self._ids), op, args, attrs, result)
            self.nodes[key] = node
        return node

    def read_table(self, table, u, v, channel, op="texel"):
        """Channel ``channel`` of ``table`` (a ``tables.Table``) at (u, v): a ``texel`` (Closest) or
        ``lut`` (Linear) node naming the table; the graph keeps only its reference."""
        if op not in TABLE_READS:
            raise ValueError(f"{op!r} does not read a table")
        known = self.tables.get(table.name)
        if known is not None and known.shape != table.shape:
            raise ValueError(f"table {table.name!r} read with sizes {known.shape} and {table.shape}")
        self.tables.setdefault(table.name, table.reference())
        return self.make(op, (u, v), (("table", table.name), ("channel", int(channel))))

    def const(self, value):
        return self.make("const", attrs=(("value", float(np.float32(value))),))

    def vconst(self, value):
        return self.make("vconst", attrs=(("value", tuple(float(np.float32(v)) for v in value)),))

    def input(self, name, kind=FLOAT):
        return self.make("input" if kind == FLOAT else "vinput", attrs=(("name", name),))

    def lift(self, value):
        if isinstance(value, Expr):
            if value.graph is not self:
                raise ValueError("expressions from different graphs cannot be combined")
            return value
        arr = np.asarray(value, dtype=np.float64)
        if arr.ndim == 0:
            return self.const(arr)
        if arr.shape == (3,):
            return self.vconst(arr)
        raise TypeError(f"cannot use a value of shape {arr.shape} in a traced expression")


class Expr:
    __slots__ = ("graph", "id", "op", "args", "attrs", "kind")

    def __init__(self, graph, ident, op, args, attrs, kind):
        self.graph, self.id, self.op, self.args, self.attrs, self.kind = graph, ident, op, args, attrs, kind

    def attr(self, name):
        return dict(self.attrs)[name]

    @property
    def is_const(self):
        return self.op in ("const", "vconst")

    def __repr__(self):
        return f"Expr#{self.id}<{self.op} {self.kind}>"

    def __bool__(self):
        raise TypeError("a traced expression has no truth value; use shading_ops.select")

    __hash__ = object.__hash__
    __array_ufunc__ = None      # numpy_array + expr defers to Expr.__radd__ instead of broadcasting

    def _bin(self, other, op, vop=None, reverse=False):
        g = self.graph
        a, b = (g.lift(other), self) if reverse else (self, g.lift(other))
        if a.kind == VECTOR or b.kind == VECTOR:
            if vop is None:
                raise TypeError(f"{op} is not defined for vectors")
            if vop == "vscale":
                v, s = (a, b) if a.kind == VECTOR else (b, a)
                return g.make("vscale", (v, s))
            return g.make(vop, (a, b))
        return g.make(op, (a, b))

    def __add__(self, o): return self._bin(o, "add", "vadd")
    def __radd__(self, o): return self._bin(o, "add", "vadd", True)
    def __sub__(self, o): return self._bin(o, "subtract", "vsubtract")
    def __rsub__(self, o): return self._bin(o, "subtract", "vsubtract", True)
    def __mul__(self, o): return self._bin(o, "multiply", "vscale")
    def __rmul__(self, o): return self._bin(o, "multiply", "vscale", True)
    def __truediv__(self, o): return self._bin(o, "divide")
    def __rtruediv__(self, o): return self._bin(o, "divide", reverse=True)
    def __gt__(self, o): return self._bin(o, "greater_than")
    def __lt__(self, o): return self._bin(o, "less_than")

    def __neg__(self):
        return self * -1.0 if self.kind == FLOAT else self.graph.make("vscale", (self, self.graph.const(-1.0)))

    def __pow__(self, exponent):
        if isinstance(exponent, (int, np.integer)) and 1 <= exponent <= 5:
            result = self
            for _ in range(int(exponent) - 1):
                result = result * self
            return result
        return self.graph.make("power", (self, exponent))


def is_expr(*values):
    return any(isinstance(v, Expr) for v in values)


def graph_of(*values):
    for v in values:
        if isinstance(v, Expr):
            return v.graph
    raise ValueError("no expression among the arguments")


def trace(fn, inputs, graph=None):
    """Call ``fn`` with Expr inputs: ``inputs`` maps argument names to "float" / "vector".
    Returns (graph, output Expr or tuple of Exprs)."""
    graph = graph or Graph()
    args = {name: graph.input(name, kind) for name, kind in inputs.items()}
    return graph, fn(**args)


class Function:
    """A traced function: named, typed inputs and outputs over one Graph of its own.

    Backends treat a call as a unit: numpy evaluates the function's graph, the node backend
    emits it once as a node group and instances it at every call (nesting keeps every emitted
    tree small, and a function shared by lights, lobes or materials is built once).  ``key`` is
    a hash of the graph's structure, so two traces of the same math have the same key.
    """

    def __init__(self, name, inputs, outputs, description="", sockets=None):
        self.name, self.description = name, description
        self.inputs = list(inputs.items())
        self.outputs = dict(outputs)
        # (inputs, outputs): name -> core.ir.interface.Socket (an input and an output may share a name)
        self.sockets = tuple(dict(d) for d in sockets) if sockets else ({}, {})
        graphs = {e.graph for e in self.outputs.values() if isinstance(e, Expr)}
        if len(graphs) != 1:
            raise ValueError(f"{name}: outputs must be expressions of one graph")
        self.graph = graphs.pop()
        self.key = _structure_hash(self)

    def __repr__(self):
        return f"Function<{self.name} {self.key[:8]}>"


def define(name, fn, inputs, description="", sockets=None):
    """Trace ``fn`` (keyword arguments named as ``inputs``, name -> kind) into a Function; ``fn``
    returns a dict of output name -> Expr (or value)."""
    graph, out = trace(fn, inputs)
    if not isinstance(out, dict):
        raise TypeError(f"{name}: a function must return a dict of named outputs")
    out = {k: graph.lift(v) for k, v in out.items()}
    return Function(name, inputs, out, description, sockets)


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


def _structure_hash(function):
    index = {}
    parts = [repr(function.inputs), repr([(k, e.kind) for k, e in function.outputs.items()])]
    for node in topological_order(list(function.outputs.values())):
        index[node.id] = len(index)
        parts.append(repr((node.op, node.attrs, tuple(index[a.id] for a in node.args))))
    parts.append(repr([index[e.id] for e in function.outputs.values()]))
    return hashlib.sha1("\n".join(parts).encode()).hexdigest()


# --- folding -----------------------------------------------------------------------------------

def _const_value(e):
    return e.attr("value")


def _simplify(graph, op, args):
    """Constant folding and algebraic identities that hold under Blender's semantics."""
    if op in LEAVES or op in TABLE_READS:
        return None
    if all(a.is_const for a in args):
        value = apply(op, [np.asarray(_const_value(a), dtype=np.float32) for a in args])
        return graph.vconst(value) if OPS[op][1] == VECTOR else graph.const(value)
    if op in ("select", "vselect") and args[0].is_const:
        return args[1] if _const_value(args[0]) != 0.0 else args[2]
    if op in ("select", "vselect") and args[1] is args[2]:
        return args[1]
    if op == "add":
        if args[0].is_const and _const_value(args[0]) == 0.0:
            return args[1]
        if args[1].is_const and _const_value(args[1]) == 0.0:
            return args[0]
    if op in ("subtract",) and args[1].is_const and _const_value(args[1]) == 0.0:
        return args[0]
    if op == "multiply":
        for i in (0, 1):
            if args[i].is_const and _const_value(args[i]) == 1.0:
                return args[1 - i]
            # x * 0 = 0: every value in a guarded graph is finite (no NaN/Inf reaches a node),
            # so this drops whole branches, e.g. the sheen lobe of a material with sheen 0
            if args[i].is_const and _const_value(args[i]) == 0.0:
                return graph.const(0.0)
    if op in ("divide",) and args[1].is_const and _const_value(args[1]) == 1.0:
        return args[0]
    if op == "vscale" and args[1].is_const and _const_value(args[1]) == 1.0:
        return args[0]
    return None
