"""Emit an IR graph (``core.ir``) as a shader node group: the node-group backend.

``build_node_group(name, outputs)`` materialises a hash-consed IR graph as one Blender node per IR
operation (shared subexpressions once; ``x``/``y``/``z`` of one vector share a single Separate XYZ
node).  Constants become socket default values (no Value nodes).  Math nodes keep ``use_clamp`` off,
so the group computes exactly what ``numpy_backend.evaluate`` does: each operation maps to the Blender
node with its rule in ``core.ir.semantics`` (``EMITTERS``: IR operation -> emitting function).

Tables are read through the table set the caller passes (``tables``: name -> ``core.ir.tables.Table``
with a ``source`` file); each becomes an image "RTL_<table>", loaded once and packed.
"""
from __future__ import annotations

from collections import Counter

import bpy
import numpy as np

from ..core.ir.expr import FLOAT, Expr, Function, topological_order
from ..core.ir.semantics import LEAVES
from ..core.ir.tables import resolve
from ..core.lut.lookup import LutSet
from .common import IMAGE_PREFIX, STAMP_KEY, before_rebuild, ensure_interface, replace_group, socket_by_identifier

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

_COMPONENTS = {"x": 0, "y": 1, "z": 2}

#: Bump when the emitter's output for an unchanged IR changes (layout aside): stamps include it.
EMITTER_VERSION = 5

#: Soft cap on nodes per emitted tree (docs/blender.md, "Node groups": flat trees build
#: super-linearly; nested groups of <= ~150 nodes build ~50x faster with identical pixels).
MAX_GROUP_NODES = 150


def lut_image(table):
    """The Blender image "RTL_<name>" of a ``core.ir.tables.Table``, loaded once from its ``source``
    (docs/blender.md, "Tables as images": float, Non-Color, channel-packed alpha, full float on the
    GPU), packed into the .blend, with a fake user.  An image of that name already in the file is used
    as it is (a packed table serves when its file is gone)."""
    name = IMAGE_PREFIX + table.name
    image = bpy.data.images.get(name)
    if image is None:
        if table.source is None:
            raise KeyError(f"no image file for table {table.name!r} (sync the world again)")
        image = bpy.data.images.load(str(table.source), check_existing=False)
        image.name = name
        image.colorspace_settings.name = "Non-Color"
        image.alpha_mode = "CHANNEL_PACKED"
        # full float on the GPU: EEVEE would otherwise upload half floats (LTC entries reach 1e8)
        image.use_half_precision = False
        image.pack()
        image.use_fake_user = True
    return image


def _socket_value(socket, value):
    """A default value shaped for ``socket`` (colours take RGBA)."""
    if isinstance(value, (tuple, list)) and getattr(socket, "type", "") == "RGBA" and len(value) == 3:
        return (*value, 1.0)
    if isinstance(value, (tuple, list)) and getattr(socket, "type", "") in ("VALUE",) and len(value) >= 3:
        return sum(value[:3]) / 3.0
    return value


def _depths(order):
    """Longest path from the inputs (inputs and constants at depth 0)."""
    depth = {}
    for node in order:
        depth[node.id] = 0 if node.op in LEAVES else 1 + max(depth[a.id] for a in node.args)
    return depth


# --- one tree ---------------------------------------------------------------------------------------

class _TreeWriter:
    """Writes the nodes of one graph into one tree: ``produced`` maps IR node id -> output socket."""

    def __init__(self, emitter, ng, order):
        self.emitter, self.nodes, self.links = emitter, ng.nodes, ng.links
        self.depth = _depths(order)
        self.rows = Counter()
        self.produced = {}
        self.separators = {}       # source vector id -> ShaderNodeSeparateXYZ
        self.components_read = Counter(n.args[0].id for n in order if n.op in _COMPONENTS)   # vector id -> of x, y, z
        self.textures = {}         # (op, table, u id, v id) -> (Image Texture node, Separate Color node)
        self.calls = {}            # call node id -> Group node

    def place(self, node, col, label):
        row = self.rows[col]
        self.rows[col] += 1
        node.location = (col * COLUMN_WIDTH, -row * ROW_HEIGHT)
        node.label = label

    def feed(self, socket, arg):
        if arg.is_const:
            socket.default_value = _socket_value(socket, arg.attr("value"))
        else:
            self.links.new(self.produced[arg.id], socket)

    def new(self, kind, node, label=None):
        bn = self.nodes.new(kind)
        self.place(bn, self.depth[node.id], label or node.op)
        return bn

    def write(self, node):
        self.produced[node.id] = EMITTERS[node.op](self, node)


