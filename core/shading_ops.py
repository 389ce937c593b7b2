"""Scalar and vector math with Blender shader-node semantics (numpy backend).

Shading code in ``core`` is written with these functions so that the guard behind every
division, square root, inverse trigonometric function and normalisation is explicit and
identical wherever the math is evaluated: in numpy here, and in Blender node groups later
(the node-group backend maps each function to one Math / Vector Math node).

Blender's Math node differs between engines (Cycles ``kernel/svm/math_util.h`` vs EEVEE
``gpu_shader_common_math.glsl``; see ../shared/reference/blender_addon.md §2.5 and ltc.md
§5.1).  The functions below pick, for each operation, the behaviour that both engines
share once the inputs are guarded, and the shading code supplies those guards:

==================  ======================================  ==============================
operation           Cycles                                  EEVEE
==================  ======================================  ==============================
a / b               0 when b == 0                           0 when b == 0
sqrt(a)             sqrt(max(a, 0))                         a > 0 ? sqrt(a) : 0
inversesqrt(a)      a > 0 ? 1/sqrt(a) : 0                   unguarded  -> callers pass max(a, eps)
acos(a), asin(a)    input clamped to [-1, 1]                0 outside [-1, 1] -> callers clamp
pow(a, b)           0 for a < 0 and fractional b            same
log(a, base)        0 for a <= 0                            same
normalize(v)        zero vector for |v| = 0                 same (5.0 GLSL checks length)
==================  ======================================  ==============================

All functions accept scalars or numpy arrays (float32 or float64) and broadcast; vectors
are arrays whose last axis has length 3.  Given an IR expression (``core.ir.Expr``) as any
argument, each function instead adds the equivalent node(s) to that expression's graph, so
the same shading code is traced for the numpy and Blender node backends (core/ir).
"""
from __future__ import annotations

import numpy as np

from .ir.expr import graph_of, is_expr


def _node(op, *args):
    return graph_of(*args).make(op, args)


def _arr(x):
    """Float array view of x: float32/float64 kept, Python numbers and integers become float64."""
    a = np.asarray(x)
    return a if a.dtype.kind == "f" else a.astype(np.float64)


# --- scalar math -------------------------------------------------------------------------

def safe_div(a, b):
    """a / b with Blender's Divide semantics: 0 where b == 0."""
    if is_expr(a, b):
        return _node("divide", a, b)
    a, b = np.broadcast_arrays(_arr(a), _arr(b))
    out = np.zeros(a.shape, dtype=np.result_type(a, b))
    np.divide(a, b, out=out, where=(b != 0))
    return out


def sqrt(a):
    """Square root with Blender semantics: 0 for a <= 0."""
    if is_expr(a):
        return _node("sqrt", a)
    return np.sqrt(np.maximum(_arr(a), 0.0))


def inverse_sqrt(a, eps):
    """1/sqrt(max(a, eps)); eps > 0 is required because EEVEE's inversesqrt is unguarded."""
    if not eps > 0:
        raise ValueError("inverse_sqrt needs an explicit eps > 0")
    if is_expr(a):
        return _node("inverse_sqrt", maximum(a, eps))
    return 1.0 / np.sqrt(np.maximum(_arr(a), eps))


def acos(a):
    """arccos of the input clamped to [-1, 1] (the clamp is explicit in nodes too)."""
    if is_expr(a):
        return _node("arccosine", clamp(a, -1.0, 1.0))
    return np.arccos(np.clip(_arr(a), -1.0, 1.0))


def asin(a):
    """arcsin of the input clamped to [-1, 1]."""
    if is_expr(a):
        return _node("arcsine", clamp(a, -1.0, 1.0))
    return np.arcsin(np.clip(_arr(a), -1.0, 1.0))


def exp(a):
    if is_expr(a):
        return _node("exponent", a)
    return np.exp(_arr(a))


def exp2(a):
    """2**a (Blender: Power node with base 2)."""
    if is_expr(a):
        return _node("power", 2.0, a)
    return np.exp2(_arr(a))


def log2(a):
    """log2(a) with Blender's Logarithm semantics: 0 for a <= 0."""
    if is_expr(a):
        return _node("log2", a)
    a = _arr(a)
    out = np.zeros(a.shape, dtype=a.dtype)
    np.log2(a, out=out, where=(a > 0))
    return out


def pow5(a):
    """a**5 by multiplication (no Power node, so no negative-base rule applies)."""
    if is_expr(a):
        a2 = a * a
        return a2 * a2 * a
    a = _arr(a)
    a2 = a * a
    return a2 * a2 * a


