"""Run emitted GLSL on the machine's OpenGL 4.5 (headless EGL: Mesa's llvmpipe on a CPU machine).

``GlslRunner.evaluate(module, inputs, tables)`` draws one full-screen triangle over an H x W float
framebuffer: the fragment at pixel (i, j) reads the inputs of the module's entry function at texel (i, j)
of one RGBA32F texture array (``texelFetch``: no filtering; every input packed as scalars, four per
layer, so a material's hundred inputs take one sampler), calls the function and writes its outputs to
colour attachments (RGBA32F; up to 8 per pass).  The result is what the GPU computes for every texel,
read back as float32 arrays shaped like the inputs, row 0 = texel row 0.

``available()`` says, once per process, whether a context can be made here (moderngl with glcontext's
EGL backend, pinned; Debian's libegl1 and the Mesa drivers).
"""
from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from ...core.ir.expr import FLOAT
from . import grids
from ...core.ir import shader_text
from ...core.ir.numpy_backend import evaluate

_STATE = {}
MAX_TARGETS = 8

_VERTEX = """#version 450 core
void main()
{
    vec2 p = vec2(float((gl_VertexID << 1) & 2), float(gl_VertexID & 2));
    gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
}
"""


def disable_shader_cache():
    """Turn off Mesa's on-disk shader cache (``~/.cache/mesa_shader_cache``) for this process, so compile
    times are real: with it, a program compiled by an earlier run "compiles" in milliseconds.  Effective
    only before the first context; returns whether it was in time."""
    if "context" in _STATE:
        return False
    os.environ["MESA_SHADER_CACHE_DISABLE"] = "true"
    os.environ["MESA_GLSL_CACHE_DISABLE"] = "true"          # the name before Mesa 22
    return True


def shader_cache_disabled():
    return os.environ.get("MESA_SHADER_CACHE_DISABLE", "").lower() in ("1", "true", "yes")


def available():
    """(True, renderer) when an OpenGL 4.5 context can be made headless here, else (False, why)."""
    if "available" not in _STATE:
        try:
            import moderngl

            ctx = moderngl.create_standalone_context(backend="egl", require=450)
            _STATE["available"] = (True, f"{ctx.info['GL_RENDERER']}, {ctx.info['GL_VERSION']}")
            _STATE["context"] = ctx
        except Exception as exc:       # no moderngl, no EGL, no driver: say which
            _STATE["available"] = (False, f"no headless OpenGL 4.5 context ({type(exc).__name__}: {exc})")
    return _STATE["available"]


def context():
    ok, why = available()
    if not ok:
        raise RuntimeError(why)
    return _STATE["context"]


class ShaderCompileError(RuntimeError):
    """The driver refused a shader; the message holds its log and the numbered source lines it names."""


def numbered(source):
    """``source`` with line numbers, as compile logs name them."""
    return "--- source ---\n" + "\n".join(f"{i + 1:5d}  {line}" for i, line in enumerate(source.splitlines()))


def compile_program(ctx, fragment_source):
    try:
        return ctx.program(vertex_shader=_VERTEX, fragment_shader=fragment_source)
    except Exception as exc:
        raise ShaderCompileError(f"the driver ({available()[1]}) refused the shader: {exc}\n"
                                 + numbered(fragment_source)) from exc


def texture(ctx, array):
    """An RGBA32F (or 1-3 channel) texture of ``array`` (H, W[, C]), row 0 first, nearest filtering."""
    a = np.asarray(array, np.float32)
    h, w = a.shape[:2]
    comps = 1 if a.ndim == 2 else a.shape[2]
    tex = ctx.texture((w, h), comps, data=np.ascontiguousarray(a).tobytes(), dtype="f4")
    tex.filter = (ctx.NEAREST, ctx.NEAREST)
    return tex


