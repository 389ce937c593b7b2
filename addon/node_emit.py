"""Emit an IR graph (``core.ir``) as a shader node group: the node-group backend.

``build_node_group(name, outputs)`` materialises a hash-consed IR graph as one Blender node per
IR operation (shared subexpressions once; ``x``/``y``/``z`` of one vector share a single Separate
XYZ node).  Constants become socket default values (no Value nodes).  Math nodes keep
``use_clamp`` off, so the group computes exactly what ``numpy_backend.evaluate`` does.
"""
from __future__ import annotations

from collections import Counter

from pathlib import Path

import numpy as np

import bpy

from ..core.ir.expr import FLOAT, VECTOR, Expr
from ..core.ir.numpy_backend import topological_order
from ..core.lut import catalog

#: IR operation -> ShaderNodeMath.operation
MATH_OPS = {
    "add": "ADD", "subtract": "SUBTRACT", "multiply": "MULTIPLY", "divide": "DIVIDE",
    "power": "POWER", "sqrt": "SQRT", "inverse_sqrt": "INVERSE_SQRT", "exponent": "EXPONENT",
    "log2": "LOGARITHM", "minimum": "MINIMUM", "maximum": "MAXIMUM", "less_than": "LESS_THAN",
    "greater_than": "GREATER_THAN", "absolute": "ABSOLUTE", "arccosine": "ARCCOSINE",
    "arcsine": "ARCSINE", "sine": "SINE", "cosine": "COSINE", "tangent": "TANGENT",
    "arctan2": "ARCTAN2", "floor": "FLOOR",
}

#: IR operation -> (ShaderNodeVectorMath.operation, input socket indices, output socket name)
VECTOR_OPS = {
    "vadd": ("ADD", (0, 1), "Vector"),
    "vsubtract": ("SUBTRACT", (0, 1), "Vector"),
    "vscale": ("SCALE", (0, 3), "Vector"),          # input 3 is 'Scale'
    "vmultiply": ("MULTIPLY", (0, 1), "Vector"),
    "dot": ("DOT_PRODUCT", (0, 1), "Value"),
    "cross": ("CROSS_PRODUCT", (0, 1), "Vector"),
    "length": ("LENGTH", (0,), "Value"),
    "normalize": ("NORMALIZE", (0,), "Vector"),
}

#: ShaderNodeMix socket identifiers: (factor, A = if_false, B = if_true, result)
MIX_SOCKETS = {
    "select": ("Factor_Float", "A_Float", "B_Float", "Result_Float"),
    "vselect": ("Factor_Float", "A_Vector", "B_Vector", "Result_Vector"),
}

COLUMN_WIDTH = 180.0
ROW_HEIGHT = 170.0

_LEAVES = ("const", "vconst", "input", "vinput")
_COMPONENTS = {"x": 0, "y": 1, "z": 2}


def _socket(sockets, identifier):
    for s in sockets:
        if s.identifier == identifier:
            return s
    raise KeyError(identifier)


#: Tables that are not in the LUT catalog (baked environments): name -> EXR path (``register_image``).
_EXTRA_IMAGES = {}


def register_image(table, path):
    """Make ``table`` (e.g. a baked environment, ``env_<hash>``) loadable by ``lut_image`` from ``path``."""
    _EXTRA_IMAGES[table] = Path(path)


def _table_path(table, lut_dir):
    if table in catalog.TABLES:
        return Path(lut_dir or catalog.default_lut_dir()) / catalog.TABLES[table].filename
    if table in _EXTRA_IMAGES:
        return _EXTRA_IMAGES[table]
    raise KeyError(f"no image for table {table!r}: not a catalog LUT and not registered (sync the world again)")


def lut_image(table, lut_dir=None):
    """The Blender image of a catalog table, loaded once (as ../shared/reference/blender_addon.md
    §3.1 prescribes: float, Non-Color, channel-packed alpha), packed into the .blend, fake user."""
    name = f"RTL_{table}"
    image = bpy.data.images.get(name)
    if image is None:
        path = _table_path(table, lut_dir)
        image = bpy.data.images.load(str(path), check_existing=False)
        image.name = name
        image.colorspace_settings.name = "Non-Color"
        image.alpha_mode = "CHANNEL_PACKED"
        # full float on the GPU: EEVEE would otherwise upload half floats (LTC entries reach 1e8)
        image.use_half_precision = False
        image.pack()
        image.use_fake_user = True
    return image


