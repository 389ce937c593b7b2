"""Every node group RT Lookdev offers artists: a list of node functions of the numpy core (no math here).

Each entry is a ``core.ir.functions.NodeFunction``: the same Python function evaluates in numpy and is
emitted as a Blender node group (addon/node_emit.py).  In Add > Group order: the RT Lit surface, the
stand-alone technique groups (multiple-scattering scales, the Fdez-Aguera environment BRDF, falloffs),
the lobes for one light direction, the per-light-kind LTC lobes for quad and disk lights, the LTC
integrals, and the Blender light conversions.
"""
from __future__ import annotations

import functools

from ..core import falloff, lights, multiscatter
from ..core.ltc import disk, polygon
from ..core.materials import lobes
from ..core.materials.surface import SURFACE


@functools.lru_cache(maxsize=1)
def all_functions():
    """Every offered node function, in Add > Group order (names start with "RTL ")."""
    out = [SURFACE]
    out += list(multiscatter.NODE_FUNCTIONS)
    out += list(falloff.NODE_FUNCTIONS)
    out += [lobe.function("point") for lobe in lobes.LOBES.values()]
    out += [lobe.function(kind) for kind in lobes.AREA_KINDS for lobe in lobes.LOBES.values()]
    out += [polygon.LTC_QUAD_INTEGRAL, disk.LTC_DISK_INTEGRAL]
    out += list(lights.NODE_FUNCTIONS)
    return tuple(out)
