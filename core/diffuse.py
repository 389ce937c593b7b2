"""Diffuse BRDFs: Lambert, Call of Duty WWII multiscattering diffuse, normalised wrapped diffuse."""
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


def cod_multiscatter_diffuse(albedo, mu_l, mu_v, n_dot_h, l_dot_h, alpha):
    """Call of Duty WWII multiscattering diffuse BRDF (Chan 2018, course notes; the talk).

    f = albedo/pi * (fd + fb) with
      f0 = (l.h) + (1 - l.h)^5                               rough limit
      f1 = (1 - 0.75 (1 - n.l)^5)(1 - 0.75 (1 - n.v)^5)     smooth limit
      fd = lerp(f0, f1, saturate(2.2 g - 0.5))
      fb = max((34.5 g - 59) g + 24.5, 0) (l.h) 2^(-max(73.2 g - 21.2, 8.9) sqrt(n.h))   retro-reflection
    The 1/pi belongs to the BRDF (multiply by mu_l for radiance).  Symmetric in l and v
    (l.h = v.h), so reciprocal.  Zero below either horizon.

    Deviation from the paper: the retro-reflection coefficient is clamped at 0 (``retro_reflection_scale``).
    """
    g = cod_gloss_from_alpha(alpha)
    ldh = op.saturate(l_dot_h)
    f0 = ldh + op.pow5(1.0 - ldh)
    f1 = (1.0 - 0.75 * op.pow5(1.0 - op.saturate(mu_l))) * (1.0 - 0.75 * op.pow5(1.0 - op.saturate(mu_v)))
    fd = op.mix(f0, f1, op.saturate(2.2 * g - 0.5))
    fb = retro_reflection_scale(g) * ldh * op.exp2(-op.maximum(73.2 * g - 21.2, 8.9) * op.sqrt(n_dot_h))
    above = op.logical_and(op.greater(mu_l, 0.0), op.greater(mu_v, 0.0))
    return op.select(above, albedo * (1.0 / np.pi) * (fd + fb), 0.0)


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