def _emit_math(w, node):
    bn = w.new("ShaderNodeMath", node)
    bn.operation = MATH_OPS[node.op]
    bn.use_clamp = False
    for i, a in enumerate(node.args):
        w.feed(bn.inputs[i], a)
    if node.op == "log2":
        bn.inputs[1].default_value = 2.0
    return bn.outputs[0]


def _emit_vector(w, node):
    operation, slots, out_name = VECTOR_OPS[node.op]
    bn = w.new("ShaderNodeVectorMath", node)
    bn.operation = operation
    for i, a in zip(slots, node.args):
        w.feed(bn.inputs[i], a)
    return socket_by_identifier(bn.outputs, out_name)


# EEVEE's mix(a, b, 1) is a + (b - a): b rounded to ulp(a), wrong when |a| >> |b| (measured; Cycles is
# exact).  mix(mix(a, 0, c), b, c) is exact for c in {0, 1} in both engines; a constant-zero false branch
# needs only the second node.
def _emit_select(w, node):
    fac, a_id, b_id, res = MIX_SOCKETS[node.op]
    cond, if_true, if_false = node.args

    def mix_node(label):
        m = w.new("ShaderNodeMix", node, label)
        m.data_type = "FLOAT" if node.op == "select" else "VECTOR"
        if node.op == "vselect":
            m.factor_mode = "UNIFORM"
        w.feed(socket_by_identifier(m.inputs, fac), cond)
        return m

    false_is_zero = if_false.is_const and not np.any(if_false.attr("value"))
    if false_is_zero:
        bn = mix_node(node.op)
        w.feed(socket_by_identifier(bn.inputs, a_id), if_false)
    else:
        zero = mix_node(f"{node.op} (zero)")
        w.feed(socket_by_identifier(zero.inputs, a_id), if_false)
        socket_by_identifier(zero.inputs, b_id).default_value = 0.0 if node.op == "select" else (0.0, 0.0, 0.0)
        bn = mix_node(node.op)
        w.links.new(socket_by_identifier(zero.outputs, res), socket_by_identifier(bn.inputs, a_id))
    w.feed(socket_by_identifier(bn.inputs, b_id), if_true)
    return socket_by_identifier(bn.outputs, res)


def _emit_combine(w, node):
    bn = w.new("ShaderNodeCombineXYZ", node)
    for i, a in enumerate(node.args):
        w.feed(bn.inputs[i], a)
    return bn.outputs[0]


# Why a vector read in part is not separated (measured with Cycles 4.5's shader log, GLOG_v=5): Cycles' Separate XYZ
# compiles by giving each of its three outputs a slot on the SVM stack whether or not anything reads it
# (``SeparateXYZNode::compile``), and the compiler frees a slot only when the last node reading it is done
# (``SVMCompiler::stack_clear_users``), so an output nothing reads holds its slot to the end of the shader.  Those
# slots, and the holes they leave, took the spread's quad rule from 59 to 138 of the 255 floats Blender 4.5 has, and
# five lobes under a light with spread past them (black renders).  A component read alone is a Dot Product with its
# axis instead: exact for finite vectors (x * 1 + y * 0 + z * 0), one node, no slot left behind.
def _emit_component(w, node):
    src = node.args[0]
    if w.components_read[src.id] < len(_COMPONENTS):
        bn = w.new("ShaderNodeVectorMath", node, "component")
        bn.operation = "DOT_PRODUCT"
        w.feed(bn.inputs[0], src)
        bn.inputs[1].default_value = [float(i == _COMPONENTS[node.op]) for i in range(len(_COMPONENTS))]
        return bn.outputs["Value"]
    bn = w.separators.get(src.id)
    if bn is None:
        bn = w.separators[src.id] = w.new("ShaderNodeSeparateXYZ", node, "separate")
        w.feed(bn.inputs[0], src)
    return bn.outputs[_COMPONENTS[node.op]]


def _emit_table_read(w, node):
    table, channel = node.attr("table"), node.attr("channel")
    u, v = node.args
    key = (node.op, table, u.id, v.id)
    if key not in w.textures:
        uv = w.new("ShaderNodeCombineXYZ", node, "lut uv")
        w.feed(uv.inputs[0], u)
        w.feed(uv.inputs[1], v)
        tex = w.new("ShaderNodeTexImage", node, table)
        tex.image = w.emitter.image(table)
        tex.interpolation = "Linear" if node.op == "lut" else "Closest"
        tex.extension = "EXTEND"
        w.links.new(uv.outputs[0], tex.inputs["Vector"])
        sep = w.new("ShaderNodeSeparateColor", node, "channels")
        w.links.new(tex.outputs["Color"], sep.inputs[0])
        w.textures[key] = (tex, sep)
    tex, sep = w.textures[key]
    return tex.outputs["Alpha"] if channel == 3 else sep.outputs[channel]


