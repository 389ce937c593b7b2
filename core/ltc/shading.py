"""Area-light shading with LTCs: the talk's combinations, for numpy and for shader nodes.

Every function returns outgoing radiance per unit emitted radiance of the light (multiply by
the light's radiance).  Geometry is world-space: shading point ``p``, unit normal ``n``, unit
view ``v`` (towards the eye), and a light built with ``QuadLight`` or ``DiskLight``; ``tables``
is a ``core.lut.lookup.LutSet`` (holding data for numpy, ``lookup.REFERENCES`` when traced).  Written with ``core.shading_ops`` only: called with numpy
arrays (vectors = (..., 3) arrays, vectorised over shading points) it computes; called with
``core.ir.Expr`` inputs (``core.ir.trace``) it builds the node graph, where the LTC table
lookups are ``lut`` nodes and each light integral is one call of ``polygon.LTC_QUAD_INTEGRAL`` /
``disk.LTC_DISK_INTEGRAL`` (a nested node group).  The local frame is computed once per
(n, v) when traced (hash-consing shares it between lobes).

The integrals read the sphere table from the same ``tables`` (``ltc_ggx_mag``, channel A: the same
table in every LUT folder).
"""
from __future__ import annotations

import functools
import operator
from dataclasses import dataclass

from .. import diffuse, light_spread, multiscatter, sheen
from .. import shading_ops as op
from ..ir.functions import NodeFunction
from ..ir.interface import factor, scalar, vector
from ..lut import catalog
from . import disk, matrix, polygon

#: The talk's Disney sheen uses the CoD diffuse tables at this roughness (smoothness 0.5).
SHEEN_TABLE_ROUGHNESS = 0.5

#: Packed entries (c0, c1, c2, c3) of the identity Minv (Lambert: the exact form factor).
IDENTITY = (1.0, 0.0, 0.0, 1.0)


@dataclass(frozen=True)
class QuadLight:
    """A planar quad: four corners in order, as a sequence of vectors (arrays (..., 3) or Expr vectors)
    or an array (..., 4, 3).  One-sided lights emit on the side away from which (c1 - c0) x (c3 - c0)
    points (corners clockwise seen from the lit side; ltc_code's convention, ``polygon.behind``).
    ``two_sided``: bool, or a 0/1 float / Expr.  ``center_point``: the centre, when known more precisely
    than the corners' mean (the light's location: the side test uses it, ``polygon.behind``).
    ``exact_horizon``: the lobes' integrals clip the transformed light at the horizon instead of reading the
    sphere table (``integral``; issue 30, docs/area_lights.md "RT Lit's exact horizon").
    ``spread``: Blender's spread (a ``core.light_spread.SpreadCone``; the corners are then the region it clamps the
    light to): every integral is weighted by the spread's weight averaged under its own lobe (``spread_weighted``)."""
    corners: object
    two_sided: object = False
    center_point: object = None
    exact_horizon: bool = False
    spread: object = None

    def corner_list(self):
        corners = polygon.corner_vectors(self.corners)
        if len(corners) != 4:
            raise ValueError("a quad light needs four corners")
        return corners

    def center(self):
        if self.center_point is not None:
            return self.center_point
        return op.scale(functools.reduce(operator.add, self.corner_list()), 0.25)

    def integral(self, tables, c, frame, p, exact_horizon=None):
        """LTC integral for packed Minv entries c in the shading frame ``frame`` (``polygon.local_frame``);
        ``exact_horizon`` (None: the light's own): clip the transformed quad at the horizon
        (``polygon.LTC_QUAD_INTEGRAL_CLIPPED``) instead of the sphere table."""
        exact_horizon = self.exact_horizon if exact_horizon is None else exact_horizon
        local = [polygon.frame_coordinates(frame, q - p) for q in self.corner_list()]
        args = {f"c{i}": c[i] for i in range(4)}
        args.update({f"p{i}": local[i] for i in range(4)})
        args["Center"] = polygon.frame_coordinates(frame, self.center() - p)
        args["Two Sided"] = self.two_sided
        fn = polygon.LTC_QUAD_INTEGRAL_CLIPPED if exact_horizon else polygon.LTC_QUAD_INTEGRAL
        return self.spread_weighted(fn(tables, **args)["Integral"], c, frame, p)

    def clipped_form_factor(self, frame, p):
        """Lambert's form factor clipped exactly at the horizon (``polygon.QUAD_FORM_FACTOR_CLIPPED``)."""
        args = {f"p{i}": polygon.frame_coordinates(frame, q - p) for i, q in enumerate(self.corner_list())}
        args["Center"] = polygon.frame_coordinates(frame, self.center() - p)
        args["Two Sided"] = self.two_sided
        return self.spread_weighted(polygon.QUAD_FORM_FACTOR_CLIPPED(**args)["Integral"], IDENTITY, frame, p)

    def spread_weighted(self, value, c, frame, p):
        """``value`` (the integral of the LTC with packed Minv c over the light) times the spread's weight averaged
        under that LTC (``light_spread.lobe_average``); ``value`` itself for a light without spread."""
        if self.spread is None:
            return value
        corners = self.corner_list()
        axis_u, axis_v = op.scale(corners[1] - corners[0], 0.5), op.scale(corners[3] - corners[0], 0.5)
        return value * spread_average("quad", self.spread, self.center(), axis_u, axis_v, p, c, frame)


