"""Emit an IR graph (``core.ir``) as a shader node group: the node-group backend.

``build_node_group(name, outputs)`` materialises a hash-consed IR graph as one Blender node per
IR operation (shared subexpressions once; ``x``/``y``/``z`` of one vector share a single Separate
XYZ node).  Constants become socket default values (no Value nodes).  Math nodes keep
``use_clamp`` off, so the group computes exactly what ``numpy_backend.evaluate`` does.
"""
from __future__ import annotations

from collections import Counter

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
    "arctan2": "ARCTAN2",
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


def lut_image(table, lut_dir=None):
    """The Blender image of a catalog table, loaded once (as ../shared/reference/blender_addon.md
    §3.1 prescribes: float, Non-Color, channel-packed alpha), packed into the .blend, fake user."""
    name = f"RTL_{table}"
    image = bpy.data.images.get(name)
    if image is None:
        path = (lut_dir or catalog.default_lut_dir()) / catalog.TABLES[table].filename
        image = bpy.data.images.load(str(path), check_existing=False)
        image.name = name
        image.colorspace_settings.name = "Non-Color"
        image.alpha_mode = "CHANNEL_PACKED"
        image.pack()
        image.use_fake_user = True
    return image


def _depths(order):
    """Longest path from the inputs (inputs and constants at depth 0)."""
    depth = {}
    for node in order:
        depth[node.id] = 0 if node.op in _LEAVES else 1 + max(depth[a.id] for a in node.args)
    return depth


def build_node_group(name, outputs, input_order=None, lut_dir=None):
    """Build a ShaderNodeTree group computing ``outputs`` (dict output name -> Expr of one Graph).

    Group inputs are the graph's ``input``/``vinput`` nodes in ``input_order`` (default: sorted
    names); group outputs are the dict's keys, in dict order.  ``lut`` operations become one
    Image Texture (Linear, EXTEND) per table and coordinate pair, with one Separate Color.
    """
    if not outputs:
        raise ValueError("a node group needs at least one output")
    outs = list(outputs.items())
    graph = outs[0][1].graph
    if any(not isinstance(e, Expr) or e.graph is not graph for _, e in outs):
        raise ValueError("all outputs must be expressions of one graph")
    order = topological_order([e for _, e in outs])
    depth = _depths(order)

    inputs = {n.attr("name"): n for n in order if n.op in ("input", "vinput")}
    names = list(input_order) if input_order is not None else sorted(inputs)
    missing = set(inputs) - set(names)
    if missing:
        raise ValueError(f"input_order lacks graph inputs {sorted(missing)}")

    ng = bpy.data.node_groups.new(name, "ShaderNodeTree")
    iface = ng.interface
    for out_name, expr in outs:
        iface.new_socket(out_name, in_out="OUTPUT",
                         socket_type="NodeSocketVector" if expr.kind == VECTOR else "NodeSocketFloat")
    in_items = {}
    for n in names:
        kind = inputs[n].kind if n in inputs else FLOAT
        in_items[n] = iface.new_socket(n, in_out="INPUT",
                                       socket_type="NodeSocketVector" if kind == VECTOR else "NodeSocketFloat")

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

    # socket producing each IR node: id -> output socket
    produced = {}
    for n, item in in_items.items():
        if n in inputs:
            produced[inputs[n].id] = _socket(group_in.outputs, item.identifier)
    separators = {}       # source vector id -> ShaderNodeSeparateXYZ
    textures = {}         # (table, u id, v id) -> (Image Texture node, Separate Color node)

    def feed(socket, arg):
        if arg.is_const:
            value = arg.attr("value")
            socket.default_value = value
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
            bn = nodes.new("ShaderNodeMix")
            bn.data_type = "FLOAT" if op == "select" else "VECTOR"
            if op == "vselect":
                bn.factor_mode = "UNIFORM"
            cond, if_true, if_false = node.args
            feed(_socket(bn.inputs, fac), cond)
            feed(_socket(bn.inputs, a_id), if_false)
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
        elif op == "lut":
            table, channel = node.attr("table"), node.attr("channel")
            u, v = node.args
            key = (table, u.id, v.id)
            if key not in textures:
                uv = nodes.new("ShaderNodeCombineXYZ")
                feed(uv.inputs[0], u)
                feed(uv.inputs[1], v)
                place(uv, col, "lut uv")
                tex = nodes.new("ShaderNodeTexImage")
                tex.image = lut_image(table, lut_dir)
                tex.interpolation = "Linear"
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
    out_items = [it for it in iface.items_tree if it.item_type == "SOCKET" and it.in_out == "OUTPUT"]
    for (out_name, expr), item in zip(outs, out_items):
        sock = _socket(group_out.inputs, item.identifier)
        if expr.is_const:
            sock.default_value = expr.attr("value")
            item.default_value = expr.attr("value")
        else:
            links.new(produced[expr.id], sock)
    return ng


def node_group_stats(ng):
    """Number of nodes in ``ng`` by Blender node type (bl_idname)."""
    return dict(Counter(n.bl_idname for n in ng.nodes))