def _emit_call(w, node):
    fn = node.graph.functions[node.attr("function")]
    bn = w.new("ShaderNodeGroup", node, fn.name)
    bn.node_tree = w.emitter.function_group(fn)
    bn.width = 200
    for (name, _), a in zip(fn.inputs, node.args):
        w.feed(bn.inputs[name], a)
    w.calls[node.id] = bn
    return None


def _emit_output(w, node):
    return w.calls[node.args[0].id].outputs[node.attr("name")]


#: IR operation -> function(writer, node) -> the output socket that carries the node's value.
EMITTERS = {
    **dict.fromkeys(MATH_OPS, _emit_math),
    **dict.fromkeys(VECTOR_OPS, _emit_vector),
    **dict.fromkeys(MIX_SOCKETS, _emit_select),
    **dict.fromkeys(_COMPONENTS, _emit_component),
    "combine": _emit_combine,
    "lut": _emit_table_read,
    "texel": _emit_table_read,
    "call": _emit_call,
    "output": _emit_output,
}


class _Emitter:
    """Materialises IR graphs as node trees; shares one group per function (by structure key)."""

    def __init__(self, tables=None):
        self.tables = tables if tables is not None else LutSet.from_folder()
        self.groups = {}          # Function.key -> node tree ensured in this build

    def image(self, table_name):
        return lut_image(resolve(self.tables, table_name))

    # -- functions ---------------------------------------------------------------------------
    def function_group(self, fn):
        ng = self.groups.get(fn.key)
        if ng is not None:
            return ng
        stamp = f"{EMITTER_VERSION}:{fn.key}"
        ng = bpy.data.node_groups.get(fn.name)
        if ng is None or ng.bl_idname != "ShaderNodeTree":
            ng = bpy.data.node_groups.new(fn.name, "ShaderNodeTree")
        elif ng.get(STAMP_KEY) == stamp:
            self._ensure_nested(fn)
            self.groups[fn.key] = ng
            return ng
        else:
            before_rebuild(ng)        # a light sync under way keeps a copy (common.node_groups_kept_on_error)
            ng.nodes.clear()
        self.fill(ng, fn.outputs, [n for n, _ in fn.inputs], fn.sockets,
                  {n: k for n, k in fn.inputs}, description=fn.description)
        ng[STAMP_KEY] = stamp
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
             shader_sums=None, aov_outputs=None, probe_attribute=None):
        """Emit ``outputs`` (name -> Expr of one graph) into the empty tree ``ng``.

        ``input_names``: interface inputs, in order; ``sockets``: (inputs, outputs), each
        name -> interface.Socket; ``internal_inputs``: graph input name -> callable(nodes, links) giving
        an output socket inside the tree (e.g. Geometry > Position) instead of an interface input.
        ``shader_sums``: shader output name -> names of colour outputs; each becomes an Emission
        closure (strength 1) and they are summed with Add Shader nodes; those colour outputs are
        not interface sockets.  ``aov_outputs``: colour output name (or a tuple of them, summed) -> Shader AOV
        name; each such output also feeds a Shader AOV node (Cycles writes it where the view layer declares the
        AOV, and drops the node where none does: addon/shadows.py reads each light's radiance this way).
        ``probe_attribute``: a view layer attribute; each shader output becomes Mix Shader(its sum, a white Diffuse
        BSDF) by it (EEVEE shadows' probe layer, addon/shadows.py).
        """
        in_sockets, out_sockets = sockets or ({}, {})
        kinds, internal_inputs, shader_sums = kinds or {}, internal_inputs or {}, shader_sums or {}
        outs = list(outputs.items())
        graph = next((e.graph for _, e in outs if isinstance(e, Expr)), None)
        if graph is None or any(not isinstance(e, Expr) or e.graph is not graph for _, e in outs):
            raise ValueError("all outputs must be expressions of one graph")
        order = topological_order([e for _, e in outs])
        inputs = {n.attr("name"): n for n in order if n.op in ("input", "vinput")}
        missing = set(inputs) - set(input_names) - set(internal_inputs)
        if missing:
            raise ValueError(f"inputs lack graph inputs {sorted(missing)}")

        ng.description = description
        hidden = {n for names in shader_sums.values() for n in names}
        wanted = [(name, "OUTPUT", "shader", out_sockets.get(name)) for name in shader_sums]
        wanted += [(out_name, "OUTPUT", expr.kind, out_sockets.get(out_name)) for out_name, expr in outs
                   if out_name not in hidden]
        wanted += [(n, "INPUT", inputs[n].kind if n in inputs else kinds.get(n, FLOAT), in_sockets.get(n))
                   for n in input_names]
        items = ensure_interface(ng, wanted)

        writer = _TreeWriter(self, ng, order)
        group_in = ng.nodes.new("NodeGroupInput")
        writer.place(group_in, 0, "inputs")
        group_in.width = 140
        for n in input_names:
            if n in inputs:
                writer.produced[inputs[n].id] = socket_by_identifier(group_in.outputs, items[(n, "INPUT")].identifier)
        for n, make_socket in internal_inputs.items():
            if n in inputs:
                writer.produced[inputs[n].id] = make_socket(ng.nodes, ng.links)
        for node in order:
            if node.op not in LEAVES:
                writer.write(node)
        self._write_outputs(ng, writer, outs, items, shader_sums, hidden, probe_attribute)
        self._write_aovs(ng, writer, dict(outs), aov_outputs or {})
        return ng

    @staticmethod
    def _write_aovs(ng, writer, outputs, aov_outputs):
        """One Shader AOV node per entry of ``aov_outputs`` (output name, or a tuple of colour output names summed by
        Vector Math Add nodes, -> AOV name) whose value is not 0."""
        max_depth = max(writer.depth.values()) if writer.depth else 0
        for row, (out_names, aov_name) in enumerate(aov_outputs.items()):
            names = (out_names,) if isinstance(out_names, str) else tuple(out_names)
            exprs = [outputs[n] for n in names if not (outputs[n].is_const and not any(outputs[n].attr("value")))]
            if not exprs:
                continue                          # an AOV never written reads 0
            x, y = (max_depth + 3) * COLUMN_WIDTH, -(row + 2) * ROW_HEIGHT
            aov = ng.nodes.new("ShaderNodeOutputAOV")
            aov.aov_name = aov_name
            aov.label = f"AOV {aov_name}"
            aov.location = (x, y)
            target = aov.inputs["Color"]
            for expr in reversed(exprs[1:]):      # (((e0 + e1) + e2) + ...), built from the AOV back
                add = ng.nodes.new("ShaderNodeVectorMath")
                add.operation = "ADD"
                add.location = (x - COLUMN_WIDTH, y)
                ng.links.new(add.outputs["Vector"], target)
                writer.feed(add.inputs[1], expr)
                target = add.inputs[0]
            writer.feed(target, exprs[0])

    def _write_outputs(self, ng, writer, outs, items, shader_sums, hidden, probe_attribute=None):
        """The Group Output node: Emission closures summed per shader output, then the plain outputs."""
        max_depth = max(writer.depth.values()) if writer.depth else 0
        outputs = dict(outs)
        group_out = ng.nodes.new("NodeGroupOutput")
        writer.place(group_out, max_depth + 1, "outputs")
        for row, (shader_name, parts) in enumerate(shader_sums.items()):
            total = None
            for i, part in enumerate(parts):
                expr = outputs[part]
                if expr.is_const and not any(expr.attr("value")):
                    continue                      # a closure of zero emission adds nothing
                emission = ng.nodes.new("ShaderNodeEmission")
                emission.label = part
                emission.location = ((max_depth + 1) * COLUMN_WIDTH, -(row + i) * ROW_HEIGHT)
                emission.inputs["Strength"].default_value = 1.0
                writer.feed(emission.inputs["Color"], expr)
                if total is None:
                    total = emission.outputs[0]
                    continue
                add = ng.nodes.new("ShaderNodeAddShader")
                add.location = ((max_depth + 2) * COLUMN_WIDTH, -(row + i) * ROW_HEIGHT)
                ng.links.new(total, add.inputs[0])
                ng.links.new(emission.outputs[0], add.inputs[1])
                total = add.outputs[0]
            if total is not None and probe_attribute:
                total = _probe_switch(ng, total, probe_attribute, ((max_depth + 2) * COLUMN_WIDTH, -row * ROW_HEIGHT))
            if total is not None:
                ng.links.new(total, socket_by_identifier(group_out.inputs, items[(shader_name, "OUTPUT")].identifier))
        group_out.location = ((max_depth + 3) * COLUMN_WIDTH, 0.0)
        for out_name, expr in outs:
            if out_name in hidden:
                continue
            item = items[(out_name, "OUTPUT")]
            sock = socket_by_identifier(group_out.inputs, item.identifier)
            if expr.is_const:
                sock.default_value = _socket_value(sock, expr.attr("value"))
                item.default_value = _socket_value(sock, expr.attr("value"))
            else:
                ng.links.new(writer.produced[expr.id], sock)