def _lobe_space(c, frame):
    """The linear map from world vectors into an LTC's space: the shading frame's coordinates, then Minv."""
    return lambda d: matrix.transform_packed(c, polygon.frame_coordinates(frame, d))


_FRAME = ("T1", "T2", "N")
_SPREAD_DISK = ("Spread Disk Center", "Spread Disk Axis U", "Spread Disk Axis V")


def _spread_average_function(form):
    """``light_spread.lobe_average`` under the LTC of packed Minv c0..c3 in the frame (T1, T2, N), as one node
    function per light form (its rules are functions of their own: core/light_spread.py)."""
    def body(**kw):
        disk = tuple(kw[n] for n in _SPREAD_DISK) if form == "disk" else None
        cone = light_spread.SpreadCone(kw["Spread Foot"], kw["Spread Radius"], kw["Spread Scale"], disk)
        to_lobe = _lobe_space(tuple(kw[f"c{i}"] for i in range(4)), tuple(kw[n] for n in _FRAME))
        return {"Average": light_spread.lobe_average(cone, form, kw["Center"], kw["Axis U"], kw["Axis V"],
                                                     kw["Position"], to_lobe)}

    inputs = {f"c{i}": scalar(0.0, f"Packed Minv entry {i} of the lobe's LTC") for i in range(4)}
    inputs.update({n: vector(f"The shading frame's {n} (polygon.local_frame)") for n in _FRAME})
    inputs.update({"Position": vector("The shading point"), "Center": vector("The region's centre"),
                   "Axis U": vector("The region's first half-axis"), "Axis V": vector("The region's second half-axis"),
                   "Spread Foot": vector("The shading point's foot on the light's plane"),
                   "Spread Radius": scalar(0.0, "The spread cone's radius R"),
                   "Spread Scale": scalar(0.0, "The spread's normalisation c")})
    if form == "disk":
        inputs.update({n: vector(f"The disk light's own {n[12:].lower()}") for n in _SPREAD_DISK})
    return NodeFunction(f"RTL Spread {form.capitalize()} Average", body, inputs,
                        {"Average": scalar(0.0, "The spread's weight averaged under the lobe's kernel")},
                        "The spread's weight averaged over a light's region under an LTC lobe's kernel "
                        "(core/light_spread.py, lobe_average)")


#: Form -> the node function of the spread's average under a lobe (``spread_average``).
SPREAD_AVERAGE = {form: _spread_average_function(form) for form in ("quad", "disk")}


def spread_average(form, cone, centre, axis_u, axis_v, p, c, frame):
    """The spread's weight averaged over the region under the lobe of packed Minv ``c`` in ``frame``
    (``light_spread.lobe_average``), one call of ``SPREAD_AVERAGE[form]``."""
    args = {f"c{i}": c[i] for i in range(4)}
    args.update(zip(_FRAME, frame))
    args.update({"Position": p, "Center": centre, "Axis U": axis_u, "Axis V": axis_v, "Spread Foot": cone.foot,
                 "Spread Radius": cone.radius, "Spread Scale": cone.scale})
    if form == "disk":
        args.update(zip(_SPREAD_DISK, cone.disk))
    return SPREAD_AVERAGE[form](**args)["Average"]


