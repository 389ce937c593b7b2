"""Specular occlusion from ambient occlusion: how much of the world's specular reflection an occluded point sees.

Ambient occlusion (AO) is the cosine-weighted visible fraction of the hemisphere above a point; it darkens the
diffuse part of the World term directly.  The specular part needs a specular occlusion (SO): the visible fraction
of the specular lobe, which AO alone does not determine.  Two estimates engines ship, each written once here with
``shading_ops`` (so numpy, nodes and shader text compute the same), and the integral they approximate:

- ``specular_occlusion_lagarde``: Lagarde & de Rousiers 2014, "Moving Frostbite to PBR", section 4.10.2: SO = saturate((N.V + AO)^(2^(-16 alpha - 1)) - 1 + AO), a fit with no direction in it.
- ``specular_occlusion_cones``: Jimenez, Wu, Pesce & Jarabo 2016, "Practical Real-Time Strategies for Accurate
  Indirect Occlusion", their specular occlusion (GTSO): the visible directions as a cone about the normal whose
  cosine-weighted solid angle is AO (cos = sqrt(1 - AO)), the specular lobe as a cone about the reflection
  direction, SO = the solid angle of their intersection over the lobe cone's.  The intersection is Oat &
  Sander 2007's smoothstep in the angle between the cones ("Ambient Aperture Lighting"), as Jimenez et al. use it;
  the lobe cone's cosine is 10^(-alpha^2) (2^(-3.321928 alpha^2)), the aperture Filament ships
  (shaders/src/surface_ambient_occlusion.fs).  Without a bent normal the visibility cone is about N.
- ``specular_occlusion_cones_clipped``: the same cones, normalised by the part of the lobe cone above the horizon
  (this project's variant: at AO = 1 it is 1).
- ``specular_occlusion_reference``: the model these approximate, integrated: the GGX specular reflection (F = 1,
  height-correlated Smith) of the view direction, sampled by its visible normals (Heitz 2018), counting only the
  light directions inside the visibility cone.  SO = visible energy / all of it.

Where the estimates disagree with the reference, and by how much per (N.V, r, AO), is measured by
``python scripts/benchmark_specular_occlusion.py`` (docs/benchmarks/specular_occlusion.md).
"""
from __future__ import annotations

import math

import numpy as np

from . import shading_ops as op
from .conventions import alpha_from_roughness
from .energy import view_vector
from .microfacet import reflect, sample_ggx_vndf, smith_g1, smith_g2_height_correlated
from .sampling import hammersley_2d


class Cone:
    """A cone of directions about an axis, by its half-angle and 1 - cos(half-angle) (its solid angle over 2 pi).

    Both are computed from the model's parameter without forming cos first: the lobe cone of a mirror-like surface
    has 1 - cos ~ 2.3 alpha^2, which is 0 in float32 below alpha ~ 2e-4 (r ~ 0.015) when taken as 1 - 10^(-alpha^2),
    and every ratio of solid angles then divides by 0."""

    def __init__(self, one_minus_cos, half_angle):
        self.one_minus_cos, self.half_angle = one_minus_cos, half_angle


def visibility_cone(ao):
    """The cone about N whose cosine-weighted share of the hemisphere is ``ao``: the share of a cone of half-angle t is
    sin^2 t (Jimenez et al. 2016), so sin t = sqrt(AO) and 1 - cos t = AO / (1 + sqrt(1 - AO))."""
    ao = op.saturate(ao)
    return Cone(op.safe_div(ao, 1.0 + op.sqrt(1.0 - ao)), op.asin(op.sqrt(ao)))


def specular_cone(alpha):
    """The cone that stands for the GGX lobe of ``alpha``: cos = 10^(-alpha^2), Filament's aperture.  1 - cos =
    1 - e^(-t), t = ln(10) alpha^2, by its series below t = 0.01 (error < t^4/24); half-angle 2 asin(sqrt((1 - cos)/2))."""
    t = 2.302585 * alpha * alpha
    one_minus_cos = op.select(op.less(t, 0.01), t * (1.0 - t * (0.5 - t * (1.0 / 6.0))), 1.0 - op.exp(-t))
    return Cone(one_minus_cos, 2.0 * op.asin(op.sqrt(0.5 * one_minus_cos)))


#: The upper hemisphere as a cone about N.
HEMISPHERE = Cone(1.0, 0.5 * math.pi)     # Python floats: no float64 scalar into the float32 path