def _depths(order):
    """Longest path from the inputs (inputs and constants at depth 0)."""
    depth = {}
    for node in order:
        depth[node.id] = 0 if node.op in _LEAVES else 1 + max(depth[a.id] for a in node.args)
    return depth


#: Bump when the emitter's output for an unchanged IR changes (layout aside): stamps include it.
EMITTER_VERSION = 4

#: Soft cap on nodes per emitted tree (../shared/reference/blender_addon.md §2.3: flat trees build
#: super-linearly; nested groups of <= ~150 nodes build ~50x faster with identical pixels).
MAX_GROUP_NODES = 150

_SOCKET_TYPES = {"float": "NodeSocketFloat", "vector": "NodeSocketVector", "color": "NodeSocketColor",
                 "shader": "NodeSocketShader",
                 FLOAT: "NodeSocketFloat", VECTOR: "NodeSocketVector"}


def _socket_value(socket, value):
    """A default value shaped for ``socket`` (colours take RGBA)."""
    if isinstance(value, (tuple, list)) and getattr(socket, "type", "") == "RGBA" and len(value) == 3:
        return (*value, 1.0)
    if isinstance(value, (tuple, list)) and getattr(socket, "type", "") in ("VALUE",) and len(value) >= 3:
        return sum(value[:3]) / 3.0
    return value


def _new_interface_socket(iface, name, in_out, kind, spec, panels):
    """An interface socket from a core.ir.interface.Socket (or just a kind)."""
    socket_kind = spec.kind if spec is not None else kind
    parent = None
    if spec is not None and spec.panel:
        parent = panels.get(spec.panel)
        if parent is None:
            parent = panels[spec.panel] = iface.new_panel(spec.panel, default_closed=False)
    item = iface.new_socket(name, in_out=in_out, socket_type=_SOCKET_TYPES[socket_kind], parent=parent)
    if spec is not None:
        _apply_socket_spec(item, in_out, spec)
    return item


def _apply_socket_spec(item, in_out, spec):
    socket_kind = spec.kind
    item.description = spec.description
    if socket_kind == "shader":
        return item
    if spec.subtype and spec.subtype != "NONE":
        item.subtype = spec.subtype
    if in_out == "INPUT":
        default = spec.default
        if socket_kind == "color" and len(default) == 3:
            default = (*default, 1.0)
        item.default_value = default
        if spec.min is not None and hasattr(item, "min_value"):
            item.min_value = spec.min
        if spec.max is not None and hasattr(item, "max_value"):
            item.max_value = spec.max
        item.hide_value = spec.hide_value
    return item


def _interface_signature(spec_list):
    return sorted((name, in_out, _SOCKET_TYPES[spec.kind if spec is not None else kind],
                   spec.panel if spec is not None else None) for name, in_out, kind, spec in spec_list)


def _ensure_interface(ng, wanted):
    """Interface items (name, in_out) -> item for ``wanted`` [(name, in_out, kind, Socket)].

    An interface that already has exactly these sockets (names, types, panels) is kept as it is:
    Group nodes using the tree keep their links and values when it is rebuilt.  Otherwise the
    interface is created anew (descriptions, ranges and defaults are refreshed either way)."""
    iface = ng.interface
    existing = [it for it in iface.items_tree if it.item_type == "SOCKET"]
    current = sorted((it.name, it.in_out, it.socket_type, it.parent.name if it.parent and it.parent.name else None)
                     for it in existing)
    keep = current == _interface_signature(wanted) and len({(it.name, it.in_out) for it in existing}) == len(existing)
    if not keep:
        iface.clear()
        panels = {}
        items = {(name, in_out): _new_interface_socket(iface, name, in_out, kind, spec, panels)
                 for name, in_out, kind, spec in wanted}
    else:
        items = {(it.name, it.in_out): it for it in existing}
        for name, in_out, kind, spec in wanted:
            if spec is not None:
                _apply_socket_spec(items[(name, in_out)], in_out, spec)
    return items


