"""Conventions fixed once for the whole project (see docs/conventions.md).

- Roughness ``r`` is Blender's "Roughness" socket (perceptual roughness).
- GGX ``alpha = r**2`` (Burley 2012; Cycles ``bsdf_microfacet_ggx_setup``), floored at
  ``ALPHA_MIN`` so that every evaluation stays finite in float32.
- ``mu = cos(theta)`` measured from the shading normal; ``mu_v`` for the view
  direction, ``mu_l`` for the light direction.
- Masking-shadowing is the height-correlated Smith G2 (Heitz 2014, "Understanding the
  Masking-Shadowing Function", eq. 99), the choice of Cycles and of selfshadow/ltc_code.
- Fresnel is Schlick's with F90 = 1 unless a function takes ``f90`` explicitly.
- Local shading frame: normal = +Z, the view vector lies in the XZ plane with x >= 0.
"""
from __future__ import annotations

import numpy as np

from . import shading_ops as op

#: Smallest GGX alpha used anywhere.  alpha**2 = 1e-8 keeps D(h) <= 1/(pi*1e-8) ~ 3e7,
#: finite in float32, and the E table at r = 0 is indistinguishable from a mirror
#: (E = 1 to 1e-7 for mu >= 1e-3).
ALPHA_MIN = 1e-4

#: Floor for denominators that are products of cosines (float32-safe: its square is
#: still a normal float32 number).
COS_EPS = 1e-7


def alpha_from_roughness(r):
    """GGX alpha from Blender roughness: alpha = max(r^2, ALPHA_MIN) (Burley 2012)."""
    if op.is_expr(r):
        r = op.saturate(r)
        return op.maximum(r * r, ALPHA_MIN)
    r = np.asarray(r)
    r = np.clip(r if r.dtype.kind == "f" else r.astype(np.float64), 0.0, 1.0)
    return np.maximum(r * r, ALPHA_MIN)
