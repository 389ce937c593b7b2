"""Shading functions that are also node groups.

``NodeFunction`` wraps a Python shading function written with ``core.shading_ops``.  Called
with numpy arrays it simply runs; called with any ``Expr`` argument it becomes one ``call``
node of the caller's graph, whose body is the function traced once (``expr.define``) and
shared by every call.  So the same source gives direct numpy evaluation, the IR's numpy
evaluation, and nested Blender node groups (one group per function, instanced at each call).
"""
from __future__ import annotations

import weakref

from .expr import FLOAT, VECTOR, define, graph_of, is_expr

_ALL = weakref.WeakSet()


def invalidate_all():
    """Forget every traced body (e.g. after the LUT folder changed: bodies hold table data)."""
    for fn in list(_ALL):
        fn.invalidate()

_KIND = {"float": FLOAT, "vector": VECTOR, "color": VECTOR}


class NodeFunction:
    """``fn(**inputs) -> dict`` of named outputs, with ``sockets`` (name -> interface.Socket) in
    interface order: inputs first, then outputs (``outputs`` lists their names)."""

    def __init__(self, name, fn, inputs, outputs, description=""):
        self.name, self.fn, self.description = name, fn, description
        self.input_sockets = dict(inputs)
        self.output_sockets = dict(outputs)
        self._function = None
        _ALL.add(self)

    def invalidate(self):
        """Trace the body again on next use."""
        self._function = None

    @property
    def input_kinds(self):
        return {n: _KIND[s.kind] for n, s in self.input_sockets.items()}

    @property
    def function(self):
        """The traced body (``expr.Function``), built on first use."""
        if self._function is None:
            sockets = (self.input_sockets, self.output_sockets)
            fn = self.fn

            def body(**kw):
                out = fn(**kw)
                missing = set(self.output_sockets) - set(out)
                if missing:
                    raise ValueError(f"{self.name} did not return {sorted(missing)}")
                return {k: out[k] for k in self.output_sockets}

            self._function = define(self.name, body, self.input_kinds, self.description, sockets)
        return self._function

    def __call__(self, **args):
        if set(args) != set(self.input_sockets):
            raise ValueError(f"{self.name}: expected inputs {sorted(self.input_sockets)}, got {sorted(args)}")
        if is_expr(*args.values()):
            return graph_of(*args.values()).call(self.function, args)
        return self.fn(**args)

    def __repr__(self):
        return f"NodeFunction<{self.name}>"