class _Emitter:
    """Materialises IR graphs as node trees; shares one group per function (by structure key)."""

    def __init__(self, lut_dir=None):
        self.lut_dir = lut_dir
        self.groups = {}          # Function.key -> node tree ensured in this build

    # -- functions ---------------------------------------------------------------------------
    def function_group(self, fn):
        ng = self.groups.get(fn.key)
        if ng is not None:
            return ng
        stamp = f"{EMITTER_VERSION}:{fn.key}"
        ng = bpy.data.node_groups.get(fn.name)
        if ng is None or ng.bl_idname != "ShaderNodeTree":
            ng = bpy.data.node_groups.new(fn.name, "ShaderNodeTree")
        elif ng.get("rtl_stamp") == stamp:
            self._ensure_nested(fn)
            self.groups[fn.key] = ng
            return ng
        else:
            ng.nodes.clear()
        self.fill(ng, fn.outputs, [n for n, _ in fn.inputs], fn.sockets,
                  {n: k for n, k in fn.inputs}, description=fn.description)
        ng["rtl_stamp"] = stamp
        ng["rtl_function"] = fn.name
        self.groups[fn.key] = ng
        return ng

    def _ensure_nested(self, fn):
        """A stamped group is current; its nested functions are current too (same key), but a
        nested group may have been deleted or renamed by the user: re-ensure them."""
        for node in topological_order(list(fn.outputs.values())):
            if node.op == "call":
                self.function_group(node.graph.functions[node.attr("function")])

    # -- one tree ----------------------------------------------------------------------------
    def fill(self, ng, outputs, input_names, sockets=None, kinds=None, internal_inputs=None, description="",
             shader_sums=None):
        """Emit ``outputs`` (name -> Expr of one graph) into the empty tree ``ng``.

        ``input_names``: interface inputs, in order; ``sockets``: (inputs, outputs), each
        name -> interface.Socket; ``internal_inputs``: graph input name -> callable(nodes, links) giving
        an output socket inside the tree (e.g. Geometry > Position) instead of an interface input.
        ``shader_sums``: shader output name -> names of colour outputs; each becomes an Emission
        closure (strength 1) and they are summed with Add Shader nodes; those colour outputs are
        not interface sockets.
        """
        in_sockets, out_sockets = sockets or ({}, {})
        kinds, internal_inputs = kinds or {}, internal_inputs or {}
        outs = list(outputs.items())
        graph = next((e.graph for _, e in outs if isinstance(e, Expr)), None)
        if graph is None or any(not isinstance(e, Expr) or e.graph is not graph for _, e in outs):
            raise ValueError("all outputs must be expressions of one graph")
        order = topological_order([e for _, e in outs])
        depth = _depths(order)
        inputs = {n.attr("name"): n for n in order if n.op in ("input", "vinput")}
        missing = set(inputs) - set(input_names) - set(internal_inputs)
        if missing:
            raise ValueError(f"inputs lack graph inputs {sorted(missing)}")

        ng.description = description
        shader_sums = shader_sums or {}
        hidden = {n for names in shader_sums.values() for n in names}
        wanted = [(name, "OUTPUT", "shader", out_sockets.get(name)) for name in shader_sums]
        wanted += [(out_name, "OUTPUT", expr.kind, out_sockets.get(out_name)) for out_name, expr in outs
                   if out_name not in hidden]
        wanted += [(n, "INPUT", inputs[n].kind if n in inputs else kinds.get(n, FLOAT), in_sockets.get(n))
                   for n in input_names]
        items = _ensure_interface(ng, wanted)
        in_items = {n: items[(n, "INPUT")] for n in input_names}

        nodes, links = ng.nodes, ng.links
        max_depth = max(depth.values()) if depth else 0
        column_rows = Counter()

        def place(node, col, label):
            row = column_rows[col]
            column_rows[col] += 1
            node.location = (col * COLUMN_WIDTH, -row * ROW_HEIGHT)
            node.label = label

        group_in = nodes.new("NodeGroupInput")
        place(group_in, 0, "inputs")
        group_in.width = 140

        produced = {}
        for n, item in in_items.items():
            if n in inputs:
                produced[inputs[n].id] = _socket(group_in.outputs, item.identifier)
        for n, make_socket in internal_inputs.items():
            if n in inputs:
                produced[inputs[n].id] = make_socket(nodes, links)
        separators = {}       # source vector id -> ShaderNodeSeparateXYZ
        textures = {}         # (table, u id, v id) -> (Image Texture node, Separate Color node)
        calls = {}            # call node id -> Group node

        def feed(socket, arg):
            if arg.is_const:
                socket.default_value = _socket_value(socket, arg.attr("value"))
            else:
                links.new(produced[arg.id], socket)

        for node in order:
            op = node.op
            if op in _LEAVES:
                continue
            col = depth[node.id]
            if op in MATH_OPS:
                bn = nodes.new("ShaderNodeMath")
                bn.operation = MATH_OPS[op]
                bn.use_clamp = False
                for i, a in enumerate(node.args):
                    feed(bn.inputs[i], a)
                if op == "log2":
                    bn.inputs[1].default_value = 2.0
                produced[node.id] = bn.outputs[0]
            elif op in MIX_SOCKETS:
                fac, a_id, b_id, res = MIX_SOCKETS[op]
                cond, if_true, if_false = node.args

                def mix_node():
                    m = nodes.new("ShaderNodeMix")
                    m.data_type = "FLOAT" if op == "select" else "VECTOR"
                    if op == "vselect":
                        m.factor_mode = "UNIFORM"
                    feed(_socket(m.inputs, fac), cond)
                    return m

                # EEVEE's mix(a, b, 1) is a + (b - a): b rounded to ulp(a), wrong when |a| >> |b|
                # (measured; Cycles is exact).  mix(mix(a, 0, c), b, c) is exact for c in {0, 1}
                # in both engines; a constant-zero false branch needs only the second node.
                false_is_zero = if_false.is_const and not np.any(if_false.attr("value"))
                bn = mix_node()
                if false_is_zero:
                    feed(_socket(bn.inputs, a_id), if_false)
                else:
                    zero = mix_node()
                    feed(_socket(zero.inputs, a_id), if_false)
                    _socket(zero.inputs, b_id).default_value = 0.0 if op == "select" else (0.0, 0.0, 0.0)
                    place(zero, col, f"{op} (zero)")
                    links.new(_socket(zero.outputs, res), _socket(bn.inputs, a_id))
                feed(_socket(bn.inputs, b_id), if_true)
                produced[node.id] = _socket(bn.outputs, res)
            elif op == "combine":
                bn = nodes.new("ShaderNodeCombineXYZ")
                for i, a in enumerate(node.args):
                    feed(bn.inputs[i], a)
                produced[node.id] = bn.outputs[0]
            elif op in _COMPONENTS:
                src = node.args[0]
                bn = separators.get(src.id)
                if bn is None:
                    bn = nodes.new("ShaderNodeSeparateXYZ")
                    feed(bn.inputs[0], src)
                    separators[src.id] = bn
                    place(bn, col, "separate")
                produced[node.id] = bn.outputs[_COMPONENTS[op]]
                continue
            elif op in ("lut", "texel"):
                table, channel = node.attr("table"), node.attr("channel")
                u, v = node.args
                key = (op, table, u.id, v.id)
                if key not in textures:
                    uv = nodes.new("ShaderNodeCombineXYZ")
                    feed(uv.inputs[0], u)
                    feed(uv.inputs[1], v)
                    place(uv, col, "lut uv")
                    tex = nodes.new("ShaderNodeTexImage")
                    tex.image = lut_image(table, self.lut_dir)
                    tex.interpolation = "Linear" if op == "lut" else "Closest"
                    tex.extension = "EXTEND"
                    links.new(uv.outputs[0], tex.inputs["Vector"])
                    place(tex, col, table)
                    sep = nodes.new("ShaderNodeSeparateColor")
                    links.new(tex.outputs["Color"], sep.inputs[0])
                    place(sep, col, "channels")
                    textures[key] = (tex, sep)
                tex, sep = textures[key]
                produced[node.id] = tex.outputs["Alpha"] if channel == 3 else sep.outputs[channel]
                continue
            elif op == "call":
                fn = node.graph.functions[node.attr("function")]
                bn = nodes.new("ShaderNodeGroup")
                bn.node_tree = self.function_group(fn)
                for (name, _), a in zip(fn.inputs, node.args):
                    feed(bn.inputs[name], a)
                calls[node.id] = bn
                place(bn, col, fn.name)
                bn.width = 200
                continue
            elif op == "output":
                produced[node.id] = calls[node.args[0].id].outputs[node.attr("name")]
                continue
            elif op in VECTOR_OPS:
                operation, slots, out_name = VECTOR_OPS[op]
                bn = nodes.new("ShaderNodeVectorMath")
                bn.operation = operation
                for i, a in zip(slots, node.args):
                    feed(bn.inputs[i], a)
                produced[node.id] = _socket(bn.outputs, out_name)
            else:  # pragma: no cover - OPS and this table are kept in step
                raise ValueError(f"no node mapping for IR operation {op!r}")
            place(bn, col, op)

        group_out = nodes.new("NodeGroupOutput")
        place(group_out, max_depth + 1, "outputs")
        for row, (shader_name, parts) in enumerate(shader_sums.items()):
            total = None
            for i, part in enumerate(parts):
                expr = outputs[part]
                if expr.is_const and not any(expr.attr("value")):
                    continue                      # a closure of zero emission adds nothing
                emission = nodes.new("ShaderNodeEmission")
                emission.label = part
                emission.location = ((max_depth + 1) * COLUMN_WIDTH, -(row + i) * ROW_HEIGHT)
                emission.inputs["Strength"].default_value = 1.0
                feed(emission.inputs["Color"], expr)
                if total is None:
                    total = emission.outputs[0]
                    continue
                add = nodes.new("ShaderNodeAddShader")
                add.location = ((max_depth + 2) * COLUMN_WIDTH, -(row + i) * ROW_HEIGHT)
                links.new(total, add.inputs[0])
                links.new(emission.outputs[0], add.inputs[1])
                total = add.outputs[0]
            if total is not None:
                links.new(total, _socket(group_out.inputs, items[(shader_name, "OUTPUT")].identifier))
        group_out.location = ((max_depth + 3) * COLUMN_WIDTH, 0.0)
        for out_name, expr in outs:
            if out_name in hidden:
                continue
            item = items[(out_name, "OUTPUT")]
            sock = _socket(group_out.inputs, item.identifier)
            if expr.is_const:
                sock.default_value = _socket_value(sock, expr.attr("value"))
                item.default_value = _socket_value(sock, expr.attr("value"))
            else:
                links.new(produced[expr.id], sock)
        return ng


