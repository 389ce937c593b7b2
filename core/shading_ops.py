"""Scalar and vector math with Blender shader-node semantics (numpy backend).

Shading code in ``core`` is written with these functions so that the guard behind every
division, square root, inverse trigonometric function and normalisation is explicit and
identical wherever the math is evaluated: in numpy here, and in Blender node groups later
(the node-group backend maps each function to one Math / Vector Math node).

The rule behind each operation (what Blender's nodes compute where plain IEEE math would give
NaN or Inf, and how EEVEE differs from Cycles) is stated once, in ``core.ir.semantics``; the numpy
path below calls those rules, and the functions that need a guard the engines do not share
(``inverse_sqrt``'s eps, the explicit clamp of ``acos`` / ``asin``) add it here, in both paths.

All functions accept scalars or numpy arrays (float32 or float64) and broadcast; vectors
are arrays whose last axis has length 3.  Given an IR expression (``core.ir.Expr``) as any
argument, each function instead adds the equivalent node(s) to that expression's graph, so
the same shading code is traced for the numpy and Blender node backends (core/ir).
"""
from __future__ import annotations

import numpy as np

from .ir import semantics
from .ir.expr import graph_of, is_expr
from .ir.tables import bilinear_function


def _node(op, *args):
    return graph_of(*args).make(op, args)


def _arr(x):
    """x for numpy: Python numbers stay Python floats (weak: they take the other operand's float dtype,
    under numpy 1 and 2 alike), arrays keep a float dtype (integers become float64)."""
    if isinstance(x, (bool, int, float)):
        return float(x)
    a = np.asarray(x)
    return a if a.dtype.kind == "f" else a.astype(np.float64)


# --- scalar math -------------------------------------------------------------------------

def safe_div(a, b):
    """a / b with Blender's Divide semantics: 0 where b == 0."""
    if is_expr(a, b):
        return _node("divide", a, b)
    return semantics.divide(a, b)


def sqrt(a):
    """Square root with Blender semantics: 0 for a <= 0."""
    if is_expr(a):
        return _node("sqrt", a)
    return semantics.sqrt(a)


def inverse_sqrt(a, eps):
    """1/sqrt(max(a, eps)); eps > 0 is required because EEVEE's inversesqrt is unguarded."""
    if not eps > 0:
        raise ValueError("inverse_sqrt needs an explicit eps > 0")
    if is_expr(a):
        return _node("inverse_sqrt", maximum(a, eps))
    return semantics.inverse_sqrt(np.maximum(_arr(a), eps))


def acos(a):
    """arccos of the input clamped to [-1, 1] (the clamp is explicit in nodes too)."""
    if is_expr(a):
        return _node("arccosine", clamp(a, -1.0, 1.0))
    return semantics.arccosine(a)


def asin(a):
    """arcsin of the input clamped to [-1, 1]."""
    if is_expr(a):
        return _node("arcsine", clamp(a, -1.0, 1.0))
    return semantics.arcsine(a)


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
    return semantics.log2(a)


def pow5(a):
    """a**5 by multiplication (no Power node, so no negative-base rule applies)."""
    if is_expr(a):
        a2 = a * a
        return a2 * a2 * a
    a = _arr(a)
    a2 = a * a
    return a2 * a2 * a


# min and max ignore a NaN operand (IEEE 754-2008 minNum / maxNum): Cycles' Math node computes them with
# fminf / fmaxf and GPUs' min / max return the other operand, so clamp(NaN, 0, 1) = 0 in every backend and
# a NaN material input (a texture, a driver) cannot reach a pixel through a clamped factor.
def minimum(a, b):
    if is_expr(a, b):
        return _node("minimum", a, b)
    return np.fmin(_arr(a), _arr(b))


def maximum(a, b):
    if is_expr(a, b):
        return _node("maximum", a, b)
    return np.fmax(_arr(a), _arr(b))


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


def floor(a):
    if is_expr(a):
        return _node("floor", a)
    return np.floor(_arr(a))


def lut_sample(table, u, v, channel):
    """Channel of ``table`` (a ``core.ir.tables.Table``) at texture coordinates (u, v), bilinear with
    EXTEND (Image Texture node, Linear; the texel-centre rule of ``semantics.sample_bilinear``).

    Traced, it is a call of ``tables.bilinear_function``: four Closest fetches and explicit weights,
    exact in Cycles and EEVEE alike, or under ``expr.table_filter("linear")`` one Linear read (Cycles'
    trees).  In numpy the table must hold its data."""
    if is_expr(u, v):
        return bilinear_function(table)(u=u, v=v)["RGBA"[channel]]
    return semantics.sample_bilinear(table.require_data(), u, v)[..., channel]


def texel_fetch(table, u, v, channel):
    """Channel of the texel of ``table`` that contains (u, v), no filtering (Image Texture, Closest,
    EXTEND): texel (floor(u W), floor(v H)) clamped to the table, row 0 at v = 0.  Traced: a
    ``texel`` node."""
    if is_expr(u, v):
        return graph_of(u, v).read_table(table, u, v, channel)
    return semantics.texel_fetch(table.require_data(), u, v)[..., channel]


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
    return np.asarray(_arr(v))[..., axis]


def vec3(x, y, z):
    """A vector from three scalars (Combine XYZ)."""
    if is_expr(x, y, z):
        g = graph_of(x, y, z)
        return g.make("combine", (x, y, z))
    return np.stack(np.broadcast_arrays(*semantics.as_floats(x, y, z)), axis=-1)


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
    v, s = semantics.as_floats(v, s)
    return v * s[..., None]


def normalize(v):
    """v/|v|, and the zero vector for |v| == 0 (Blender's Vector Math Normalize)."""
    if is_expr(v):
        return _node("normalize", v)
    return semantics.normalize(v)


# --- colours (3-vectors) --------------------------------------------------------------------

def per_channel(fn, rgb, *args):
    """fn applied to each channel of a colour (a Separate/Combine XYZ pair in nodes)."""
    return vec3(*(fn(component(rgb, i), *args) for i in range(3)))


def splat(x):
    """The grey colour (x, x, x)."""
    return vec3(x, x, x)