def _probe_switch(ng, shader, attribute, location):
    """Mix Shader(``shader``, a white Diffuse BSDF) with the factor of the View Layer attribute ``attribute`` (0 where
    the view layer has no such property); returns its output."""
    x, y = location
    fac = ng.nodes.new("ShaderNodeAttribute")
    fac.attribute_type = "VIEW_LAYER"
    fac.attribute_name = fac.label = attribute
    diffuse = ng.nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    mix = ng.nodes.new("ShaderNodeMixShader")
    fac.location, diffuse.location, mix.location = (x, y + 300.0), (x, y - 300.0), (x + COLUMN_WIDTH, y)
    ng.links.new(fac.outputs["Fac"], mix.inputs["Fac"])
    ng.links.new(shader, mix.inputs[1])
    ng.links.new(diffuse.outputs[0], mix.inputs[2])
    return mix.outputs[0]


def build_node_group(name, outputs, input_order=None, tables=None):
    """Build a new ShaderNodeTree group computing ``outputs`` (dict output name -> Expr of one Graph).

    Group inputs are the graph's ``input``/``vinput`` nodes in ``input_order`` (default: sorted
    names); group outputs are the dict's keys, in dict order.  ``lut`` / ``texel`` operations become
    one Image Texture per table and coordinate pair, with one Separate Color; function calls become
    Group nodes of their (shared, stamped) groups.  ``tables``: the table set (default: the shipped
    LUTs)."""
    if not outputs:
        raise ValueError("a node group needs at least one output")
    first = next(iter(outputs.values()))
    if not isinstance(first, Expr):
        raise ValueError("all outputs must be expressions of one graph")
    order = topological_order(list(outputs.values()))
    names = list(input_order) if input_order is not None else sorted(
        n.attr("name") for n in order if n.op in ("input", "vinput"))
    ng = bpy.data.node_groups.new(name, "ShaderNodeTree")
    _Emitter(tables).fill(ng, outputs, names)
    return ng


