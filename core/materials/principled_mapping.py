"""Principled BSDF <-> RT Lit: which inputs correspond and how a value crosses from one socket to the other.

The RT Lit group's inputs (``RT_LIT_INPUTS``) take the Principled BSDF's names where one exists, so the
mapping is one to one by name (``MAPPED_INPUTS``), in both directions.  "Normal" is link-only: its value is
hidden and unused, so only its link crosses.  The RT Lit-only inputs (Wrap, Cloth ...) have no Principled
counterpart (``RT_LIT_ONLY_INPUTS``).  Principled's sheen is RT Lit's ``PRINCIPLED_SHEEN`` model
(``rt_lit_interface``).

Pure Python on plain values (floats and tuples, as a socket's ``default_value`` reads): the node trees are
edited by ``addon/convert.py``.
"""
from __future__ import annotations

from .rt_lit_interface import RT_LIT_INPUTS

#: Principled BSDF input -> RT Lit input (same names).  "Normal" is link-only.
MAPPED_INPUTS = (
    "Base Color", "Metallic", "Roughness", "IOR", "Specular IOR Level", "Specular Tint",
    "Sheen Weight", "Sheen Roughness", "Sheen Tint", "Emission Color", "Emission Strength", "Normal",
)
#: Principled's Diffuse Roughness (Blender 4.3+) drives RT Lit's "oren_nayar" diffuse (core/rough_diffuse.py).
MAPPED_INPUTS += ("Diffuse Roughness",)
#: Inputs whose value is never copied (only their link): the value is hidden and unused.
LINK_ONLY_INPUTS = ("Normal",)
#: RT Lit inputs with no Principled counterpart; their values are remembered on the material.
RT_LIT_ONLY_INPUTS = tuple(name for name in RT_LIT_INPUTS if name not in MAPPED_INPUTS)

#: Two socket values closer than this (per component) are equal.
FLOAT_TOLERANCE = 1e-6


def converted_value(value, target):
    """``value`` (a float or a tuple: a colour or a vector) in the shape of ``target``, the value it replaces:
    a float spread over every component, a tuple cut to the target's size or completed with its components
    (a colour's alpha), a tuple into a float the mean of its first three components."""
    if isinstance(target, tuple):
        if not isinstance(value, tuple):
            value = (value,) * len(target)
        return tuple(value[:len(target)]) + tuple(target[len(value):])
    if isinstance(value, tuple):
        return sum(value[:3]) / min(len(value), 3)
    return value


def values_equal(a, b):
    """Whether two socket values are equal (numbers and tuples of them to ``FLOAT_TOLERANCE``; a float
    equals a 1-tuple)."""
    if isinstance(a, tuple) or isinstance(b, tuple):
        a, b = tuple(a) if isinstance(a, tuple) else (a,), tuple(b) if isinstance(b, tuple) else (b,)
        return len(a) == len(b) and all(abs(x - y) <= FLOAT_TOLERANCE for x, y in zip(a, b))
    if isinstance(a, (int, float)) and isinstance(b, (int, float)):
        return abs(a - b) <= FLOAT_TOLERANCE
    return a == b