@dataclass(frozen=True)
class DiskLight:
    """An ellipse (disk when |axis_u| = |axis_v|): centre and semi-axis vectors (arrays (..., 3) or Expr
    vectors).  One-sided lights emit on the side away from which axis_u x axis_v points (as ``QuadLight``);
    ``spread`` as ``QuadLight``'s."""
    center: object
    axis_u: object
    axis_v: object
    two_sided: object = False
    exact_horizon: bool = False
    spread: object = None

    def integral(self, tables, c, frame, p, exact_horizon=None):
        """As ``QuadLight.integral``; ``exact_horizon``: ``disk.LTC_DISK_INTEGRAL_CLIPPED``."""
        exact_horizon = self.exact_horizon if exact_horizon is None else exact_horizon
        args = {f"c{i}": c[i] for i in range(4)}
        args.update({"Center": polygon.frame_coordinates(frame, self.center - p),
                     "Axis U": polygon.frame_coordinates(frame, self.axis_u),
                     "Axis V": polygon.frame_coordinates(frame, self.axis_v),
                     "Two Sided": self.two_sided})
        fn = disk.LTC_DISK_INTEGRAL_CLIPPED if exact_horizon else disk.LTC_DISK_INTEGRAL
        return self.spread_weighted(fn(tables, **args)["Integral"], c, frame, p)

    def spread_weighted(self, value, c, frame, p):
        """As ``QuadLight.spread_weighted``, the average over the ellipse."""
        if self.spread is None:
            return value
        return value * spread_average("disk", self.spread, self.center, self.axis_u, self.axis_v, p, c, frame)


def lobe_integral(tables, prefix, light, p, n, v, roughness):
    """(LTC integral, magnitude, fresnel) of one table's lobe at this shading point (with its band, for a lobe
    that has one: ``band_integral``); the light's ``exact_horizon`` says how it meets the horizon."""
    mu = op.saturate(op.dot(n, v))
    frame = polygon.local_frame(n, v)
    band = catalog.LTC_BANDS.get(prefix)
    if band is None:
        packed, magnitude, fresnel = tables.ltc(prefix, mu, roughness)
        return light.integral(tables, packed, frame, p), magnitude, fresnel
    packed, magnitude, fresnel, weight = tables.ltc(prefix, mu, roughness, band_weight=True)
    return band_integral(tables, light, packed, weight, band["squash"], frame, p), magnitude, fresnel


# The band (this project's, issue 15; docs/area_lights.md, "The band"): the lobe is the mixture
# (1 - w) D(Minv) + w D(Minv diag(1, 1, k)) of the fitted LTC and the same LTC pressed towards the horizon
# (``matrix.squash_packed``), so its integral is the same mixture of the two LTC integrals (Heitz et al. 2016,
# eq. 11, for each), written main + w (band - main); w is bounded by [0, 1] (saturate) as the fit bounds it.
def mix_band(main, band, weight):
    """The mixture's integral from the two LTC integrals and the band's weight."""
    return main + op.saturate(weight) * (band - main)


def band_integral(tables, light, packed, weight, squash, frame, p):
    """Integral of the LTC with packed entries ``packed`` mixed with its band (squash factor ``squash``) by
    ``weight``, over the light, in the shading frame ``frame``."""
    return mix_band(light.integral(tables, packed, frame, p),
                    light.integral(tables, matrix.squash_packed(packed, squash), frame, p), weight)


# Heitz et al. 2016 with Hill 2016's Fresnel split: int f cos F = F0 (mag - fres) + F90 fres.
def ggx_specular(tables, light, p, n, v, roughness, f0, f90=1.0):
    value, magnitude, fresnel = lobe_integral(tables, "ltc_ggx", light, p, n, v, roughness)
    return value * (f0 * (magnitude - fresnel) + f90 * fresnel)


# The talk, "No implementation for multiscattering specular": scale f_ss by Turquin's
# 1 + F0 (1 - E)/E or by the approximation to Fdez-Aguera, E = the GGX table's magnitude.
def ggx_specular_multiscatter(tables, light, p, n, v, roughness, f0, method="turquin"):
    if method not in ("turquin", "fdez_aguera"):
        raise ValueError(f"unknown multiscattering method {method!r}")
    value, magnitude, fresnel = lobe_integral(tables, "ltc_ggx", light, p, n, v, roughness)
    single = value * (f0 * (magnitude - fresnel) + fresnel)
    if method == "turquin":
        return single * multiscatter.turquin_compensation(f0, magnitude)
    return single * multiscatter.fdez_aguera_area_scale(f0, magnitude)


