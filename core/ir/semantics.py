"""The one table of semantics: what every IR operation computes, including where it is guarded.

Blender's shader nodes are not plain IEEE math: Cycles' Math node (``kernel/svm/math_util.h``,
float32) returns 0 for a zero divisor, for the square root of a negative, for the logarithm of a
non-positive number; it clamps the input of arccosine and arcsine; Vector Math Normalize of a zero
vector is zero.  EEVEE's GLSL (``gpu_shader_common_math.glsl``) agrees once the shading code guards
its inputs (see the notes below and docs/blender.md, "Node semantics").  Every backend computes
exactly these rules, from this module:

* the numpy backend (``numpy_backend``) and the numpy path of ``core.shading_ops`` call the
  functions named in ``OPERATIONS``;
* constant folding (``expr``) evaluates folded operations with the same functions;
* the node-group backend maps each operation to the Blender node that has these semantics (and the
  tests measure that it does: tests/blender/test_node_conformance.py).

Where Cycles and EEVEE differ, the shading code supplies the guard that makes them agree:

==================  ======================================  ==============================
operation           Cycles                                  EEVEE
==================  ======================================  ==============================
a / b               0 when b == 0                           0 when b == 0
sqrt(a)             sqrt(max(a, 0))                         a > 0 ? sqrt(a) : 0
inversesqrt(a)      a > 0 ? 1/sqrt(a) : 0                   unguarded  -> callers pass max(a, eps)
acos(a), asin(a)    input clamped to [-1, 1]                0 outside [-1, 1] -> callers clamp
pow(a, b)           0 for a < 0 and fractional b            same
log(a, base)        0 for a <= 0                            same
normalize(v)        zero vector for |v| = 0                 same (5.0 GLSL checks the length)
==================  ======================================  ==============================

An entry of ``OPERATIONS``: argument kinds, result kind, the numpy function (``None`` for structural
operations the backends handle themselves) and a one-line statement of the rule.  ``texel_index`` and
``sample_bilinear`` state how a table is read (texel centres, EXTEND): the rule of Cycles' Image
Texture node with Closest / Linear interpolation.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

FLOAT, VECTOR = "float", "vector"
CALL = "call"   # the kind of a function-call node; its outputs are "output" nodes


# --- guarded scalar rules ---------------------------------------------------------------------------

def float_dtype(*values):
    """The float dtype an operation on ``values`` computes in, the same under numpy 1 and 2: arrays keep
    their float dtype (integer and boolean ones count as float64); Python numbers, numpy scalars and 0-d
    arrays are weak (they take the arrays' dtype, as numpy 1's value-based casting gave and as NEP 50 gives
    numpy 2 only for Python numbers); values that are all weak give float64, or their own float dtype."""
    arrays = []
    for v in values:
        if isinstance(v, (bool, int, float)):
            continue
        a = np.asarray(v)
        arrays.append(a if a.dtype.kind == "f" else a.astype(np.float64))
    shaped = [a for a in arrays if a.ndim > 0]
    if shaped:
        return np.result_type(*shaped)
    return np.result_type(*arrays) if arrays else np.dtype(np.float64)


def as_floats(*values):
    """``values`` as numpy arrays of one float dtype (``float_dtype``)."""
    dtype = float_dtype(*values)
    return [np.asarray(v, dtype=dtype) for v in values]


_floats = as_floats


def divide(a, b):
    """a / b, and 0 where b == 0 (Cycles ``safe_divide``)."""
    a, b = np.broadcast_arrays(*_floats(a, b))
    out = np.zeros(a.shape, dtype=a.dtype)
    np.divide(a, b, out=out, where=(b != 0))
    return out


def power(a, b):
    """a ** b, and 0 for a negative base with a fractional exponent or a zero base with a negative
    exponent (Cycles ``safe_powf``; the zero-base rule measured with Cycles 5.0.1)."""
    a, b = np.broadcast_arrays(*_floats(a, b))
    bad = ((a < 0) & (b != np.floor(b))) | ((a == 0) & (b < 0))
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        out = np.power(np.where(bad, 1.0, a).astype(a.dtype), b)
    return np.where(bad, 0.0, out).astype(a.dtype)


def sqrt(a):
    """sqrt(max(a, 0)) (Cycles ``safe_sqrtf``)."""
    (a,) = _floats(a)
    return np.sqrt(np.maximum(a, 0.0))


def _positive_only(f, a):
    """f(a) where a > 0, else 0."""
    (a,) = _floats(a)
    out = np.zeros(a.shape, dtype=a.dtype)
    with np.errstate(divide="ignore", invalid="ignore"):
        np.copyto(out, f(np.where(a > 0, a, 1).astype(a.dtype)), where=a > 0)
    return out


def inverse_sqrt(a):
    """1 / sqrt(a) for a > 0, else 0 (Cycles ``safe_inversesqrtf``; EEVEE is unguarded, so shading
    code passes max(a, eps) with eps > 0: ``shading_ops.inverse_sqrt``)."""
    return _positive_only(lambda x: 1.0 / np.sqrt(x), a)


def log2(a):
    """log2(a) for a > 0, else 0 (the Logarithm node with base 2; Cycles ``safe_logf``)."""
    return _positive_only(np.log2, a)


def arccosine(a):
    """acos of a clamped to [-1, 1] (Cycles ``safe_acosf``; EEVEE gives 0 outside, so the shading
    code clamps explicitly: ``shading_ops.acos``)."""
    (a,) = _floats(a)
    return np.arccos(np.clip(a, -1.0, 1.0))


def arcsine(a):
    """asin of a clamped to [-1, 1] (Cycles ``safe_asinf``)."""
    (a,) = _floats(a)
    return np.arcsin(np.clip(a, -1.0, 1.0))


def select(condition, if_true, if_false):
    """if_true where condition is non-zero (a Mix node with factor 0 or 1)."""
    return np.where(np.asarray(condition) != 0, if_true, if_false)


def vselect(condition, if_true, if_false):
    """select between vectors (last axis xyz)."""
    return np.where((np.asarray(condition) != 0)[..., None], if_true, if_false)


# --- vectors (last axis = xyz) ------------------------------------------------------------------------

def dot(a, b):
    return np.sum(a * b, axis=-1)


def length(v):
    return np.sqrt(dot(v, v))


def normalize(v):
    """v / |v|, and the zero vector where |v| == 0 (Cycles ``safe_normalize``; EEVEE 5.0 checks the
    length too)."""
    (v,) = _floats(v)
    n = length(v)[..., None]
    out = np.zeros(np.broadcast_shapes(v.shape, n.shape), dtype=v.dtype)
    np.divide(v, n, out=out, where=(n > 0))
    return out


def combine(x, y, z):
    return np.stack(np.broadcast_arrays(x, y, z), axis=-1)


def cross(a, b):
    return np.cross(*np.broadcast_arrays(a, b))


# --- tables -----------------------------------------------------------------------------------------

def texel_index(t, n):
    """Index of the texel holding texture coordinate t on an axis of n texels: floor(t n) clamped to
    [0, n - 1] (Image Texture, Closest, EXTEND; texel i covers [i/n, (i + 1)/n), centre (i + 0.5)/n).
    A NaN coordinate reads texel 0 (numpy would otherwise index with garbage)."""
    x = np.floor(np.asarray(t, np.float64) * n)
    return np.clip(np.where(np.isnan(x), 0.0, x), 0, n - 1).astype(np.int64)


def texel_fetch(table, u, v):
    """The texel of ``table`` (H, W, C), row 0 at v = 0, that contains (u, v): (..., C)."""
    table = np.asarray(table)
    h, w = table.shape[:2]
    return table[texel_index(v, h), texel_index(u, w)]


def sample_bilinear(table, u, v):
    """Bilinear lookup of a (H, W, C) table at texture coordinates (u, v) (Image Texture, Linear,
    EXTEND, no mipmaps): texel i has its centre at (i + 0.5)/W; coordinates outside the centres of the
    edge texels clamp to them.  A NaN coordinate reads the first texel."""
    table = np.asarray(table)
    h, w = table.shape[:2]

    def axis(t, n):
        x = np.asarray(t, dtype=np.float64) * n - 0.5
        x = np.clip(np.where(np.isnan(x), 0.0, x), 0.0, n - 1)
        x0 = np.minimum(np.floor(x).astype(np.int64), n - 2) if n > 1 else np.zeros(x.shape, np.int64)
        return x0, np.minimum(x0 + 1, n - 1), (x - x0)[..., None]

    x0, x1, fx = axis(u, w)
    y0, y1, fy = axis(v, h)
    top = table[y0, x0] * (1.0 - fx) + table[y0, x1] * fx
    bottom = table[y1, x0] * (1.0 - fx) + table[y1, x1] * fx
    return top * (1.0 - fy) + bottom * fy


# --- the table ---------------------------------------------------------------------------------------

@dataclass(frozen=True)
class Operation:
    """One IR operation: argument kinds, result kind, numpy rule (None: structural), statement, and the
    operation in shader text (``text``: a template over the arguments ``{0}``, ``{1}``, ... and the
    dialect's words ``{vec3}``, ``{atan2}``, ``{inversesqrt}``; None: structural).  A template that calls
    ``rtl_*`` uses a helper of ``SHADER_HELPERS``: the guarded rule where the language's own differs."""
    args: tuple
    result: str
    numpy: object
    rule: str
    text: str | None = None


def _op(args, result, fn, rule, text=None):
    return Operation(tuple(args), result, fn, rule, text)


F, V = FLOAT, VECTOR

OPERATIONS = {
    # leaves and structure (handled by each backend)
    "const": _op((), F, None, "a float constant (stored as float32, as Blender's sockets store it)"),
    "vconst": _op((), V, None, "a vector constant (float32 components)"),
    "input": _op((), F, None, "a named float input"),
    "vinput": _op((), V, None, "a named vector input"),
    # Math node (ShaderNodeMath)
    "add": _op((F, F), F, np.add, "a + b", "({0} + {1})"),
    "subtract": _op((F, F), F, np.subtract, "a - b", "({0} - {1})"),
    "multiply": _op((F, F), F, np.multiply, "a * b", "({0} * {1})"),
    "divide": _op((F, F), F, divide, "a / b; 0 where b == 0", "rtl_div({0}, {1})"),
    "power": _op((F, F), F, power, "a ** b; 0 for a < 0 with fractional b, and for a == 0 with b < 0",
                 "rtl_pow({0}, {1})"),
    "sqrt": _op((F,), F, sqrt, "sqrt(max(a, 0))", "sqrt(max({0}, 0.0))"),
    "inverse_sqrt": _op((F,), F, inverse_sqrt, "1/sqrt(a) for a > 0, else 0", "rtl_inverse_sqrt({0})"),
    "exponent": _op((F,), F, np.exp, "e ** a", "exp({0})"),
    "log2": _op((F,), F, log2, "log2(a) for a > 0, else 0", "rtl_log2({0})"),
    "minimum": _op((F, F), F, np.fmin, "min(a, b); the other operand where one is NaN", "min({0}, {1})"),
    "maximum": _op((F, F), F, np.fmax, "max(a, b); the other operand where one is NaN", "max({0}, {1})"),
    "less_than": _op((F, F), F, lambda a, b: (a < b).astype(np.result_type(a, b)), "1 if a < b else 0",
                     "(({0} < {1}) ? 1.0 : 0.0)"),
    "greater_than": _op((F, F), F, lambda a, b: (a > b).astype(np.result_type(a, b)), "1 if a > b else 0",
                        "(({0} > {1}) ? 1.0 : 0.0)"),
    "absolute": _op((F,), F, np.abs, "|a|", "abs({0})"),
    "floor": _op((F,), F, np.floor, "floor(a)", "floor({0})"),
    "arccosine": _op((F,), F, arccosine, "acos(clamp(a, -1, 1))", "rtl_acos({0})"),
    "arcsine": _op((F,), F, arcsine, "asin(clamp(a, -1, 1))", "rtl_asin({0})"),
    "sine": _op((F,), F, np.sin, "sin(a)", "sin({0})"),
    "cosine": _op((F,), F, np.cos, "cos(a)", "cos({0})"),
    "tangent": _op((F,), F, np.tan, "tan(a)", "tan({0})"),
    "arctan2": _op((F, F), F, np.arctan2, "atan2(a, b) (the angle of (b, a)); atan2(+-0, +-0) = +-0 or +-pi",
                   "rtl_atan2({0}, {1})"),
    # Mix node with a float factor: select(c, a, b) = mix(b, a, c) for c in {0, 1}
    "select": _op((F, F, F), F, select, "a if c != 0 else b (Mix: exact for c in {0, 1})",
                  "(({0} != 0.0) ? {1} : {2})"),
    "vselect": _op((F, V, V), V, vselect, "vector a if c != 0 else b", "(({0} != 0.0) ? {1} : {2})"),
    # Image Texture at (u, v), one channel: attrs ("table", name), ("channel", 0..3)
    "lut": _op((F, F), F, None, "Linear, EXTEND: sample_bilinear(table, u, v)[channel]"),
    "texel": _op((F, F), F, None, "Closest, EXTEND: texel_fetch(table, u, v)[channel]"),
    # Combine / Separate XYZ
    "combine": _op((F, F, F), V, combine, "(x, y, z)", "{vec3}({0}, {1}, {2})"),
    "x": _op((V,), F, lambda v: v[..., 0], "v.x", "{0}.x"),
    "y": _op((V,), F, lambda v: v[..., 1], "v.y", "{0}.y"),
    "z": _op((V,), F, lambda v: v[..., 2], "v.z", "{0}.z"),
    # Vector Math node (ShaderNodeVectorMath)
    "vadd": _op((V, V), V, np.add, "a + b", "({0} + {1})"),
    "vsubtract": _op((V, V), V, np.subtract, "a - b", "({0} - {1})"),
    "vscale": _op((V, F), V, lambda v, s: v * np.asarray(s)[..., None], "v * s", "({0} * {1})"),
    "vmultiply": _op((V, V), V, np.multiply, "component-wise a * b", "({0} * {1})"),
    # written out in numpy's order ((x + y) + z), not the language's dot(): llvmpipe's dot() fuses
    # multiply-adds and differs from numpy by up to 6e-6 relative where the sum cancels; this form is
    # bit-identical there (measured; docs/realtime.md, "Semantics")
    "dot": _op((V, V), F, dot, "a . b ((a.x b.x + a.y b.y) + a.z b.z)",
               "({0}.x * {1}.x + {0}.y * {1}.y + {0}.z * {1}.z)"),
    "cross": _op((V, V), V, cross, "a x b (written out, as dot)",
                 "{vec3}({0}.y * {1}.z - {0}.z * {1}.y, {0}.z * {1}.x - {0}.x * {1}.z, {0}.x * {1}.y - {0}.y * {1}.x)"),
    "length": _op((V,), F, length, "|v| (sqrt of the written-out dot)",
                  "sqrt({0}.x * {0}.x + {0}.y * {0}.y + {0}.z * {0}.z)"),
    "normalize": _op((V,), V, normalize, "v / |v|; the zero vector for |v| == 0", "rtl_normalize({0})"),
}

#: The guarded rules as shader functions, written in the subset GLSL (4.50, ES 3.00) and HLSL (SM 5) share;
#: ``{vec3}`` and ``{inversesqrt}`` are the dialect's words.  Each states the rule of its operation above.
SHADER_HELPERS = {
    "rtl_div": ("float rtl_div(float a, float b)", "return (b != 0.0) ? a / b : 0.0;"),
    # a ** b with Cycles' rules: 0 for 0 ** negative; a negative base needs an integer exponent (odd: -);
    # x ** 0 = 1 for every x (C's powf; GLSL leaves pow(0, 0) undefined: llvmpipe gives 0)
    "rtl_pow": ("float rtl_pow(float a, float b)",
                "if (b == 0.0) return 1.0;\n"
                "if (a == 0.0 && b < 0.0) return 0.0;\n"
                "if (a < 0.0) {\n"
                "    if (b != floor(b)) return 0.0;\n"
                "    float r = pow(-a, b);\n"
                "    return (b - 2.0 * floor(0.5 * b) != 0.0) ? -r : r;\n"
                "}\n"
                "return pow(a, b);"),
    "rtl_inverse_sqrt": ("float rtl_inverse_sqrt(float a)", "return (a > 0.0) ? {inversesqrt}(a) : 0.0;"),
    "rtl_log2": ("float rtl_log2(float a)", "return (a > 0.0) ? log2(a) : 0.0;"),
    # atan2 with IEEE's signed zeros (C's atan2f, numpy): GLSL leaves atan(0, 0) undefined (llvmpipe
    # gives 3 pi / 4) and Mesa's atan is off by 2e-5 relative (measured), so it is computed here: the
    # octant reduction, then atan(t) for |t| <= tan(pi / 8) by the minimax polynomial of Moshier's Cephes
    # ``atanf`` (coefficients as published; relative error ~2e-7 in float32)
    "rtl_atan2": ("float rtl_atan2(float y, float x)",
                  "float ax = abs(x), ay = abs(y);\n"
                  "float hi = max(ax, ay), lo = min(ax, ay);\n"
                  "float t = (hi > 0.0) ? lo / hi : 0.0;\n"
                  "float base = 0.0;\n"
                  "if (t > 0.41421356237) { t = (t - 1.0) / (t + 1.0); base = 0.78539816340; }\n"
                  "float z = t * t;\n"
                  "float r = base + ((((0.0805374449538 * z - 0.138776856032) * z + 0.199777106478) * z\n"
                  "                   - 0.333329491539) * z * t + t);\n"
                  "if (ay > ax) r = 1.57079632679 - r;\n"
                  "if ({sign_bit}(x)) r = 3.14159265359 - r;\n"
                  "return {sign_bit}(y) ? -r : r;"),
    # acos / asin of the clamped input through rtl_atan2 (Mesa's acos / asin are off by 1e-4 / 4e-4, measured)
    "rtl_acos": ("float rtl_acos(float a)",
                 "float c = clamp(a, -1.0, 1.0);\nreturn rtl_atan2(sqrt((1.0 - c) * (1.0 + c)), c);"),
    "rtl_asin": ("float rtl_asin(float a)",
                 "float c = clamp(a, -1.0, 1.0);\nreturn rtl_atan2(c, sqrt((1.0 - c) * (1.0 + c)));"),
    "rtl_normalize": ("{vec3} rtl_normalize({vec3} v)",
                      "float n = sqrt(v.x * v.x + v.y * v.y + v.z * v.z);\n"
                      "return (n > 0.0) ? v / n : {vec3}(0.0, 0.0, 0.0);"),
    # texel (floor(t n) clamped to [0, n - 1]; NaN reads texel 0): ``texel_index`` above
    "rtl_texel_index": ("int rtl_texel_index(float t, int n)",
                        "float x = floor(t * float(n));\n"
                        "if (isnan(x)) x = 0.0;\n"
                        "return int(clamp(x, 0.0, float(n - 1)));"),
}

#: Operations whose arguments are none (graph leaves).
LEAVES = ("const", "vconst", "input", "vinput")
#: Operations that read a table (attributes "table" and "channel").
TABLE_READS = ("lut", "texel")


def apply(op, values):
    """The numpy rule of ``op`` on arrays (all of one float dtype)."""
    fn = OPERATIONS[op].numpy
    if fn is None:
        raise ValueError(f"{op!r} is structural: backends evaluate it themselves")
    with np.errstate(over="ignore", under="ignore", invalid="ignore", divide="ignore"):
        return np.asarray(fn(*values))
