"""Diffuse BRDFs: Lambert, Call of Duty WWII multiscattering diffuse, normalised wrapped diffuse, and the two
combined (multiscattering wrapped diffuse)."""
from __future__ import annotations

import numpy as np

from . import shading_ops as op
from .conventions import ALPHA_MIN


def lambert(albedo):
    """Lambertian BRDF albedo / pi."""
    return np.asarray(albedo) / np.pi


def cod_gloss_from_alpha(alpha):
    """Call of Duty WWII gloss g from GGX alpha (Chan 2018, "Material Advances in CoD: WWII").

    CoD parameterises roughness as alpha^2 = 2 / (1 + 2^(18 g)), so
    g = saturate(log2(2 / alpha^2 - 1) / 18).  r = 0.5 (alpha = 0.25) gives g = 0.2752;
    r = 1 gives g = 0; g saturates at 1 for r <= 0.053.

    The talk writes ``saturate(0.18455 * log(2 / pow(1 - smoothness, 4) - 1))``.  Since
    1 / (18 log10(2)) = 0.18455, that equals this mapping only if ``log`` is base 10; HLSL's
    ``log`` is the natural logarithm, which gives g larger by ln(10) = 2.30 (r = 0.5: 0.634).
    We follow the paper's definition (tested in tests/core/test_diffuse.py).
    """
    a2 = op.maximum(alpha, ALPHA_MIN) ** 2
    return op.saturate(op.log2(2.0 / a2 - 1.0) / 18.0)


def cod_gloss_talk(smoothness, natural_log=False):
    """The talk's expression for g, with ``log`` read as log10 (default) or ln; for tests only."""
    x = 2.0 / np.maximum((1.0 - np.asarray(smoothness, dtype=np.float64)) ** 4, 1e-300) - 1.0
    log = np.log if natural_log else np.log10
    return np.clip(0.18455 * log(np.maximum(x, 1e-300)), 0.0, 1.0)


# Chan 2018 fits the retro-reflection amplitude with the quadratic (34.5 g - 59) g + 24.5, whose roots are
# g = 0.710 and g = 1: between them it is negative (down to -0.72 at g = 0.855, i.e. r ~ 0.05-0.13), and
# with light and view grazing from the same side (fd -> 0.0625, l.h -> 1, n.h -> 0) the BRDF itself went
# negative (found by the robustness sweep, docs/robustness.md).  The fit reaches 0 at g = 1, so clamping it
# at 0 keeps its shape where it is positive and only removes the overshoot.
def retro_reflection_scale(g):
    """max((34.5 g - 59) g + 24.5, 0): the CoD WWII retro-reflection amplitude, clamped at 0."""
    return op.maximum((34.5 * g - 59.0) * g + 24.5, 0.0)


def cod_lobe_shape(mu_l, mu_v, n_dot_h, l_dot_h, alpha):
    """fd + fb of the Call of Duty WWII multiscattering diffuse (Chan 2018; the talk): the BRDF without its
    albedo / pi and without the horizon test (``cod_multiscatter_diffuse``).

      f0 = (l.h) + (1 - l.h)^5                               rough limit
      f1 = (1 - 0.75 (1 - n.l)^5)(1 - 0.75 (1 - n.v)^5)     smooth limit (cosines clamped at 0)
      fd = lerp(f0, f1, saturate(2.2 g - 0.5))
      fb = max((34.5 g - 59) g + 24.5, 0) (l.h) 2^(-max(73.2 g - 21.2, 8.9) sqrt(n.h))   retro-reflection
    """
    g = cod_gloss_from_alpha(alpha)
    ldh = op.saturate(l_dot_h)
    f0 = ldh + op.pow5(1.0 - ldh)
    f1 = (1.0 - 0.75 * op.pow5(1.0 - op.saturate(mu_l))) * (1.0 - 0.75 * op.pow5(1.0 - op.saturate(mu_v)))
    fd = op.mix(f0, f1, op.saturate(2.2 * g - 0.5))
    # n.h < 0 only for light below the horizon (the wrapped form), where sqrt gives 0 (core/ir/semantics.py)
    fb = retro_reflection_scale(g) * ldh * op.exp2(-op.maximum(73.2 * g - 21.2, 8.9) * op.sqrt(n_dot_h))
    return fd + fb


def cod_multiscatter_diffuse(albedo, mu_l, mu_v, n_dot_h, l_dot_h, alpha):
    """Call of Duty WWII multiscattering diffuse BRDF (Chan 2018, course notes; the talk).

    f = albedo/pi * (fd + fb) (``cod_lobe_shape``).  The 1/pi belongs to the BRDF (multiply by mu_l for
    radiance).  Symmetric in l and v (l.h = v.h), so reciprocal.  Zero below either horizon.

    Deviation from the paper: the retro-reflection coefficient is clamped at 0 (``retro_reflection_scale``).
    """
    above = op.logical_and(op.greater(mu_l, 0.0), op.greater(mu_v, 0.0))
    return op.select(above, albedo * (1.0 / np.pi) * cod_lobe_shape(mu_l, mu_v, n_dot_h, l_dot_h, alpha), 0.0)


