"""Socket descriptions for functions that become node groups: what an artist sees.

A ``Socket`` carries the presentation of one input or output of a ``NodeFunction``: its
Blender socket type, subtype, default, soft range and tooltip, and the panel it sits in.  The
math never reads these; the node backend turns them into the group interface.
"""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Socket:
    """One interface socket.  ``kind``: "float", "vector" or "color" (a vector in the IR)."""
    kind: str = "float"
    default: object = 0.0
    min: float | None = None
    max: float | None = None
    subtype: str = "NONE"            # FACTOR, DISTANCE, ANGLE, DIRECTION, XYZ, TRANSLATION, ...
    description: str = ""
    panel: str | None = None
    hide_value: bool = False


def factor(default, description, panel=None):
    """A [0, 1] slider."""
    return Socket("float", default, 0.0, 1.0, "FACTOR", description, panel)


def color(default, description, panel=None):
    return Socket("color", tuple(default), None, None, "NONE", description, panel)


def vector(description, subtype="XYZ", panel=None, hide_value=False, default=(0.0, 0.0, 0.0)):
    return Socket("vector", tuple(default), None, None, subtype, description, panel, hide_value)


def scalar(default, description, lo=None, hi=None, subtype="NONE", panel=None):
    return Socket("float", default, lo, hi, subtype, description, panel)
