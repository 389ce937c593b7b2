"""Shading functions that are also node groups.

``NodeFunction`` wraps a Python shading function written with ``core.shading_ops``.  Called with
numpy arrays it simply runs; called with any ``Expr`` argument it becomes one ``call`` node of the
caller's graph, whose body is the function traced once (``expr.define``) and shared by every call.
So the same source gives direct numpy evaluation, the IR's numpy evaluation, and nested Blender
node groups (one group per function, instanced at each call).

A function that reads tables is declared with ``tables=``: the table set it is traced with, whose
entries are references (name and size, no data; ``core.lut.lookup.REFERENCES``).  Its Python body
takes the table set as its first argument: traced, it receives those references, so the traced body
does not depend on any folder of tables; called with numpy arrays, it receives the table set the
caller passes (``fn(tables=..., **inputs)``), which holds the data.
"""
from __future__ import annotations

from .expr import FLOAT, VECTOR, define, folding_enabled, graph_of, is_expr, table_filter_mode, topological_order

_KIND = {"float": FLOAT, "vector": VECTOR, "color": VECTOR}

#: Name suffix of a function traced with ``expr.table_filter("linear")`` whose body (or a function it
#: calls) reads a table with Linear filtering: its node group lives beside the four-fetch one.
LINEAR_SUFFIX = " (Linear)"


def reads_linear(function):
    """Whether ``function`` (an ``expr.Function``) or one it calls has a ``lut`` (Linear) table read."""
    for node in topological_order(list(function.outputs.values())):
        if node.op == "lut":
            return True
        if node.op == "call" and node.graph.functions[node.attr("function")].name.endswith(LINEAR_SUFFIX):
            return True
    return False


class NodeFunction:
    """``fn(**inputs) -> dict`` of named outputs (``fn(tables, **inputs)`` when ``tables`` is given),
    with ``sockets`` (name -> interface.Socket) in interface order: inputs first, then outputs."""

    def __init__(self, name, fn, inputs, outputs, description="", tables=None):
        self.name, self.fn, self.description = name, fn, description
        self.input_sockets = dict(inputs)
        self.output_sockets = dict(outputs)
        self.trace_tables = tables
        self._functions = {}        # (folding on/off, table filter) -> traced body

    @property
    def reads_tables(self):
        return self.trace_tables is not None

    @property
    def input_kinds(self):
        return {n: _KIND[s.kind] for n, s in self.input_sockets.items()}

    @property
    def function(self):
        """The traced body (``expr.Function``), built on first use, once per setting of constant
        folding (``expr.folding``) and of the table filter (``expr.table_filter``)."""
        folded = (folding_enabled(), table_filter_mode())
        if folded not in self._functions:
            sockets = (self.input_sockets, self.output_sockets)

            def body(**kw):
                out = self._run(self.trace_tables, kw)
                missing = set(self.output_sockets) - set(out)
                if missing:
                    raise ValueError(f"{self.name} did not return {sorted(missing)}")
                return {k: out[k] for k in self.output_sockets}

            function = define(self.name, body, self.input_kinds, self.description, sockets)
            if folded[1] == "linear" and reads_linear(function):
                # a different body under the same name would overwrite the other's node group
                function.name = f"{self.name}{LINEAR_SUFFIX}"
            self._functions[folded] = function
        return self._functions[folded]

    def _run(self, tables, args):
        return self.fn(tables, **args) if self.reads_tables else self.fn(**args)

    def __call__(self, tables=None, **args):
        if set(args) != set(self.input_sockets):
            raise ValueError(f"{self.name}: expected inputs {sorted(self.input_sockets)}, got {sorted(args)}")
        if is_expr(*args.values()):
            return graph_of(*args.values()).call(self.function, args)
        if self.reads_tables and tables is None:
            raise TypeError(f"{self.name} reads tables: pass tables= (e.g. core.lut.lookup.LutSet.from_folder())")
        return self._run(tables, args)

    def __repr__(self):
        return f"NodeFunction<{self.name}>"