def minimum(a, b):
    if is_expr(a, b):
        return _node("minimum", a, b)
    return np.minimum(_arr(a), _arr(b))


def maximum(a, b):
    if is_expr(a, b):
        return _node("maximum", a, b)
    return np.maximum(_arr(a), _arr(b))


def clamp(a, lo, hi):
    return minimum(maximum(a, lo), hi)


def saturate(a):
    """Clamp to [0, 1] (the Math node's "Clamp" option)."""
    return clamp(a, 0.0, 1.0)


def mix(a, b, t):
    """Linear interpolation a + (b - a) t (HLSL lerp, Blender Mix node)."""
    if is_expr(a, b, t):
        return a + (b - a) * t
    a, b, t = _arr(a), _arr(b), _arr(t)
    return a + (b - a) * t


def select(condition, if_true, if_false):
    """Per-element choice; in nodes a Compare/Greater Than result drives a Mix factor."""
    if is_expr(condition, if_true, if_false):
        return _node("select", condition, if_true, if_false)
    return np.where(condition, _arr(if_true), _arr(if_false))


def vselect(condition, if_true, if_false):
    """Per-element choice between vectors (a Mix node in vector mode)."""
    if is_expr(condition, if_true, if_false):
        return _node("vselect", condition, if_true, if_false)
    return np.where(np.asarray(condition)[..., None], _arr(if_true), _arr(if_false))


def greater(a, b):
    """a > b: a boolean array, or a 0/1 float in nodes (Math "Greater Than")."""
    if is_expr(a, b):
        return _node("greater_than", a, b)
    return _arr(a) > _arr(b)


def less(a, b):
    """a < b (Math "Less Than")."""
    if is_expr(a, b):
        return _node("less_than", a, b)
    return _arr(a) < _arr(b)


def logical_and(a, b):
    """Both conditions (in nodes: the product of two 0/1 floats)."""
    if is_expr(a, b):
        return _node("multiply", a, b)
    return np.logical_and(a, b)


def cos(a):
    if is_expr(a):
        return _node("cosine", a)
    return np.cos(_arr(a))


def sin(a):
    if is_expr(a):
        return _node("sine", a)
    return np.sin(_arr(a))


def atan2(y, x):
    """Angle of (x, y) in [-pi, pi] (Math "Arctan2": atan2(first input, second input))."""
    if is_expr(y, x):
        return _node("arctan2", y, x)
    return np.arctan2(_arr(y), _arr(x))


def absolute(a):
    if is_expr(a):
        return _node("absolute", a)
    return np.abs(_arr(a))


def tan(a):
    if is_expr(a):
        return _node("tangent", a)
    return np.tan(_arr(a))


class Lut:
    """A lookup table for shading code: its catalog name and its (H, W, 4) data."""

    def __init__(self, name, table):
        self.name, self.table = name, np.asarray(table)


def floor(a):
    if is_expr(a):
        return _node("floor", a)
    return np.floor(_arr(a))


def lut_sample(lut, u, v, channel):
    """Channel of ``lut`` at texture coordinates (u, v), bilinear with EXTEND (Image Texture node,
    Linear; core/lut/lookup.py for the texel-centre convention).

    Traced, the bilinear filter is written out (``lut_bilinear_function``): four Closest fetches
    and explicit weights.  EEVEE's Linear filtering selects mipmaps from screen-space derivatives
    of the coordinates, which for a LUT indexed by per-pixel values blurred lookups by up to 40%
    of the table's range (measured); Closest fetches are exact in both engines."""
    if is_expr(u, v):
        return lut_bilinear_function(lut)(u=u, v=v)["RGBA"[channel]]
    from .lut.lookup import sample_bilinear

    return sample_bilinear(lut.table, u, v)[..., channel]


def texel_fetch(lut, u, v, channel):
    """Channel of the texel of ``lut`` that contains (u, v), no filtering (Image Texture, Closest,
    EXTEND): texel (floor(u W), floor(v H)) clamped to the table, row 0 at v = 0.  Traced: a
    ``texel`` node."""
    if is_expr(u, v):
        g = graph_of(u, v)
        g.luts.setdefault(lut.name, lut.table)
        return g.make("texel", (u, v), (("table", lut.name), ("channel", channel)))
    table = np.asarray(lut.table)
    h, w = table.shape[:2]
    i = np.clip(np.floor(np.asarray(u, np.float64) * w), 0, w - 1).astype(np.int64)
    j = np.clip(np.floor(np.asarray(v, np.float64) * h), 0, h - 1).astype(np.int64)
    return table[j, i][..., channel]