def caps_intersection(cone_a, cone_b, cos_d):
    """Solid angle of the intersection of two spherical caps (``Cone``s) whose axes are ``cos_d`` apart, over
    2 pi: Oat & Sander 2007's approximation (a smoothstep between touching and nested caps).  Exact acos and asin
    (``shading_ops`` clamps their arguments), not the fast fits engines use."""
    a, b, d = cone_a.half_angle, cone_b.half_angle, op.acos(cos_d)
    small_cap = op.minimum(cone_a.one_minus_cos, cone_b.one_minus_cos)
    delta = op.absolute(a - b)
    x = 1.0 - op.saturate(op.safe_div(d - delta, op.maximum(a + b - delta, 1e-4)))
    return small_cap * x * x * (3.0 - 2.0 * x)


def specular_occlusion_cones(n_dot_r, ao, roughness):
    """GTSO without a bent normal (Jimenez et al. 2016): the visibility cone about N and the lobe cone about
    the reflection direction R (``n_dot_r`` = N.R), their intersection over the lobe cone; in [0, 1]."""
    lobe = specular_cone(alpha_from_roughness(roughness))
    return op.saturate(op.safe_div(caps_intersection(visibility_cone(ao), lobe, n_dot_r), lobe.one_minus_cos))


def specular_occlusion_cones_clipped(n_dot_r, ao, roughness):
    """The cones of ``specular_occlusion_cones`` with the lobe cone first clipped by the horizon: the intersection at
    ``ao`` over the intersection at AO = 1 (the visibility cone the whole hemisphere), so that AO = 1 occludes
    nothing, where the plain ratio darkens rough and grazing lobes that reach below the horizon.  A variant of this
    project (measured in docs/benchmarks/specular_occlusion.md), not a published one."""
    lobe = specular_cone(alpha_from_roughness(roughness))
    above_horizon = caps_intersection(HEMISPHERE, lobe, n_dot_r)
    return op.saturate(op.safe_div(caps_intersection(visibility_cone(ao), lobe, n_dot_r), above_horizon))


def specular_occlusion_lagarde(n_dot_v, ao, roughness):
    """Lagarde & de Rousiers 2014, section 4.10.2: saturate((N.V + AO)^(2^(-16 alpha - 1)) - 1 + AO), alpha = r^2 (their
    "roughness" is Frostbite's alpha, as Filament reads it too)."""
    alpha = alpha_from_roughness(roughness)
    base = op.saturate(n_dot_v) + op.saturate(ao)
    return op.saturate(op.exp2(op.exp2(-16.0 * alpha - 1.0) * op.log2(base)) - 1.0 + op.saturate(ao))


def specular_occlusion_reference(mu, roughness, ao, samples=1 << 14):
    """The visible share of the GGX reflection of a view at ``mu`` = N.V when the visible directions are the cone
    about N of cosine-weighted share ``ao`` (scalars).  Heitz 2018 VNDF sampling: each microfacet normal m gives the
    light direction l = reflect(v, m) with weight G2(l, v) / G1(v) (the estimator of the BRDF times cos); SO is the
    weighted share of the l inside the cone (the estimator of ``energy.split_sum_terms``, written out here: that file
    is a LUT bake source).  Float64; Hammersley points, so the same figures every run."""
    alpha = float(alpha_from_roughness(roughness))
    v = view_vector(mu)
    mu = float(v[2])
    u1, u2 = hammersley_2d(samples)
    m = sample_ggx_vndf(np.broadcast_to(v, (samples, 3)), alpha, u1, u2)
    l = reflect(np.broadcast_to(v, (samples, 3)), m)
    mu_l = l[:, 2]
    weight = np.where(mu_l > 0.0, smith_g2_height_correlated(np.maximum(mu_l, 1e-12), mu, alpha)
                      / smith_g1(mu, alpha), 0.0)
    total = weight.sum()
    if total <= 0.0:
        return 1.0
    visible = mu_l >= math.sqrt(1.0 - min(max(float(ao), 0.0), 1.0))      # the cone of visibility_cone(ao)
    return float(weight[visible].sum() / total)


#: Occlusion model (``rt_lit_interface.OCCLUSION_MODELS``, "none" excepted) -> its specular occlusion, a function
#: of (N.V, AO, Blender roughness).  Without a bent normal the lobe's axis is the mirror direction R, and
#: N.R = N.V.
SPECULAR_OCCLUSION = {
    "lagarde": specular_occlusion_lagarde,
    "cones": specular_occlusion_cones,
    "cones_clipped": specular_occlusion_cones_clipped,
}
