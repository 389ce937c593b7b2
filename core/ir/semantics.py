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

def _floats(*values):
    """numpy arrays of a float dtype (float32 and float64 kept; Python numbers as float64)."""
    out = []
    for v in values:
        a = np.asarray(v)
        out.append(a if a.dtype.kind == "f" else a.astype(np.float64))
    return out


def divide(a, b):
    """a / b, and 0 where b == 0 (Cycles ``safe_divide``)."""
    a, b = np.broadcast_arrays(*_floats(a, b))
    out = np.zeros(a.shape, dtype=np.result_type(a, b))
    np.divide(a, b, out=out, where=(b != 0))
    return out


def power(a, b):
    """a ** b, and 0 for a negative base with a fractional exponent or a zero base with a negative
    exponent (Cycles ``safe_powf``; the zero-base rule measured with Cycles 5.0.1)."""
    a, b = np.broadcast_arrays(*_floats(a, b))
    bad = ((a < 0) & (b != np.floor(b))) | ((a == 0) & (b < 0))
    with np.errstate(over="ignore", divide="ignore", invalid="ignore"):
        out = np.power(np.where(bad, 1.0, a).astype(a.dtype), b)
    return np.where(bad, 0.0, out).astype(np.result_type(a, b))


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
    """One IR operation: argument kinds, result kind, numpy rule (None: structural), statement."""
    args: tuple
    result: str
    numpy: object
    rule: str


def _op(args, result, fn, rule):
    return Operation(tuple(args), result, fn, rule)


F, V = FLOAT, VECTOR

OPERATIONS = {
    # leaves and structure (handled by each backend)
    "const": _op((), F, None, "a float constant (stored as float32, as Blender's sockets store it)"),
    "vconst": _op((), V, None, "a vector constant (float32 components)"),
    "input": _op((), F, None, "a named float input"),
    "vinput": _op((), V, None, "a named vector input"),
    # Math node (ShaderNodeMath)
    "add": _op((F, F), F, np.add, "a + b"),
    "subtract": _op((F, F), F, np.subtract, "a - b"),
    "multiply": _op((F, F), F, np.multiply, "a * b"),
    "divide": _op((F, F), F, divide, "a / b; 0 where b == 0"),
    "power": _op((F, F), F, power, "a ** b; 0 for a < 0 with fractional b, and for a == 0 with b < 0"),
    "sqrt": _op((F,), F, sqrt, "sqrt(max(a, 0))"),
    "inverse_sqrt": _op((F,), F, inverse_sqrt, "1/sqrt(a) for a > 0, else 0"),
    "exponent": _op((F,), F, np.exp, "e ** a"),
    "log2": _op((F,), F, log2, "log2(a) for a > 0, else 0"),
    "minimum": _op((F, F), F, np.minimum, "min(a, b)"),
    "maximum": _op((F, F), F, np.maximum, "max(a, b)"),
    "less_than": _op((F, F), F, lambda a, b: (a < b).astype(np.result_type(a, b)), "1 if a < b else 0"),
    "greater_than": _op((F, F), F, lambda a, b: (a > b).astype(np.result_type(a, b)), "1 if a > b else 0"),
    "absolute": _op((F,), F, np.abs, "|a|"),
    "floor": _op((F,), F, np.floor, "floor(a)"),
    "arccosine": _op((F,), F, arccosine, "acos(clamp(a, -1, 1))"),
    "arcsine": _op((F,), F, arcsine, "asin(clamp(a, -1, 1))"),
    "sine": _op((F,), F, np.sin, "sin(a)"),
    "cosine": _op((F,), F, np.cos, "cos(a)"),
    "tangent": _op((F,), F, np.tan, "tan(a)"),
    "arctan2": _op((F, F), F, np.arctan2, "atan2(a, b) (the angle of (b, a))"),
    # Mix node with a float factor: select(c, a, b) = mix(b, a, c) for c in {0, 1}
    "select": _op((F, F, F), F, select, "a if c != 0 else b (Mix: exact for c in {0, 1})"),
    "vselect": _op((F, V, V), V, vselect, "vector a if c != 0 else b"),
    # Image Texture at (u, v), one channel: attrs ("table", name), ("channel", 0..3)
    "lut": _op((F, F), F, None, "Linear, EXTEND: sample_bilinear(table, u, v)[channel]"),
    "texel": _op((F, F), F, None, "Closest, EXTEND: texel_fetch(table, u, v)[channel]"),
    # Combine / Separate XYZ
    "combine": _op((F, F, F), V, combine, "(x, y, z)"),
    "x": _op((V,), F, lambda v: v[..., 0], "v.x"),
    "y": _op((V,), F, lambda v: v[..., 1], "v.y"),
    "z": _op((V,), F, lambda v: v[..., 2], "v.z"),
    # Vector Math node (ShaderNodeVectorMath)
    "vadd": _op((V, V), V, np.add, "a + b"),
    "vsubtract": _op((V, V), V, np.subtract, "a - b"),
    "vscale": _op((V, F), V, lambda v, s: v * np.asarray(s)[..., None], "v * s"),
    "vmultiply": _op((V, V), V, np.multiply, "component-wise a * b"),
    "dot": _op((V, V), F, dot, "a . b"),
    "cross": _op((V, V), V, cross, "a x b"),
    "length": _op((V,), F, length, "|v|"),
    "normalize": _op((V,), V, normalize, "v / |v|; the zero vector for |v| == 0"),
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
