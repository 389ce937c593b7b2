"""Emit traced functions as shader source: the real-time backend (GLSL 4.50, GLSL ES 3.00, HLSL SM 5).

Every node function of a traced graph becomes one function of the target language, called where the
IR calls it (not inlined), its outputs ``out`` parameters; constants are the graph's (already folded,
float32); each operation is written from its ``text`` in the one table of semantics
(``semantics.OPERATIONS``), and the guarded rules (safe divide, Cycles' power, inverse sqrt and log2 of
non-positive numbers, clamped acos/asin, normalize of a zero vector, the texel index) are the helpers
``semantics.SHADER_HELPERS``, emitted once at the top.

Tables: each table the graph reads is a texture of 32-bit float RGBA texels, rows in table order (row 0
is v = 0, as ``core.ir.semantics.texel_fetch`` reads it), read with exact texel fetches
(``rtl_texel_<table>``: the texel holding (u, v), EXTEND); bilinear filtering is the IR's own
``RTL LUT <table>`` function of four fetches, exactly as the node groups do it.  No sampler state,
filtering or mipmaps are involved, so GLSL and HLSL read what numpy reads.

``emit(function, dialect)`` returns a ``ShaderModule``: the source and, for the caller that writes the
entry point, each emitted function's identifier and parameters, and each table's texture name and size.
"""
from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from .expr import CALL, FLOAT, VECTOR, topological_order
from .semantics import OPERATIONS, SHADER_HELPERS, TABLE_READS


@dataclass(frozen=True)
class Dialect:
    """What differs between the target languages: version header, type and function names, textures."""
    name: str
    header: str
    vec3: str
    vec4: str
    atan2: str
    inversesqrt: str
    texture_declaration: str        # {name}
    fetch: str                      # {texture}, {i}, {j}
    sign_bit: str                   # a function bool(float): the sign bit is set (-0.0 included)
    precise: bool                   # has the ``precise`` qualifier (no fused or reordered arithmetic)

    def words(self):
        return {"vec3": self.vec3, "vec4": self.vec4, "atan2": self.atan2, "inversesqrt": self.inversesqrt,
                "sign_bit": self.sign_bit}


DIALECTS = {
    "glsl450": Dialect("glsl450", "#version 450 core\n", "vec3", "vec4", "atan", "inversesqrt",
                       "uniform sampler2D {name};", "texelFetch({texture}, ivec2({i}, {j}), 0)", "rtl_sign_bit", True),
    "glsl300es": Dialect("glsl300es", "#version 300 es\nprecision highp float;\nprecision highp int;\n"
                         "precision highp sampler2D;\n", "vec3", "vec4", "atan", "inversesqrt",
                         "uniform sampler2D {name};", "texelFetch({texture}, ivec2({i}, {j}), 0)", "rtl_sign_bit", False),
    "hlsl": Dialect("hlsl", "", "float3", "float4", "atan2", "rsqrt", "Texture2D<float4> {name};",
                    "{texture}.Load(int3({i}, {j}, 0))", "rtl_sign_bit", True),
}

#: Words no emitted identifier may be (GLSL and HLSL keywords and built-ins a parameter could hit).
_RESERVED = {"in", "out", "inout", "input", "output", "sample", "smooth", "flat", "line", "point", "texture",
             "filter", "common", "partition", "active", "precision", "half", "fixed", "matrix", "vector",
             "packed", "register", "linear", "centroid", "shared", "uniform", "const", "float", "int",
             "bool", "void", "discard", "return"}


def identifier(text, prefix=""):
    """A C identifier from a name: lower case, runs of other characters as "_"."""
    ident = re.sub(r"[^0-9a-zA-Z]+", "_", text).strip("_").lower() or "x"
    if ident[0].isdigit():
        ident = "n" + ident
    ident = prefix + ident
    return ident + "_" if ident in _RESERVED else ident


def literal(value):
    """A float32 constant as a shader literal that reads back to the same float32."""
    v = np.float32(value)
    if not np.isfinite(v):
        raise ValueError(f"constant {value!r} is not finite: guarded graphs hold none")
    text = str(v)
    if "e" not in text and "." not in text:
        text += ".0"
    if text.startswith("-"):
        text = "(" + text + ")"
    return text