# The talk, "LTCs for multiscattering diffuse": the CoD WWII lobe's own LTC (albedo 1 in the table).
# Chan 2018's fit reflects more than it receives for rough surfaces seen at grazing angles (its directional
# albedo, the table's magnitude, reaches 1.14 at r = 1, mu_v -> 0; docs/robustness.md), so the magnitude is
# bounded by 1 (``albedo_bound``): a white CoD surface stays within the white furnace under any light.
def albedo_bound(magnitude):
    """min(magnitude, 1): a lobe's directional albedo, bounded by energy conservation."""
    return op.minimum(magnitude, 1.0)


def cod_diffuse(tables, light, p, n, v, roughness, albedo):
    value, magnitude, _ = lobe_integral(tables, "ltc_cod_diffuse", light, p, n, v, roughness)
    return albedo_bound(magnitude) * value * albedo


# The talk, "LTCs for Ashikhmin cloth": the cloth lobe's LTC (sheen colour 1 in the table).
def ashikhmin_cloth(tables, light, p, n, v, roughness, sheen_color):
    value, magnitude, _ = lobe_integral(tables, "ltc_cloth", light, p, n, v, roughness)
    return magnitude * value * sheen_color


def disney_sheen(tables, light, p, n, v, sheen_color):
    """The talk: f_sheen(theta) ~ LTC_MagFresnel,MSDiffuse(theta, 0.5): the Fresnel channel of the
    CoD diffuse table at r = 0.5 with that table's LTC.  The CoD lobe carries 1/pi and Disney
    sheen (1 - l.h)^5 does not (Burley 2012), hence the factor pi; the error of the whole
    approximation is measured in docs/benchmarks/ltc.md."""
    value, _, fresnel = lobe_integral(tables, "ltc_cod_diffuse", light, p, n, v, SHEEN_TABLE_ROUGHNESS)
    return fresnel * value * sheen_color * 3.141592653589793


# Zeltner et al. 2022 (core/sheen.py): the sheen lobe IS an LTC, Minv = [[a, 0, b], [0, a, 0], [0, 0, 1]]
# (packed (1, 0, b/a, 1/a)), so its integral over the light is the LTC integral times the albedo R(mu_v, r);
# Cycles' cut-off (|a| or R < 1e-5: no lobe) is kept.  Quads are clipped exactly at the horizon: at low sheen
# roughness the lobe lives next to it, where the sphere table's cap misses the clipped polygon (measured in
# the validation suite: 25-28% median at r = 0.2 under quads with the sphere table; docs/sheen.md).
def zeltner_sheen(tables, light, p, n, v, roughness):
    """(radiance per unit light radiance, albedo R(mu_v)) of the Zeltner sheen lobe over the light."""
    mu = op.saturate(op.dot(n, v))
    a, b, albedo = tables.zeltner_sheen(mu, sheen.zeltner_roughness(roughness))
    keep = op.logical_and(sheen.zeltner_active(a, albedo), op.greater(op.dot(n, v), 0.0))
    value = light.integral(tables, sheen.zeltner_packed_inverse(a, b), polygon.local_frame(n, v), p,
                           exact_horizon=True)
    return op.select(keep, value * albedo, 0.0), op.select(keep, albedo, 0.0)


# Disney sheen (1 - l.h)^5 (Burley 2012) with its own fitted LTC (table ltc_disney_sheen, core/ltc/fit_lobes.py):
# the lobe has no roughness, so the table is read at r = 0.
def disney_sheen_fitted(tables, light, p, n, v, sheen_color):
    value, magnitude, _ = lobe_integral(tables, "ltc_disney_sheen", light, p, n, v, 0.0)
    return magnitude * value * sheen_color


# Lambert is the identity LTC (Heitz et al. 2016, section 5): the light's exact form factor above the horizon.
# Where the light crosses it the clipless form's sphere table stands for a cap far from the clipped polygon (issue
# 30's minimal case: 0.00180 for 0.00034, +424%); a light with ``exact_horizon`` clips it (the quad exactly, with exact
# edges; the disk by its closed form above the horizon and its clipped boundary integral where it crosses).
def lambert(tables, light, p, n, v, albedo):
    """Lambert's form factor of the light (clipped at the horizon where the light says so) times ``albedo``."""
    frame = polygon.local_frame(n, v)
    if isinstance(light, DiskLight) and light.spread is not None:
        return disk_spread_form_factor(light, frame[2], p) * albedo
    if isinstance(light, QuadLight) and light.exact_horizon:
        return light.clipped_form_factor(frame, p) * albedo
    return light.integral(tables, IDENTITY, frame, p) * albedo