def ensure_function_group(function, tables=None):
    """The node group of a NodeFunction / expr.Function, built only when missing or when its
    stamp (emitter version + structure hash) differs; rebuilt in place, so materials keep it."""
    fn = getattr(function, "function", function)
    return _Emitter(tables).function_group(fn)


def ensure_tree(name, function, interface_inputs, sockets=None, internal_inputs=None, stamp_extra="", tables=None,
                shader_sums=None, aov_outputs=None, probe_attribute=None):
    """A named group computing the traced ``function`` (an ``expr.Function``): ``interface_inputs`` become
    its interface (described by ``sockets``, (inputs, outputs) name -> Socket, default the function's),
    the other inputs are produced inside the tree (``internal_inputs``: name -> callable(nodes, links)
    giving a socket).  ``shader_sums``, ``aov_outputs`` and ``probe_attribute``: as ``_Emitter.fill``.  Rebuilt only when the function's
    structure, ``stamp_extra`` or the AOVs change; returns (group, rebuilt)."""
    if not isinstance(function, Function):
        raise TypeError("ensure_tree emits a traced expr.Function")
    stamp = f"{EMITTER_VERSION}:{function.key}:{sorted(interface_inputs)}:{stamp_extra}:{shader_sums!r}"
    if aov_outputs:
        stamp += f":aovs {sorted(aov_outputs.items(), key=lambda item: str(item[0]))!r}"
    if probe_attribute:
        stamp += f":probe {probe_attribute}"
    ng = bpy.data.node_groups.get(name)
    if ng is not None and ng.get(STAMP_KEY) == stamp:
        return ng, False
    in_use = ng
    if in_use is None:
        ng = bpy.data.node_groups.new(name, "ShaderNodeTree")
    else:
        # rebuilt in a copy no tree uses, then swapped in (``replace_group``): each edit of a group in use is
        # propagated to the trees and materials that use it, which made a 100-light sync take minutes
        before_rebuild(in_use)
        ng = in_use.copy()
        ng.nodes.clear()
    try:
        _Emitter(tables).fill(ng, function.outputs, list(interface_inputs), sockets or function.sockets,
                              internal_inputs=internal_inputs, description=function.description, shader_sums=shader_sums,
                              aov_outputs=aov_outputs, probe_attribute=probe_attribute)
    except BaseException:
        if in_use is not None:          # the group in use stays as it was
            bpy.data.node_groups.remove(ng)
        raise
    ng[STAMP_KEY] = stamp
    if in_use is not None:
        replace_group(in_use, ng)
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