@dataclass
class ShaderFunction:
    """An emitted function: its identifier and its parameters (IR name, identifier, kind), in order."""
    name: str
    ident: str
    inputs: list
    outputs: list


@dataclass
class ShaderModule:
    """Emitted source: helpers, table fetchers and functions (callees first); ``entry`` is the traced
    function given to ``emit``; ``tables``: table name -> (texture identifier, height, width)."""
    dialect: Dialect
    source: str
    entry: ShaderFunction
    functions: dict = field(default_factory=dict)
    tables: dict = field(default_factory=dict)


class _Emitter:
    def __init__(self, dialect, precise=True):
        self.d = dialect
        self.precise = "precise " if precise and dialect.precise else ""
        self.words = dialect.words()
        self.functions = {}            # Function.key -> ShaderFunction
        self.bodies = []               # emitted function texts, callees first
        self.tables = {}               # name -> (texture ident, h, w)
        self.linear = set()            # tables read with Linear filtering (the ``lut`` operation)
        self.names = set()

    def type_of(self, kind):
        return "float" if kind == FLOAT else self.d.vec3

    def fmt(self, template, *args):
        """``template`` with ``{0}``, ``{1}``, ... and the dialect's ``{word}``s replaced (plain replacement:
        helper bodies hold braces of their own)."""
        for word, text in self.words.items():
            template = template.replace("{" + word + "}", text)
        for i, arg in enumerate(args):
            template = template.replace("{" + str(i) + "}", arg)
        return template

    # -- tables ------------------------------------------------------------------------------------
    def table(self, graph, name):
        if name not in self.tables:
            ref = graph.tables.get(name)
            if ref is None:
                raise KeyError(f"table {name!r} is read but not described by its graph")
            self.tables[name] = (identifier(name, "rtl_tex_"), ref.height, ref.width)
        return self.tables[name]

    def fetcher(self, name):
        texture, h, w = self.tables[name]
        i = f"rtl_texel_index(u, {w})"
        j = f"rtl_texel_index(v, {h})"
        return (f"{self.d.vec4} rtl_texel_{identifier(name)}(float u, float v)\n{{\n"
                f"    return {self.d.fetch.format(texture=texture, i=i, j=j)};\n}}\n")

    # -- functions ---------------------------------------------------------------------------------
    def function(self, fn):
        """Emit ``fn`` (an expr.Function) and the functions it calls; returns its ShaderFunction."""
        done = self.functions.get(fn.key)
        if done is not None:
            return done
        for node in topological_order(list(fn.outputs.values())):
            if node.op == CALL:
                self.function(node.graph.functions[node.attr("function")])
        ident = identifier(fn.name, "" if fn.name.lower().startswith("rtl") else "rtl_")
        base, k = ident, 2
        while ident in self.names:
            ident, k = f"{base}_{k}", k + 1
        self.names.add(ident)
        inputs = [(name, identifier(name, "i_"), kind) for name, kind in fn.inputs]
        outputs = [(name, identifier(name, "o_"), expr.kind) for name, expr in fn.outputs.items()]
        sf = ShaderFunction(fn.name, ident, inputs, outputs)
        self.functions[fn.key] = sf
        self.bodies.append(self.body(fn, sf))
        return sf

    def body(self, fn, sf):
        params = [f"{self.type_of(kind)} {p}" for _, p, kind in sf.inputs]
        params += [f"out {self.type_of(kind)} {p}" for _, p, kind in sf.outputs]
        lines = [f"// {fn.name}" + (f": {fn.description}" if fn.description else ""),
                 f"void {sf.ident}({', '.join(params)})", "{"]
        value = {}
        args_of = {name: p for name, p, _ in sf.inputs}
        fetches = {}
        for node in topological_order(list(fn.outputs.values())):
            if node.op == "const":
                value[node.id] = literal(node.attr("value"))
            elif node.op == "vconst":
                value[node.id] = f"{self.d.vec3}({', '.join(literal(x) for x in node.attr('value'))})"
            elif node.op in ("input", "vinput"):
                value[node.id] = args_of[node.attr("name")]
            elif node.op == CALL:
                lines += self.call(node, value)
            elif node.op == "output":
                value[node.id] = value[(node.args[0].id, node.attr("name"))]
            elif node.op in TABLE_READS:
                lines += self.table_read(node, value, fetches)
            else:
                lines.append(self.operation(node, value))
        for name, oident, _ in sf.outputs:
            lines.append(f"    {oident} = {value[fn.outputs[name].id]};")
        lines.append("}")
        return "\n".join(lines) + "\n"

    def call(self, node, value):
        """The lines of a function call: one variable per output, then the call."""
        callee = self.functions[node.attr("function")]
        lines, outs = [], []
        for oname, oident, kind in callee.outputs:
            var = f"c{node.id}_{oident}"
            lines.append(f"    {self.type_of(kind)} {var};")
            outs.append(var)
            value[(node.id, oname)] = var
        args = [value[a.id] for a in node.args]
        lines.append(f"    {callee.ident}({', '.join(args + outs)});")
        return lines

    def table_read(self, node, value, fetches):
        """A table read: one fetch per (table, u, v) in this function, its channel taken from it."""
        name = node.attr("table")
        self.table(node.graph, name)
        if node.op == "lut":
            self.linear.add(name)
        key = (node.op, name, node.args[0].id, node.args[1].id)
        lines = []
        if key not in fetches:
            var = f"f{node.id}"
            u, v = (value[a.id] for a in node.args)
            reader = f"rtl_texel_{identifier(name)}" if node.op == "texel" else f"rtl_linear_{identifier(name)}"
            lines.append(f"    {self.d.vec4} {var} = {reader}({u}, {v});")
            fetches[key] = var
        value[node.id] = f"{fetches[key]}.{'xyzw'[node.attr('channel')]}"
        return lines

    def operation(self, node, value):
        """One operation, from its text in the table of semantics, into a temporary."""
        text = OPERATIONS[node.op].text
        if text is None:
            raise ValueError(f"no shader text for IR operation {node.op!r}")
        var = f"t{node.id}"
        value[node.id] = var
        expr = self.fmt(text, *(value[a.id] for a in node.args))
        return f"    {self.precise}{self.type_of(node.kind)} {var} = {expr};"

    # -- the module ----------------------------------------------------------------------------------
    def helpers(self):
        bits = "floatBitsToUint" if self.d.name.startswith("glsl") else "asuint"
        out = [f"bool rtl_sign_bit(float x)\n{{\n    return ({bits}(x) >> 31u) != 0u;\n}}\n"]
        for signature, body in SHADER_HELPERS.values():
            text = self.fmt(body)
            indented = "\n".join("    " + line for line in text.split("\n"))
            out.append(f"{self.fmt(signature)}\n{{\n{indented}\n}}\n")
        return out

    def linear_reader(self, name):
        """``lut`` (Linear filtering) as exact bilinear filtering of four fetches (semantics.sample_bilinear)."""
        _, h, w = self.tables[name]
        n = identifier(name)
        return (f"{self.d.vec4} rtl_linear_{n}(float u, float v)\n{{\n"
                f"    float x = clamp(u * {literal(w)} - 0.5, 0.0, {literal(w - 1)});\n"
                f"    float y = clamp(v * {literal(h)} - 0.5, 0.0, {literal(h - 1)});\n"
                f"    float x0 = min(floor(x), {literal(max(w - 2, 0))});\n"
                f"    float y0 = min(floor(y), {literal(max(h - 2, 0))});\n"
                f"    float fx = x - x0, fy = y - y0;\n"
                f"    float u0 = (x0 + 0.5) / {literal(w)}, u1 = (min(x0 + 1.0, {literal(w - 1)}) + 0.5) / {literal(w)};\n"
                f"    float v0 = (y0 + 0.5) / {literal(h)}, v1 = (min(y0 + 1.0, {literal(h - 1)}) + 0.5) / {literal(h)};\n"
                f"    return (rtl_texel_{n}(u0, v0) * (1.0 - fx) + rtl_texel_{n}(u1, v0) * fx) * (1.0 - fy)\n"
                f"         + (rtl_texel_{n}(u0, v1) * (1.0 - fx) + rtl_texel_{n}(u1, v1) * fx) * fy;\n}}\n")

    def module(self, entry):
        parts = [self.d.header, "// Emitted by RT Lookdev (core/ir/shader_text.py) from the traced shading functions.\n"]
        parts += ["// Node semantics (core/ir/semantics.py): the guarded rules.\n"] + self.helpers()
        if self.tables:
            parts.append("// Tables: RGBA32F textures, row 0 at v = 0, read with exact texel fetches.\n")
            parts += [self.d.texture_declaration.format(name=t) + "\n" for t, _, _ in self.tables.values()]
            parts += [self.fetcher(name) for name in self.tables]
            parts += [self.linear_reader(name) for name in self.tables if name in self.linear]
        parts += self.bodies
        return "\n".join(parts)