def build_node_group(name, outputs, input_order=None, lut_dir=None):
    """Build a new ShaderNodeTree group computing ``outputs`` (dict output name -> Expr of one Graph).

    Group inputs are the graph's ``input``/``vinput`` nodes in ``input_order`` (default: sorted
    names); group outputs are the dict's keys, in dict order.  ``lut`` operations become one
    Image Texture (Linear, EXTEND) per table and coordinate pair, with one Separate Color;
    function calls become Group nodes of their (shared, stamped) groups.
    """
    if not outputs:
        raise ValueError("a node group needs at least one output")
    first = next(iter(outputs.values()))
    if not isinstance(first, Expr):
        raise ValueError("all outputs must be expressions of one graph")
    order = topological_order(list(outputs.values()))
    names = list(input_order) if input_order is not None else sorted(
        n.attr("name") for n in order if n.op in ("input", "vinput"))
    ng = bpy.data.node_groups.new(name, "ShaderNodeTree")
    _Emitter(lut_dir).fill(ng, outputs, names)
    return ng


def ensure_function_group(function, lut_dir=None):
    """The node group of a NodeFunction / expr.Function, built only when missing or when its
    stamp (emitter version + structure hash) differs; rebuilt in place, so materials keep it."""
    fn = getattr(function, "function", function)
    return _Emitter(lut_dir).function_group(fn)


