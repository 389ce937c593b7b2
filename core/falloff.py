"""Light falloffs and the quad-to-spot projector distance (the talk's epilogue)."""
from __future__ import annotations

from . import shading_ops as op
from .ir.functions import NodeFunction
from .ir.interface import factor, scalar

#: Smallest distance used by the inverse-square law (1 cm, Lagarde & de Rousiers 2014, eq. 15).
MIN_DISTANCE = 0.01
#: Smallest denominator for the cone falloff and the projector distance.
ANGLE_EPS = 1e-6


def window_falloff(distance, radius):
    """Windowing function saturate(1 - (d/r)^4)^2 (Karis 2013, eq. 9); 0 for radius <= 0."""
    x = op.safe_div(distance, radius)
    x2 = x * x
    w = op.saturate(1.0 - x2 * x2)
    return op.select(op.greater(radius, 0.0), w * w, 0.0)


def inverse_square_falloff(distance, min_distance=MIN_DISTANCE):
    """1 / max(d^2, d_min^2): the inverse-square law, clamped at 1 cm (Lagarde & de Rousiers 2014)."""
    d2 = op.maximum(distance * distance, min_distance * min_distance)
    return 1.0 / d2


def cone_falloff(cos_to_axis, inner_angle, outer_angle):
    """Spot cone falloff saturate((cos(a/2) - cos(phi/2)) / (cos(theta/2) - cos(phi/2))).

    The talk's epilogue: theta = inner and phi = outer *full* cone angles (as Blender's
    spot size), a/2 the angle between the spot axis and the direction to the point, so
    ``cos_to_axis`` = cos(a/2).  inner >= outer gives a hard edge at the outer angle.
    """
    cos_outer = op.cos(0.5 * outer_angle)
    cos_inner = op.cos(0.5 * op.minimum(inner_angle, outer_angle))
    return op.saturate((cos_to_axis - cos_outer) / op.maximum(cos_inner - cos_outer, ANGLE_EPS))


def projector_distance(diameter, outer_angle):
    """Distance behind a quad light of the spot apex whose cone fits it: p = (d/2) / tan(phi/2).

    The talk's quad-to-spot fallback; phi = outer full cone angle in (0, pi).
    """
    return 0.5 * diameter / op.maximum(op.tan(0.5 * outer_angle), ANGLE_EPS)


# --- node functions (offered to artists as stand-alone groups) --------------------------------------

_FALLOFF_OUT = {"Falloff": factor(1.0, "Light attenuation factor")}
_DISTANCE = scalar(1.0, "Distance from the light to the shading point (m)", 0.0, None, "DISTANCE")
_ANGLES = {"Inner Angle": scalar(0.6, "Inner full cone angle (rad)", 0.0, 3.14159, "ANGLE"),
           "Outer Angle": scalar(0.8, "Outer full cone angle (rad)", 0.0, 3.14159, "ANGLE")}

WINDOW_FALLOFF = NodeFunction(
    "RTL Window Falloff", lambda Distance, Radius: {"Falloff": window_falloff(Distance, Radius)},
    {"Distance": _DISTANCE, "Radius": scalar(10.0, "Light radius of influence (m)", 0.0, None, "DISTANCE")},
    _FALLOFF_OUT, "Karis 2013 windowing saturate(1 - (d/r)^4)^2")
INVERSE_SQUARE_FALLOFF = NodeFunction(
    "RTL Inverse Square Falloff", lambda Distance: {"Falloff": inverse_square_falloff(Distance)},
    {"Distance": _DISTANCE}, {"Falloff": scalar(1.0, "1 / max(d^2, 1 cm^2)")}, "Inverse-square law clamped at 1 cm")
CONE_FALLOFF = NodeFunction(
    "RTL Cone Falloff", lambda **kw: {"Falloff": cone_falloff(kw["Cos To Axis"], kw["Inner Angle"],
                                                              kw["Outer Angle"])},
    {"Cos To Axis": factor(1.0, "Cosine of the angle between the spot axis and the point"), **_ANGLES},
    _FALLOFF_OUT, "The talk's spot cone falloff between the inner and outer angles")
PROJECTOR_DISTANCE = NodeFunction(
    "RTL Projector Distance", lambda **kw: {"Distance": projector_distance(kw["Diameter"], kw["Outer Angle"])},
    {"Diameter": scalar(1.0, "Light diameter (m)", 0.0, None, "DISTANCE"), "Outer Angle": _ANGLES["Outer Angle"]},
    {"Distance": scalar(1.0, "Apex distance behind the quad light (m)")},
    "The talk's quad-to-spot fallback: distance of the spot apex behind the light")

NODE_FUNCTIONS = (WINDOW_FALLOFF, INVERSE_SQUARE_FALLOFF, CONE_FALLOFF, PROJECTOR_DISTANCE)