def emit(function, dialect="glsl450", precise=True):
    """Emit the traced ``function`` (an ``expr.Function``, or a NodeFunction) and everything it calls.
    ``precise``: every temporary is ``precise`` where the dialect has the qualifier (not GLSL ES 3.00), so
    the compiler neither fuses multiply-adds nor reorders products: the arithmetic of the numpy backend."""
    fn = getattr(function, "function", function)
    d = DIALECTS[dialect] if isinstance(dialect, str) else dialect
    em = _Emitter(d, precise)
    entry = em.function(fn)
    return ShaderModule(d, em.module(entry), entry, {sf.name: sf for sf in em.functions.values()}, dict(em.tables))


def emit_library(functions, dialect="glsl450", precise=True, title=None):
    """Emit several traced functions (and everything they call) as one include file: no version or
    precision header (the including shader has its own) and no entry point.  Returns a ShaderModule
    whose ``entry`` is the last function given."""
    d = DIALECTS[dialect] if isinstance(dialect, str) else dialect
    em = _Emitter(d, precise)
    entries = [em.function(getattr(f, "function", f)) for f in functions]
    source = em.module(entries[-1])[len(d.header):]
    if title:
        source = f"// {title}\n" + source
    return ShaderModule(d, source, entries[-1], {sf.name: sf for sf in em.functions.values()}, dict(em.tables))