def disk_spread_form_factor(light, n, p):
    """Lambert's form factor of a disk light with spread, exact along each ray (``light_spread.LAMBERT_DISK``; the
    horizon clipped whatever the light's ``exact_horizon``), 0 behind a one-sided light."""
    return light_spread.lambert_disk_form_factor(light.spread, p, n, light.two_sided)


def light_center(light):
    return light.center if isinstance(light, DiskLight) else light.center()


# The talk, "How to combine LTCs with wrapped diffuse": tilt N towards the light's centre
# (WrappedNormal), integrate the clamped cosine about the tilted normal, normalise by 1/(1 + w).
def wrapped_diffuse(tables, light, p, n, v, albedo, wrap):
    to_light = op.normalize(light_center(light) - p)
    n_wrapped = diffuse.wrapped_normal(n, to_light, wrap)
    return lambert(tables, light, p, n_wrapped, v, albedo) / (1.0 + op.saturate(wrap))


# --- multiscattering wrapped diffuse over an area light ------------------------------------------------------
# The lobe is defined in core/diffuse.py: f_w(l) mu_l = f_CoD(l_w) mu_w / (1 + w), l_w the wrapped light direction
# (azimuth kept, mu -> mu_w = (mu + w)/(1 + w)).  The map's Jacobian is exactly 1/(1 + w) (dl = (1 + w) dl_w), so
#     int_light f_w(l) mu_l dl  =  int_{image of the light} f_CoD(l') mu' dl',
# the CoD lobe over the light's image under the map: we map the light's corners (a disk: its centre and the ends
# of its semi-axes) and integrate the CoD LTC over the polygon (ellipse) they span, which is exact as the light
# shrinks.  Points beyond the wrap's reach (mu < -w) are mapped below the horizon (mu_w < 0, unclamped), where the
# integrals' horizon handling takes them as it takes any light below the horizon, so w = 0 is the CoD area form
# exactly.  The image is integrated two-sided; the original light's own side test decides whether it shines.
# The talk's construction, the CoD LTC about the normal tilted towards the light, / (1 + w)
# (``cod_wrapped_diffuse_tilted``), measured 10-18% median error against the lobe's integral where the image gives
# 2-3% (docs/area_lights.md, "Multiscattering wrapped diffuse").

def _wrapped_point(**kw):
    direction, _ = diffuse.wrapped_light_direction(kw["N"], op.normalize(kw["Point"]), kw["Wrap"], clamp=False)
    return {"Direction": direction}


WRAPPED_LIGHT_POINT = NodeFunction(
    "RTL Wrapped Light Point", _wrapped_point,
    {"Point": vector("A point of the light, relative to the shading point", "XYZ", hide_value=True),
     "N": vector("Unit shading normal", "NONE", hide_value=True),
     "Wrap": factor(0.0, "Wrapped-diffuse amount w")},
    {"Direction": vector("Unit direction the normalised wrap maps the point's direction to, below the horizon "
                         "beyond its reach (0 for -N)", "NONE")},
    "Where the normalised wrap moves a light point's direction (core/diffuse.py wrapped_light_direction)")


def _wrapped(point, n, wrap):
    return WRAPPED_LIGHT_POINT(Point=point, N=n, Wrap=wrap)["Direction"]


#: Least cosine between a mapped disk point's direction and the light's plane normal, for placing it back on the
#: plane.
WRAPPED_DISK_COS_MIN = 0.05


def light_shines(light, p):
    """1.0 where the shading point ``p`` sees the light's emitting side off its plane (``polygon.behind`` /
    ``off_plane`` for quads, the disk integral's own test for disks), 0 else; two-sided lights shine both ways."""
    if isinstance(light, DiskLight):
        c, normal = light.center - p, op.cross(light.axis_u, light.axis_v)
        side = op.dot(c, normal)
        off = polygon.beyond_plane(side, polygon.EDGE_ON_SIN * op.length(c) * op.length(normal))
        back = op.less(side, 0.0)
    else:
        rel = [q - p for q in light.corner_list()]
        center = light.center() - p
        off, back = polygon.off_plane(rel, center), polygon.behind(rel, center)
    return op.select(off, op.select(back, 1.0 * light.two_sided, 1.0), 0.0)