# The talk's "no multiscattering wrapped diffuse", solved in its closing table ("Multiscattering diffuse: direct,
# indirect and wrapped lighting").  The talk shows how to wrap under area lights (tilt the normal towards the light,
# integrate the lobe about it, divide by 1 + w), not a wrapped form of the CoD lobe itself; this is ours.  The
# normalised wrap of Lambert replaces mu_l by the wrapped cosine mu_w = (mu_l + w)/(1 + w) and divides by 1 + w
# (``wrapped_diffuse_cosine``).  We do the same to the whole CoD lobe: the light direction l is moved, in the plane
# of n and l, to the direction l_w whose cosine is mu_w, and the CoD BRDF is evaluated there:
#     f_w(l, v) mu_l  :=  f_CoD(l_w, v) mu_w / (1 + w).
# Every CoD term (the smooth limit's (1 - n.l)^5, l.h, the retro-reflection's n.h) then stays in the lobe's own
# domain, w = 0 is the CoD diffuse, a Lambert-like lobe gives the normalised wrapped Lambert exactly, and the
# directional albedo is the CoD lobe's for every w (substituting mu_w for mu_l maps the wrapped region onto the
# hemisphere with Jacobian 1 + w), so the SH and area forms keep the CoD table's magnitude.
def wrapped_light_direction(n, l, wrap, clamp=True):
    """(l_w, mu_w): the direction l_w in the plane of unit n and l at cosine mu_w = saturate((n.l + w)/(1 + w))
    from n, w = saturate(wrap); l_w is 0 when l = -n (where mu_w = 0 for w < 1).  ``clamp=False`` keeps the
    directions beyond the wrap's reach below the horizon (mu_w < 0) instead of on it: a light's corners mapped so
    keep its shape for the horizon handling of the LTC integrals (core/ltc/shading.py)."""
    w = op.saturate(wrap)
    mu = op.dot(n, l)
    mu_w = (mu + w) / (1.0 + w)
    if clamp:
        mu_w = op.saturate(mu_w)
    tangent = op.normalize(l - op.scale(n, mu))          # normalize of zero is zero (core/ir/semantics.py)
    return op.scale(n, mu_w) + op.scale(tangent, op.sqrt(1.0 - mu_w * mu_w)), mu_w


def cod_wrapped_diffuse_cosine(albedo, n, v, l, alpha, wrap):
    """Multiscattering wrapped diffuse, the term that replaces f * mu_l: f_CoD(l_w, v) mu_w / (1 + w)
    (``wrapped_light_direction``) for unit n, v, l; zero below the view's horizon; w in [0, 1]."""
    l_w, mu_w = wrapped_light_direction(n, l, wrap)
    h = op.normalize(l_w + v)
    f = cod_multiscatter_diffuse(albedo, mu_w, op.dot(n, v), op.dot(n, h), op.dot(l_w, h), alpha)
    return f * mu_w / (1.0 + op.saturate(wrap))


def wrapped_diffuse_cosine(mu_l, wrap):
    """Normalised wrapped Lambert, the term that replaces f * mu_l: max(mu_l + w, 0) / (pi (1 + w)^2).

    The talk (section "How to combine LTCs with wrapped diffuse") wraps lighting as
    (cos + w)/(1 + w) / pi and normalises by the ratio of the lit area 2 pi (1 + w) to the
    hemisphere 2 pi (the talk prints that ratio as 1/(1 + w); the factor applied is its
    inverse).  The result equals this form, and integration confirms it conserves energy
    exactly: int_sphere max(cos + w, 0)/(1 + w)^2 dw = 2 pi (1 + w)^2 / 2 / (1 + w)^2 = pi,
    the same as Lambert's cosine lobe, so a uniform environment gives albedo 1 for every w
    (tested).  Filament's Fd_Wrap uses the same normalisation.  w in [0, 1]; w = 0 is Lambert.
    """
    w = op.saturate(wrap)
    return op.maximum(mu_l + w, 0.0) / (np.pi * (1.0 + w) * (1.0 + w))


def wrapped_normal(n, l, wrap):
    """The talk's ``WrappedNormal``: tilt N towards L so a clamped cosine mimics wrapped lighting.

    sin(phi) = lerp(w, 0, saturate((n.l + w)/(1 + w))), cos(phi) = sqrt(1 - sin^2),
    N' = normalize(cos(phi) N + sin(phi) ((N x L) x N)).  (N x L) x N = L - (N.L) N has
    length sin(theta), not 1, as in the talk; the final normalisation absorbs it.  When
    L = -N and w = 1 the sum is the zero vector; N is returned there (Blender's Normalize
    would give 0, so nodes select N explicitly too).
    """
    w = op.saturate(wrap)
    cos_theta = op.dot(n, l)
    wrapped = op.saturate((cos_theta + w) / (1.0 + w))
    sin_phi = op.mix(w, 0.0, wrapped)
    cos_phi = op.sqrt(1.0 - sin_phi * sin_phi)
    tilted = op.scale(n, cos_phi) + op.scale(op.cross(op.cross(n, l), n), sin_phi)
    return op.vselect(op.greater(op.dot(tilted, tilted), 0.0), op.normalize(tilted), n)