def kinds_glsl(kind, dialect):
    """The type of an IR kind in ``dialect`` ("float", "vec3"/"float3")."""
    d = DIALECTS[dialect] if isinstance(dialect, str) else dialect
    return "float" if kind == FLOAT else (d.vec3 if kind == VECTOR else kind)


def probe_entry(module):
    """A fragment entry point for ``module`` on its own: each input of its entry function a uniform
    (``p_<input>``), the outputs summed into the one colour output.  What an engine's own entry point
    does with the material's interface (core/materials/rt_lit_shader.py); here it lets a single function
    be compiled and linked by itself (tests/glsl/test_shader_compile.py)."""
    d, entry = module.dialect, module.entry
    hlsl = d.name == "hlsl"
    lines = [f"{'' if hlsl else 'uniform '}{kinds_glsl(kind, d)} p_{ident};   // {name}"
             for name, ident, kind in entry.inputs]
    body = [f"    {kinds_glsl(kind, d)} r_{ident};" for _, ident, kind in entry.outputs]
    args = [f"p_{ident}" for _, ident, _ in entry.inputs] + [f"r_{ident}" for _, ident, _ in entry.outputs]
    body.append(f"    {entry.ident}({', '.join(args)});")
    total = " + ".join(f"r_{ident}" if kind == FLOAT else f"dot(r_{ident}, {d.vec3}(1.0, 1.0, 1.0))"
                       for _, ident, kind in entry.outputs) or "0.0"
    if hlsl:
        main = ["float4 main() : SV_Target", "{", *body, f"    return {d.vec4}({total}, 0.0, 0.0, 1.0);", "}"]
    else:
        lines.append("layout(location = 0) out vec4 p_result;")
        main = ["void main()", "{", *body, f"    p_result = vec4({total}, 0.0, 0.0, 1.0);", "}"]
    return module.source + "\n" + "\n".join(lines + [""] + main) + "\n"