def wrapped_light(light, p, n, wrap):
    """The light's image under the normalised wrap seen from ``p``, two-sided: a ``QuadLight`` of the mapped corners
    (unit distance), or a ``DiskLight`` through the mapped ends of the semi-axes placed back on the light's plane
    (conjugate semi-axes of the image, to first order; w = 0 gives the light itself)."""
    if isinstance(light, QuadLight):
        corners = [p + _wrapped(q - p, n, wrap) for q in light.corner_list()]
        return QuadLight(corners, two_sided=True, center_point=p + _wrapped(light.center() - p, n, wrap),
                         exact_horizon=light.exact_horizon)
    c = light.center - p
    normal = op.cross(light.axis_u, light.axis_v)
    depth = op.dot(normal, c)
    side = op.select(op.greater(depth, 0.0), 1.0, -1.0)
    floor = WRAPPED_DISK_COS_MIN * op.length(normal)

    # where the mapped direction meets the light's plane: w = 0 gives the disk's own points; a direction the wrap
    # turned (nearly) parallel to the plane is taken at a grazing hit
    def on_plane(point):
        d = _wrapped(point, n, wrap)
        return op.scale(d, op.absolute(depth) / op.maximum(op.dot(normal, d) * side, floor))

    u1, u2 = on_plane(c + light.axis_u), on_plane(c - light.axis_u)
    v1, v2 = on_plane(c + light.axis_v), on_plane(c - light.axis_v)
    # the centre mapped itself, not the mean of the four points: for a light much larger than its distance the
    # points are ~|axis| away and their mean loses the centre to float32 rounding
    return DiskLight(p + on_plane(c), op.scale(u1 - u2, 0.5), op.scale(v1 - v2, 0.5), two_sided=True,
                     exact_horizon=light.exact_horizon)


def _wrapped_frame(**kw):
    n_wrapped = diffuse.wrapped_normal(kw["N"], op.normalize(kw["To Light"]), kw["Wrap"])
    return dict(zip(_FRAME, polygon.local_frame(n_wrapped, kw["V"])))


WRAPPED_FRAME = NodeFunction(
    "RTL Wrapped Frame", _wrapped_frame,
    {"N": vector("Unit shading normal", "NONE", hide_value=True), "V": vector("Unit view direction", "NONE"),
     "To Light": vector("The light's centre relative to the shading point", "XYZ", hide_value=True),
     "Wrap": factor(0.0, "Wrapped-diffuse amount w")},
    {name: vector(f"The frame's {name} about the wrapped normal", "NONE") for name in _FRAME},
    "The shading frame (polygon.local_frame) about the normal tilted towards the light by the wrap (the talk's "
    "WrappedNormal; core/diffuse.py)")


def cod_wrapped_diffuse(tables, light, p, n, v, roughness, albedo, wrap):
    """Multiscattering wrapped diffuse over an area light: the CoD LTC over the light's image under the wrap (a
    light with spread: times the spread's weight averaged under the cosine about the wrapped normal, as
    ``wrapped_diffuse`` weights it; the image is another region of the plane)."""
    value = cod_diffuse(tables, wrapped_light(light, p, n, wrap), p, n, v, roughness, albedo)
    if light.spread is not None:
        frame = WRAPPED_FRAME(N=n, V=v, Wrap=wrap, **{"To Light": light_center(light) - p})
        value = light.spread_weighted(value, IDENTITY, tuple(frame[name] for name in _FRAME), p)
    return op.select(op.greater(light_shines(light, p), 0.5), value, 0.0)


def cod_wrapped_diffuse_tilted(tables, light, p, n, v, roughness, albedo, wrap):
    """The talk's construction for comparison: the CoD LTC about the normal tilted towards the light's centre
    (WrappedNormal), / (1 + w)."""
    to_light = op.normalize(light_center(light) - p)
    n_wrapped = diffuse.wrapped_normal(n, to_light, wrap)
    return cod_diffuse(tables, light, p, n_wrapped, v, roughness, albedo) / (1.0 + op.saturate(wrap))