def input_slots(module):
    """[(input index, component count, first scalar slot)] for ``module.entry``'s inputs: all inputs are
    packed as scalars, four per RGBA layer of one texture array (slot s: layer s // 4, channel s % 4)."""
    slots, at = [], 0
    for k, (_, _, kind) in enumerate(module.entry.inputs):
        count = 1 if kind == FLOAT else 3
        slots.append((k, count, at))
        at += count
    return slots, at


def pack_inputs(module, inputs, h, w):
    """The inputs as one (layers, H, W, 4) float32 array (``input_slots``)."""
    slots, total = input_slots(module)
    packed = np.zeros((max(1, -(-total // 4)) * 4, h, w), np.float32)
    for (k, count, at), (name, _, kind) in zip(slots, module.entry.inputs):
        a = np.asarray(inputs[name], np.float32)
        a = np.broadcast_to(a, (h, w) + ((3,) if kind != FLOAT else ()))
        packed[at:at + count] = a[None] if count == 1 else np.moveaxis(a, -1, 0)
    return np.ascontiguousarray(packed.reshape(-1, 4, h, w).transpose(0, 2, 3, 1))


def fragment_source(module, outputs):
    """The fragment shader that evaluates ``module.entry`` per texel and writes ``outputs`` (names)."""
    entry = module.entry
    slots, total = input_slots(module)
    layers = max(1, -(-total // 4))
    lines = [module.source, "", "uniform sampler2DArray rtl_inputs;   // the inputs, four scalars per layer"]
    targets = [o for o in entry.outputs if o[0] in outputs]
    for k, (name, ident, kind) in enumerate(targets):
        lines.append(f"layout(location = {k}) out vec4 rtl_out_{k};   // {name}")
    lines += ["", "void main()", "{", "    ivec2 p = ivec2(gl_FragCoord.xy);"]
    lines += [f"    vec4 l{i} = texelFetch(rtl_inputs, ivec3(p, {i}), 0);" for i in range(layers)]
    scalar = lambda s: f"l{s // 4}.{'xyzw'[s % 4]}"
    args = []
    for (k, count, at), (name, ident, kind) in zip(slots, entry.inputs):
        value = scalar(at) if count == 1 else f"vec3({', '.join(scalar(at + c) for c in range(3))})"
        lines.append(f"    {'float' if kind == FLOAT else 'vec3'} a{k} = {value};   // {name}")
        args.append(f"a{k}")
    for k, (name, ident, kind) in enumerate(entry.outputs):
        lines.append(f"    {'float' if kind == FLOAT else 'vec3'} r{k};")
        args.append(f"r{k}")
    lines.append(f"    {entry.ident}({', '.join(args)});")
    index = {o[0]: k for k, o in enumerate(entry.outputs)}
    for k, (name, ident, kind) in enumerate(targets):
        value = f"vec4(r{index[name]}, 0.0, 0.0, 1.0)" if kind == FLOAT else f"vec4(r{index[name]}, 1.0)"
        lines.append(f"    rtl_out_{k} = {value};")
    lines.append("}")
    return "\n".join(lines) + "\n"


class GlslRunner:
    """Evaluates emitted GLSL 4.50 modules on the GPU (or llvmpipe), texel by texel."""

    def __init__(self):
        self.ctx = context()

    def evaluate(self, module, inputs, tables=None, outputs=None):
        """{output name -> float32 array} of ``module.entry`` for ``inputs`` (its input names -> arrays
        (H, W) for floats, (H, W, 3) for vectors; all the same H, W) reading ``tables`` (name -> Table with
        data) for the module's textures."""
        entry = module.entry
        names = [o[0] for o in entry.outputs] if outputs is None else list(outputs)
        shape = None
        for name, _, _ in entry.inputs:
            a = np.asarray(inputs[name])
            shape = a.shape[:2] if shape is None else shape
        h, w = shape
        results = {}
        for start in range(0, len(names), MAX_TARGETS):
            chunk = names[start:start + MAX_TARGETS]
            results.update(self._pass(module, inputs, tables, chunk, h, w))
        return results

    def _pass(self, module, inputs, tables, chunk, h, w):
        ctx = self.ctx
        program = compile_program(ctx, fragment_source(module, chunk))
        packed = pack_inputs(module, inputs, h, w)
        array = ctx.texture_array((w, h, packed.shape[0]), 4, data=packed.tobytes(), dtype="f4")
        array.filter = (ctx.NEAREST, ctx.NEAREST)
        keep = [array]
        array.use(0)
        if "rtl_inputs" in program:
            program["rtl_inputs"] = 0
        unit = 1
        for table, (sampler, th, tw) in module.tables.items():
            if tables is None or table not in tables:
                raise KeyError(f"the shader reads table {table!r}: pass it in tables=")
            data = tables[table].require_data()
            if data.shape[:2] != (th, tw):
                raise ValueError(f"table {table!r} is {data.shape[:2]}, the shader was emitted for {(th, tw)}")
            tex = texture(ctx, data)
            keep.append(tex)
            if sampler in program:
                tex.use(unit)
                program[sampler] = unit
            unit += 1
        targets = [ctx.texture((w, h), 4, dtype="f4") for _ in chunk]
        fbo = ctx.framebuffer(color_attachments=targets)
        fbo.use()
        ctx.viewport = (0, 0, w, h)
        vao = ctx.vertex_array(program, [])
        vao.render(mode=ctx.TRIANGLES, vertices=3)
        ctx.finish()
        out = {}
        kinds = {o[0]: o[2] for o in module.entry.outputs}
        for k, name in enumerate(chunk):
            raw = np.frombuffer(fbo.read(components=4, attachment=k, dtype="f4"), np.float32).reshape(h, w, 4)
            out[name] = raw[..., 0].copy() if kinds[name] == FLOAT else raw[..., :3].copy()
        for obj in keep + targets + [fbo, vao, program]:
            obj.release()
        return out


# --- GLSL against the numpy backend -----------------------------------------------------------------

#: The backend's targets (issue 13): relative where |numpy| >= NEAR_ZERO, absolute below.
RTOL = 1e-5
ATOL = 1e-7
NEAR_ZERO = grids.NEAR_ZERO
#: A texel is ill-conditioned where numpy's own float32 evaluation is farther than this share of the
#: tolerance from its float64 evaluation, or where float64 moves that far when the float32 inputs move by one ulp:
#: there float32 rounding (one ulp of an arccosine, a cancelling sum, an input) is amplified by the function itself,
#: and two correct float32 backends may differ by more than the tolerance.  The second test catches texels where
#: numpy float32 lands near float64 by chance: a disk light whose rim passes 0.09 of its distance from the point,
#: nearly edge-on, crossing the horizon has a clipped form factor 177x as sensitive as its inputs (numpy float32
#: 6e-7 from float64 there, GLSL 2.9e-5, one ulp of the inputs up to 1.8e-5).
ILL_CONDITIONED = 0.1


def deviation(got, ref):
    """(max relative error where |ref| >= NEAR_ZERO, max absolute error elsewhere)."""
    return grids.max_deviation(got, ref, NEAR_ZERO)


def _tolerance_units(got, ref):
    """|got - ref| in units of the tolerance (RTOL |ref| where |ref| >= NEAR_ZERO, ATOL below)."""
    got, ref = np.asarray(got, np.float64), np.asarray(ref, np.float64)
    scale = np.where(np.abs(ref) >= NEAR_ZERO, RTOL * np.abs(ref), ATOL)
    return np.abs(got - ref) / scale


@dataclass
class Conformance:
    """One output of a function, GLSL against numpy.

    ``rel`` / ``abs``: the plain maxima against numpy float32 (relative where |numpy| >= NEAR_ZERO, absolute
    below), over all texels; ``rel_conditioned`` / ``abs_conditioned`` the same over well-conditioned
    texels; ``ill_conditioned``: how many texels are not (numpy float32 vs float64, or float64 vs float64 at the inputs one
    ulp apart, beyond ``ILL_CONDITIONED`` of the tolerance); ``ill_ratio``: at those texels, the largest (GLSL's
    distance to float64) / (the larger of those two distances + the tolerance)."""
    rel: float
    abs: float
    rel_conditioned: float
    abs_conditioned: float
    ill_conditioned: int
    ill_ratio: float
    texels: int
    finite: bool

    @property
    def ok(self):
        """Finite; within the tolerance of numpy float32 where the function is well conditioned; elsewhere
        no farther from float64 than twice numpy float32 (plus the tolerance)."""
        return (self.finite and self.rel_conditioned <= RTOL and self.abs_conditioned <= ATOL
                and self.ill_ratio <= 2.0)

    def summary(self):
        return (f"max rel {self.rel:.3g}, max abs near zero {self.abs:.3g}; well-conditioned: {self.rel_conditioned:.3g} / "
                f"{self.abs_conditioned:.3g}; {self.ill_conditioned} of {self.texels} ill-conditioned "
                f"(ratio {self.ill_ratio:.3g})")


def one_ulp_apart(values, seed=0):
    """``values`` (name -> array) as float32, each element moved one ulp up or down (seeded)."""
    rng = np.random.default_rng(seed)
    moved = {}
    for name, array in values.items():
        array = np.asarray(array, np.float32)
        moved[name] = np.nextafter(array, np.where(rng.random(array.shape) < 0.5, -np.inf, np.inf).astype(np.float32))
    return moved


def conformance(got, ref32, ref64, ref64_moved=None):
    """``Conformance`` of the GLSL values ``got`` against numpy's float32 and float64 evaluations;
    ``ref64_moved``: float64 at the inputs one ulp apart (``one_ulp_apart``), where known."""
    got = np.asarray(got, np.float64)
    ref32, ref64 = (np.broadcast_to(np.asarray(r, np.float64), got.shape) for r in (ref32, ref64))
    finite = bool(np.isfinite(got).all())
    rel, absolute = deviation(got, ref32)
    own = _tolerance_units(ref32, ref64)
    if ref64_moved is not None:
        own = np.maximum(own, _tolerance_units(np.broadcast_to(np.asarray(ref64_moved, np.float64), got.shape), ref64))
    ill = own > ILL_CONDITIONED
    well_rel, well_abs = deviation(got[~ill], ref32[~ill]) if (~ill).any() else (0.0, 0.0)
    ratio = float((_tolerance_units(got[ill], ref64[ill]) / (own[ill] + 1.0)).max()) if ill.any() else 0.0
    return Conformance(rel, absolute, well_rel, well_abs, int(ill.sum()), ratio, int(got.size), finite)


def compare_function(function, values, tables=None, runner=None, precise=True):
    """Emit ``function`` (a NodeFunction or expr.Function) as GLSL 4.50, evaluate it per texel on the GPU
    and with the numpy backend (float32 and float64) for ``values`` (input name -> (H, W) or (H, W, 3)),
    reading ``tables``.  Returns {output: Conformance}."""
    fn = getattr(function, "function", function)
    module = shader_text.emit(fn, "glsl450", precise=precise)
    vals = {name: np.asarray(values[name], np.float32) for name, _ in fn.inputs}
    got = (runner or GlslRunner()).evaluate(module, vals, tables)
    names = [n for n, e in fn.outputs.items() if not e.is_const]
    exprs = tuple(fn.outputs[n] for n in names)
    refs32 = evaluate(exprs, vals, np.float32, tables)
    refs64 = evaluate(exprs, vals, np.float64, tables)
    moved64 = evaluate(exprs, one_ulp_apart(vals), np.float64, tables)
    return {name: conformance(got[name], r32, r64, m64)
            for name, r32, r64, m64 in zip(names, refs32, refs64, moved64)}