def ensure_tree(name, outputs, input_names, sockets=None, internal_inputs=None, stamp_extra="",
                lut_dir=None, description="", shader_sums=None):
    """A named group computing ``outputs`` with some inputs produced inside the tree
    (``internal_inputs``); rebuilt only when the graph's structure or ``stamp_extra`` changes."""
    from ..core.ir.expr import Function

    fn = Function(name, {}, outputs)         # for its structure hash
    stamp = f"{EMITTER_VERSION}:{fn.key}:{sorted(input_names)}:{stamp_extra}:{shader_sums!r}"
    ng = bpy.data.node_groups.get(name)
    if ng is not None and ng.get("rtl_stamp") == stamp:
        return ng, False
    if ng is None:
        ng = bpy.data.node_groups.new(name, "ShaderNodeTree")
    else:
        ng.nodes.clear()
    _Emitter(lut_dir).fill(ng, outputs, input_names, sockets, internal_inputs=internal_inputs,
                           description=description, shader_sums=shader_sums)
    ng["rtl_stamp"] = stamp
    return ng, True


def tree_node_counts(ng, seen=None):
    """{group name: node count} for ``ng`` and every group nested in it (each once)."""
    seen = {} if seen is None else seen
    if ng.name in seen:
        return seen
    seen[ng.name] = len(ng.nodes)
    for node in ng.nodes:
        if node.bl_idname == "ShaderNodeGroup" and node.node_tree is not None:
            tree_node_counts(node.node_tree, seen)
    return seen


def flat_tree_node_count(ng):
    """Nodes of ``ng`` with every Group node replaced by its content (recursively)."""
    total = 0
    for node in ng.nodes:
        if node.bl_idname == "ShaderNodeGroup" and node.node_tree is not None:
            total += flat_tree_node_count(node.node_tree) - 2   # minus the inner group input/output
        else:
            total += 1
    return total


def node_group_stats(ng):
    """Number of nodes in ``ng`` by Blender node type (bl_idname)."""
    return dict(Counter(n.bl_idname for n in ng.nodes))