_LUT_FUNCTIONS = {}


def lut_bilinear_function(lut):
    """The node function "RTL LUT <table>": (u, v) -> the four channels, bilinear, EXTEND."""
    from .ir.functions import NodeFunction
    from .ir.interface import Socket

    cached = _LUT_FUNCTIONS.get(lut.name)
    if cached is not None and cached[0] is lut.table:
        return cached[1]
    h, w = np.shape(lut.table)[:2]

    # Bilinear filtering as Cycles' Linear Image Texture does it (texel centres at (i + 0.5)/W,
    # coordinates clamped to the centres of the edge texels: EXTEND).
    def axis(t, n):
        x = clamp(t * n - 0.5, 0.0, n - 1.0)
        x0 = minimum(floor(x), max(n - 2.0, 0.0))
        return (x0 + 0.5) / n, (x0 + 1.5) / n if n > 1 else (x0 + 0.5) / n, x - x0

    def body(u, v):
        u0, u1, fu = axis(u, w)
        v0, v1, fv = axis(v, h)
        g = graph_of(u, v)
        g.luts.setdefault(lut.name, lut.table)
        # each tap is weighted and accumulated at once (one live tap at a time: Cycles' SVM stack
        # holds 255 floats for a whole material, and a tap read by four later mixes stays live)
        taps = ((u0, v0, (1.0 - fu) * (1.0 - fv)), (u1, v0, fu * (1.0 - fv)),
                (u0, v1, (1.0 - fu) * fv), (u1, v1, fu * fv))
        out = {}
        for c, name in enumerate("RGBA"):
            total = None
            for uu, vv, weight in taps:
                term = g.make("texel", (uu, vv), (("table", lut.name), ("channel", c))) * weight
                total = term if total is None else total + term
            out[name] = total
        return out

    coord = Socket("float", 0.5, description="Texture coordinate (texel centres at (i + 0.5)/N)")
    fn = NodeFunction(f"RTL LUT {lut.name}", body, {"u": coord, "v": coord},
                      {c: Socket("float", 0.0, description=f"Channel {c}, bilinear") for c in "RGBA"},
                      f"Bilinear lookup of the {lut.name} table (four exact texel fetches; EXTEND)")
    _LUT_FUNCTIONS[lut.name] = (lut.table, fn)
    return fn


# --- vector math (last axis = xyz) -------------------------------------------------------

def dot(a, b):
    if is_expr(a, b):
        return _node("dot", a, b)
    return np.sum(_arr(a) * _arr(b), axis=-1)


def cross(a, b):
    if is_expr(a, b):
        return _node("cross", a, b)
    return np.cross(_arr(a), _arr(b))


def length(v):
    if is_expr(v):
        return _node("length", v)
    return np.sqrt(dot(v, v))


def component(v, axis):
    """Component 0/1/2 (x/y/z) of a vector (a Separate XYZ output in nodes)."""
    if is_expr(v):
        return _node("xyz"[axis], v)
    return _arr(v)[..., axis]


def vec3(x, y, z):
    """A vector from three scalars (Combine XYZ)."""
    if is_expr(x, y, z):
        g = graph_of(x, y, z)
        return g.make("combine", (x, y, z))
    return np.stack(np.broadcast_arrays(_arr(x), _arr(y), _arr(z)), axis=-1)


def vmul(a, b):
    """Component-wise product of two vectors (Vector Math "Multiply"), e.g. colour times colour."""
    if is_expr(a, b):
        return _node("vmultiply", a, b)
    return _arr(a) * _arr(b)


def mat_vec(rows, x):
    """A 3x3 matrix given as its three row vectors, applied to a vector: three dot products."""
    return vec3(dot(rows[0], x), dot(rows[1], x), dot(rows[2], x))


def scale(v, s):
    """Vector v times scalar s (Vector Math "Scale")."""
    if is_expr(v, s):
        return _node("vscale", v, s)
    return _arr(v) * _arr(s)[..., None]


def normalize(v):
    """v/|v|, and the zero vector for |v| == 0 (Blender's Vector Math Normalize)."""
    if is_expr(v):
        return _node("normalize", v)
    v = _arr(v)
    n = length(v)[..., None]
    out = np.zeros(np.broadcast_shapes(v.shape, n.shape), dtype=v.dtype)
    np.divide(v, n, out=out, where=(n > 0))
    return out
