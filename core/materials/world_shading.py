"""The World term of the RT Lit material: image-based lighting from the scene's environment.

The talk's "Light Type" tables list what each technique needs under an environment; this module is
that column, written with ``core.shading_ops`` so one source gives numpy evaluation and node groups:

* diffuse from L2 spherical harmonics (``core/indirect.py``): Lambert irradiance, the normalised
  wrapped lobe, and the talk's LTC-rotated cosine lobe for the CoD multiscattering diffuse (wrapped:
  the normalised wrapped lobe about that axis);
* specular by the split sum (Karis 2013): GGX-prefiltered radiance (``core/environment/prefilter.py``)
  looked up along the dominant specular direction (Lagarde & de Rousiers 2014), times the environment
  BRDF (F0 scale + bias); multiple scattering by the material's specular model (below), evaluated
  separately for the dielectric and the metallic F0 and then mixed by Metallic;
* cloth and sheen by the same LTC-rotated cosine lobe as the CoD diffuse, with their own tables.

Frames
------
SH coefficients and the prefiltered image are in the image's frame at strength 1 (the bake).  The
world shows L(d) = Strength image(R d), R the Mapping node's Euler XYZ rotation (Blender: R = Rz Ry Rx,
applied to the direction before the Environment Texture), so N and V are rotated into the image frame
once (``RTL World Rotation``) and the result is multiplied by Strength.

Multiple scattering under the environment (specular model of the material, F90 = 1)
-----------------------------------------------------------------------------------
With (A, B) the split-sum table at (mu_v, r), FssEss = F0 A + B, E = A + B, P the prefiltered
radiance, I = E(n)/pi the cosine-weighted mean radiance (SH):

* ``single``       FssEss P                                            (Karis 2013, eq. 4)
* ``turquin``      FssEss (1 + F0 (1 - E)/E) P                         (Turquin 2019, eq. 16)
* ``fdez_aguera``  irradiance form: FssEss P + FmsEms I                (Fdez-Aguera 2019, eq. 11-16)
                   radiance form (the talk): (FssEss + FmsEms) P       (``Features.environment_ms``)
* ``kulla_conty``  FssEss P + F_ms (1 - E) I: the Kulla-Conty lobe's directional albedo is exactly
                   1 - E(mu_v) (Kulla & Conty 2017, slide 18), its angular shape ~ cosine, so it is lit
                   by I; F_ms = F_avg E_avg / (1 - F_avg (1 - E_avg)) as for the lights.

Mixing the two F0 *after* these formulas is what three.js (#32190) and Bevy (#23203) got wrong:
they are non-linear in F0, so a mixed F0 = lerp(F0_dielectric, base colour, metallic) over-brightens
partly metallic surfaces.  The lights shade the two apart too (light_shading.SPLIT_F0_MODELS).

Occlusion (``Features.occlusion``, issue 29)
-------------------------------------------
With occlusion on, the renderer's ambient occlusion AO (Blender's Ambient Occlusion node; an engine's own AO)
scales the broad lobes (diffuse, rough diffuse, sheen, cloth) and a specular occlusion SO(N.V, AO, r) derived
from it scales the GGX specular (core/occlusion.py: Lagarde & de Rousiers 2014, section 4.10.2, or Jimenez et
al. 2016's cones).  Both are visibility estimates, not radiance ones: the occluder's own light is not added.

Specular dominant direction (Lagarde & de Rousiers 2014, "Moving Frostbite to PBR", listing 22):
lerp(N, R, s (sqrt(s) + alpha)) with s = 1 - alpha, alpha = r^2, R the mirror direction.
"""
from __future__ import annotations

import functools
import hashlib
import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import indirect, multiscatter, occlusion, rough_diffuse, shading_ops as op, sheen
from ..conventions import alpha_from_roughness
from ..fresnel import fresnel_average
from ..ir.functions import NodeFunction
from ..ir.interface import Socket, color, factor, vector
from ..ir.tables import Table
from ..ltc import polygon, shading as ltc_shading
from ..lut import exr_io
from ..lut.lookup import REFERENCES
from .light_shading import layer_sheen
from .rt_lit_interface import OCCLUSION_INPUT, OCCLUSION_SOCKET, SURFACE_OUTPUTS, world_input

PI = math.pi

SH_NAMES = tuple(f"SH {i}" for i in range(9))
#: The world's parameters as the RT Lit group receives them ("World <name>" inputs, from the shared
#: "RTL World" group written by addon/world.py).
WORLD_PARAMETERS = {
    **{name: color((0.0, 0.0, 0.0), f"L2 SH radiance coefficient {i} (R&H 2001 order), image frame, "
                                    "strength 1") for i, name in enumerate(SH_NAMES)},
    "Strength": Socket("float", 1.0, description="The Background node's Strength"),
    "Rotation": vector("Euler XYZ rotation (radians) of the world's Mapping node", "EULER"),
}

#: Tables of the LTC-rotated lobes (core/lut/catalog.py).
COD_TABLE = "ltc_cod_diffuse"
CLOTH_TABLE = "ltc_cloth"
SHEEN_TABLE_ROUGHNESS = 0.5       # the talk's sheen: the CoD table at r = 0.5 (core/ltc/shading.py)


# --- the prefiltered environment --------------------------------------------------------------------

@dataclass(frozen=True)
class WorldEnvironment:
    """A baked environment as shading code needs it: the prefiltered levels as one table (the EXR's
    rows, Blender order: row 0 at the bottom; level k in rows [k H, (k + 1) H)) and their roughness;
    ``source``: the EXR file it was read from (None when it came from elsewhere, e.g. a packed image)."""
    name: str                 # table / image name, e.g. env_<content hash>
    table: np.ndarray         # (L H, W, 4) float32
    roughness_levels: tuple
    source: object = None

    @classmethod
    def load(cls, prefiltered_path, name):
        """From a prefiltered EXR (``core.environment.prefilter``); exr_io's errors for an unreadable file,
        ValueError for another table."""
        table, meta = exr_io.read_table(prefiltered_path)
        if "roughness_levels" not in meta:
            raise ValueError(f"{prefiltered_path} holds the table {meta['table']!r}, not prefiltered levels "
                             "(no roughness_levels attribute)")
        levels = tuple(float(r) for r in json.loads(meta["roughness_levels"]))
        return cls(name, np.asarray(table, np.float32), levels, Path(prefiltered_path))

    @classmethod
    def from_bake(cls, bake):
        """From a ``core.environment.prefilter.EnvironmentBake``, named by its ``table_name``."""
        return cls.load(bake.prefiltered_path, bake.table_name)

    def __post_init__(self):
        levels = np.asarray(self.roughness_levels, np.float64)
        if len(levels) < 2 or not np.allclose(levels, np.linspace(levels[0], levels[-1], len(levels))):
            raise ValueError(f"prefiltered levels must be >= 2 evenly spaced roughnesses, got {self.roughness_levels}")
        if self.table.shape[0] % len(levels):
            raise ValueError(f"prefiltered table of {self.table.shape[0]} rows is not {len(levels)} levels")

    def as_table(self):
        """The prefiltered levels as a table of a table set (``core.ir.tables.Table``)."""
        return Table.from_array(self.name, self.table, self.source)

    @functools.cached_property
    def digest(self):
        """SHA-1 of the table's bytes: two environments are equal (and share traced functions) only when
        their data are."""
        return hashlib.sha1(np.ascontiguousarray(self.table, np.float32).tobytes()).hexdigest()

    def _key(self):
        return (self.name, self.table.shape, self.roughness_levels, self.digest)

    def __hash__(self):
        return hash(self._key())

    def __eq__(self, other):
        return isinstance(other, WorldEnvironment) and self._key() == other._key()


def _wrap(t):
    """t - floor(t): a REPEAT texture coordinate fetched with EXTEND (exact at texel centres)."""
    return t - op.floor(t)


# Blender's equirectangular mapping (core/environment/equirect.py, Cycles direction_to_equirectangular):
# u = 0.5 - atan2(y, x) / (2 pi), v = 1 - acos(z) / pi.  Bilinear within a level (REPEAT in u, rows
# clamped to the level), linear across the two levels around r: 8 exact Closest fetches (EEVEE's Linear
# filtering picks mipmaps from screen-space derivatives; core/ir/tables.py).
def _prefiltered_body(env):
    lut = env.as_table()
    n_levels = len(env.roughness_levels)
    h = env.table.shape[0] // n_levels
    w = env.table.shape[1]
    r_lo, r_hi = env.roughness_levels[0], env.roughness_levels[-1]

    def body(Direction, Roughness):
        d = op.normalize(Direction)
        x, y, z = (op.component(d, i) for i in range(3))
        u = 0.5 - op.atan2(y, x) * (1.0 / (2.0 * PI))
        v = 1.0 - op.acos(z) * (1.0 / PI)
        xs = u * w - 0.5
        x0 = op.floor(xs)
        fx = xs - x0
        cols = (_wrap((x0 + 0.5) * (1.0 / w)), _wrap((x0 + 1.5) * (1.0 / w)))
        ys = op.clamp(v * h - 0.5, 0.0, h - 1.0)
        y0 = op.minimum(op.floor(ys), h - 2.0)
        fy = ys - y0
        t = (op.clamp(Roughness, r_lo, r_hi) - r_lo) * ((n_levels - 1) / (r_hi - r_lo))
        k0 = op.minimum(op.floor(t), n_levels - 2.0)
        fk = t - k0
        total = None
        for dk, wk in ((0.0, 1.0 - fk), (1.0, fk)):
            for dy, wy in ((0.0, 1.0 - fy), (1.0, fy)):
                row = ((k0 + dk) * h + y0 + dy + 0.5) * (1.0 / (n_levels * h))
                for col, wx in ((cols[0], 1.0 - fx), (cols[1], fx)):
                    weight = wk * wy * wx
                    texel = op.vec3(*(op.texel_fetch(lut, col, row, c) for c in range(3)))
                    term = op.scale(texel, weight)
                    total = term if total is None else total + term
        return {"Radiance": total}

    return body


@functools.lru_cache(maxsize=8)
def prefiltered_function(env):
    """``RTL Environment <name>``: GGX-prefiltered radiance of ``env`` in a direction (image frame) at a
    roughness, strength 1."""
    return NodeFunction(f"RTL Environment {env.name}", _prefiltered_body(env),
                        {"Direction": vector("Lookup direction, image frame", "NONE", hide_value=True),
                         "Roughness": factor(0.5, "Blender roughness r")},
                        {"Radiance": color((0.0, 0.0, 0.0), "Prefiltered radiance (strength 1)")},
                        f"Split-sum GGX prefiltered radiance of {env.name} (8 exact texel fetches)")


# --- rotation into the image frame ------------------------------------------------------------------

# Blender's Euler XYZ: R = Rz(c) Ry(b) Rx(a) (Mapping node, type Point or Vector), applied to directions.
def euler_xyz_rows(rotation):
    sa, ca = op.sin(op.component(rotation, 0)), op.cos(op.component(rotation, 0))
    sb, cb = op.sin(op.component(rotation, 1)), op.cos(op.component(rotation, 1))
    sc, cc = op.sin(op.component(rotation, 2)), op.cos(op.component(rotation, 2))
    return (op.vec3(cc * cb, cc * sb * sa - sc * ca, cc * sb * ca + sc * sa),
            op.vec3(sc * cb, sc * sb * sa + cc * ca, sc * sb * ca - cc * sa),
            op.vec3(-1.0 * sb, cb * sa, cb * ca))


def _rotation(N, V, Rotation):
    rows = euler_xyz_rows(Rotation)
    return {"N": op.mat_vec(rows, N), "V": op.mat_vec(rows, V)}


_DIR = vector("Unit direction, world space", "NONE", hide_value=True)
WORLD_ROTATION = NodeFunction(
    "RTL World Rotation", _rotation, {"N": _DIR, "V": _DIR, "Rotation": WORLD_PARAMETERS["Rotation"]},
    {"N": vector("N in the image frame", "NONE"), "V": vector("V in the image frame", "NONE")},
    "World directions to the environment image's frame (the Mapping node's Euler XYZ rotation)")


# --- SH lobes ---------------------------------------------------------------------------------------

def _sh_lobe(**kw):
    coeffs = [kw[name] for name in SH_NAMES]
    zonal = (1.0, kw["Lambda 1"], kw["Lambda 2"])
    return {"Radiance": indirect.sh_zonal_eval(coeffs, op.normalize(kw["Axis"]), zonal)}


SH_LOBE = NodeFunction(
    "RTL SH Lobe", _sh_lobe,
    {**{name: WORLD_PARAMETERS[name] for name in SH_NAMES},
     "Axis": vector("Lobe axis (normalised inside)", "NONE", hide_value=True),
     "Lambda 1": Socket("float", 2.0 / 3.0, description="Funk-Hecke factor of band 1 (band 0: 1)"),
     "Lambda 2": Socket("float", 0.25, description="Funk-Hecke factor of band 2")},
    {"Radiance": color((0.0, 0.0, 0.0), "int L(w) k(axis.w) dw for the normalised zonal lobe k")},
    "SH environment seen through a normalised zonal lobe (Funk-Hecke; R&H 2001 basis)")


def sh_lobe(coeffs, axis, zonal):
    kw = dict(zip(SH_NAMES, coeffs))
    return SH_LOBE(**kw, Axis=axis, **{"Lambda 1": zonal[1], "Lambda 2": zonal[2]})["Radiance"]


def _ltc_axis_and_magnitude(tables, table, n, v, roughness):
    mu = op.saturate(op.dot(n, v))
    c, magnitude, fresnel = tables.ltc(table, mu, roughness)
    axis = indirect.ltc_lobe_axis(c, polygon.local_frame(n, v), "talk")
    return axis, magnitude, fresnel


# The talk, "LTCs for Spherical Harmonics": the cosine lobe rotated by the LTC inverse matrix of the
# BRDF (axis c1 T1 + c3 N), evaluated against the SH, scaled by the LTC magnitude.
def _ltc_lobe_function(title, table, description, fixed_roughness=None, use_fresnel=False):
    def body(tables, **kw):
        r = fixed_roughness if fixed_roughness is not None else kw["Roughness"]
        axis, magnitude, fresnel = _ltc_axis_and_magnitude(tables, table, kw["N"], kw["V"], r)
        amount = fresnel * PI if use_fresnel else ltc_shading.albedo_bound(magnitude)
        return {"Axis": op.normalize(axis), "Magnitude": amount}

    inputs = {"N": _DIR, "V": _DIR}
    if fixed_roughness is None:
        inputs["Roughness"] = factor(0.5, "Blender roughness r")
    return NodeFunction(f"RTL SH-LTC {title}", body, inputs,
                        {"Axis": vector("Cosine lobe axis, unit", "NONE"),
                         "Magnitude": Socket("float", 0.0, description="Scale of the lobe")}, description,
                        tables=REFERENCES)


SH_LTC_COD = _ltc_lobe_function("CoD Diffuse", COD_TABLE, "The CoD WWII diffuse's LTC: lobe axis and magnitude")
SH_LTC_CLOTH = _ltc_lobe_function("Cloth", CLOTH_TABLE, "The Ashikhmin cloth's LTC: lobe axis and magnitude")
SH_LTC_SHEEN = _ltc_lobe_function("Sheen", COD_TABLE, "Disney sheen as the talk: the CoD LTC at r = 0.5, "
                                  "magnitude pi x its Fresnel channel", SHEEN_TABLE_ROUGHNESS, use_fresnel=True)


# Rough diffuse as Cycles (core/rough_diffuse.py): the single scattering as the CoD diffuse, a cosine lobe about
# an axis of its LTC (table ltc_oren_nayar), scaled by its directional albedo E_F(mu_v) in closed form (EON); the
# axis is the image of the cosine's peak (indirect.ltc_lobe_axis "peak"), not the talk's: measured against the
# brute-force integral under an SH environment it has 2-3x less error for this lobe (median 0.4% vs 1.5% at
# sigma = 0.5, 1.1% vs 2.6% at sigma = 1; tests/core/test_rough_diffuse.py, docs/rough_diffuse.md).  The multiple
# scattering (1 - E_F(mu_v)) x ms_kernel is zonal about N, so its SH convolution is exact (Funk-Hecke factors
# rough_diffuse.MS_KERNEL_ZONAL).
def _sh_ltc_oren_nayar(tables, N, V, **kw):
    r = kw["Diffuse Roughness"]
    mu_v = op.saturate(op.dot(N, V))
    c, _, _ = tables.ltc(OREN_NAYAR_TABLE, mu_v, r)
    axis = indirect.ltc_lobe_axis(c, polygon.local_frame(N, V), "peak")
    return {"Axis": op.normalize(axis), "Magnitude": rough_diffuse.fon_albedo(mu_v, r),
            "MS Weight": rough_diffuse.fon_one_minus_albedo(mu_v, r)}


OREN_NAYAR_TABLE = "ltc_oren_nayar"
SH_LTC_OREN_NAYAR = NodeFunction(
    "RTL SH-LTC Oren-Nayar", _sh_ltc_oren_nayar,
    {"N": _DIR, "V": _DIR, "Diffuse Roughness": factor(0.0, "Diffuse roughness sigma")},
    {"Axis": vector("Cosine lobe axis of the single scattering, unit", "NONE"),
     "Magnitude": Socket("float", 1.0, description="E_F(mu_v): the single scattering's directional albedo"),
     "MS Weight": Socket("float", 0.0, description="1 - E_F(mu_v): the multiple-scattering lobe's view factor")},
    "Rough diffuse (Fujii + EON) under the SH: the single scattering's LTC axis and albedo", tables=REFERENCES)


def _rough_diffuse_multiscatter_world(coeffs, n, surface, ms_weight):
    """The rough diffuse's multiple scattering under the SH environment, in colour (exact for the L2 SH)."""
    lobe = sh_lobe(coeffs, n, rough_diffuse.MS_KERNEL_ZONAL)
    color = rough_diffuse.multiscatter_color(surface["Albedo"], surface["Metal F0"], surface["Diffuse Roughness"])
    return op.scale(op.vmul(color, lobe), ms_weight)
# Zeltner 2022 sheen under the world (core/sheen.py): its exact integral against the L2 SH radiance.  L2 radiance
# is a polynomial of degree 2 in the direction, so int L D = sum_i c_i E_D[Y_i] needs only D's first and second
# moments (tables zeltner_sheen_sh1/2, computed per cell from the measured LTC: validation/benchmarks/sheen_table.py), taken
# from the local frame (T1, T2, N) to the world's here.  Against Cycles under two studio HDRIs (docs/sheen.md):
# median 21% (studio, r = 0.5) and 7.9% (sunset, r = 0.2) where the talk's cosine lobe about the LTC's peak gave
# 49% and 28%; what remains is the L2 truncation of the environment.
def _zeltner_world_lobe(tables, **kw):
    n, v = kw["N"], kw["V"]
    mu, r = op.saturate(op.dot(n, v)), sheen.zeltner_roughness(kw["Sheen Roughness"])
    a, _, albedo = tables.zeltner_sheen(mu, r)
    (mx, mz, mxz), (mxx, myy, mzz) = tables.zeltner_sheen_moments(mu, r)
    keep = op.logical_and(sheen.zeltner_active(a, albedo), op.greater(op.dot(n, v), 0.0))
    t1, t2, nn = polygon.local_frame(n, v)

    def second(i, j):
        """E[w_i w_j] in world coordinates: sum over the local axes (only xx, yy, zz and xz are non-zero)."""
        t1i, t1j, t2i, t2j = op.component(t1, i), op.component(t1, j), op.component(t2, i), op.component(t2, j)
        ni, nj = op.component(nn, i), op.component(nn, j)
        return mxx * t1i * t1j + myy * t2i * t2j + mzz * ni * nj + mxz * (t1i * nj + ni * t1j)

    out = {"Mean": op.scale(t1, mx) + op.scale(nn, mz), "Albedo": op.select(keep, albedo, 0.0)}
    out.update({name: second(i, j) for name, (i, j) in SECOND_MOMENTS.items()})
    return out


#: World second moments E[w_i w_j] the SH integral needs, by output name.
SECOND_MOMENTS = {"XX": (0, 0), "YY": (1, 1), "ZZ": (2, 2), "XY": (0, 1), "YZ": (1, 2), "XZ": (0, 2)}

SH_LTC_ZELTNER = NodeFunction(
    "RTL SH-LTC Zeltner Sheen", _zeltner_world_lobe,
    {"N": _DIR, "V": _DIR, "Sheen Roughness": factor(0.5, "Sheen roughness")},
    dict({"Mean": vector("E[w] of the sheen's normalised LTC, world space", "NONE")},
         **{k: Socket("float", 0.0, description=f"E[w_{k[0].lower()} w_{k[1].lower()}], world space")
            for k in SECOND_MOMENTS},
         Albedo=Socket("float", 0.0, description="Directional albedo R(mu_v) (0 where Cycles drops the lobe)")),
    "Zeltner sheen's LTC: its moments in world space and its albedo", tables=REFERENCES)


# Ramamoorthi & Hanrahan 2001, eq. 3: each basis function is a polynomial of degree <= 2, so its expectation
# under a distribution is the same polynomial of the moments.
def _sh_moments(**kw):
    coeffs = [kw[name] for name in SH_NAMES]
    m = kw["Mean"]
    e = {k: kw[k] for k in SECOND_MOMENTS}
    x, y, z = (op.component(m, i) for i in range(3))
    expectations = (indirect.Y00 + 0.0 * x, indirect.Y1 * y, indirect.Y1 * z, indirect.Y1 * x,
                    indirect.Y2_PRODUCT * e["XY"], indirect.Y2_PRODUCT * e["YZ"], indirect.Y20 * (3.0 * e["ZZ"] - 1.0),
                    indirect.Y2_PRODUCT * e["XZ"], indirect.Y22 * (e["XX"] - e["YY"]))
    total = op.scale(coeffs[0], expectations[0])
    for c, ey in zip(coeffs[1:], expectations[1:]):
        total = total + op.scale(c, ey)
    return {"Radiance": total}


SH_MOMENTS = NodeFunction(
    "RTL SH Moments", _sh_moments,
    {**{name: WORLD_PARAMETERS[name] for name in SH_NAMES}, "Mean": vector("E[w]", "NONE", hide_value=True),
     **{k: Socket("float", 0.0, description=f"E[w_{k[0].lower()} w_{k[1].lower()}]") for k in SECOND_MOMENTS}},
    {"Radiance": color((0.0, 0.0, 0.0), "int L(w) D(w) dw for the distribution D with these moments")},
    "L2 SH environment integrated against a distribution given by its first and second moments")


def sh_moments(coeffs, lobe):
    """int L D for the SH ``coeffs`` (9 colours) and the moments of D (``SH_LTC_ZELTNER``'s outputs)."""
    kw = dict(zip(SH_NAMES, coeffs))
    return SH_MOMENTS(**kw, Mean=lobe["Mean"], **{k: lobe[k] for k in SECOND_MOMENTS})["Radiance"]


SH_LTC_DISNEY_FITTED = _ltc_lobe_function("Disney Sheen Fitted", "ltc_disney_sheen",
                                          "Disney sheen's own fitted LTC: lobe axis and magnitude", 0.0)


# --- specular ---------------------------------------------------------------------------------------

def _channel_specular(model, environment_ms):
    """Per colour channel: f0, A, B, P, I (floats) -> outgoing specular radiance (module docstring)."""
    def spec(f0, a, b, p, i, om_avg):
        fss_ess = f0 * a + b
        if model == "single":
            return fss_ess * p
        e = a + b
        if model == "turquin":
            return fss_ess * multiscatter.turquin_compensation(f0, e) * p
        if model == "fdez_aguera":
            fss, fms = multiscatter.fdez_aguera_terms(f0, a, b)
            return fss * p + fms * (p if environment_ms == "radiance" else i)
        if model == "kulla_conty":
            f_ms = multiscatter.kulla_conty_fresnel_factor(fresnel_average(f0), om_avg)
            return fss_ess * p + f_ms * (1.0 - e) * i
        raise ValueError(f"unknown specular model {model!r}")
    return spec


@functools.lru_cache(maxsize=None)
def specular_function(model, environment_ms="irradiance"):
    """``RTL World Specular (<model>)``: one F0's specular under the environment."""
    channel = _channel_specular(model, environment_ms)

    def body(tables, **kw):
        om_avg = tables.one_minus_e_avg(kw["Roughness"]) if model == "kulla_conty" else 0.0
        parts = [channel(op.component(kw["F0"], c), kw["Scale"], kw["Bias"], op.component(kw["Prefiltered"], c),
                         op.component(kw["Irradiance"], c), om_avg) for c in range(3)]
        return {"Specular": op.vec3(*parts)}

    inputs = {"F0": color((0.04, 0.04, 0.04), "Specular reflectance at normal incidence"),
              "Scale": Socket("float", 1.0, description="Split-sum scale A at (N.V, r)"),
              "Bias": Socket("float", 0.0, description="Split-sum bias B at (N.V, r)"),
              "Prefiltered": color((0.0, 0.0, 0.0), "Prefiltered radiance along the dominant direction"),
              "Irradiance": color((0.0, 0.0, 0.0), "Cosine-weighted mean radiance E(N)/pi")}
    if model == "kulla_conty":
        inputs["Roughness"] = factor(0.5, "Blender roughness r")
    label = model.replace("_", "-") + (f", {environment_ms} form" if model == "fdez_aguera" else "")
    return NodeFunction(f"RTL World Specular ({label})", body, inputs,
                        {"Specular": color((0.0, 0.0, 0.0), "Outgoing specular radiance")},
                        f"Split-sum specular under the environment, {label}", tables=REFERENCES)


def dominant_direction(n, v, roughness):
    """Lagarde & de Rousiers 2014, listing 22: lerp(N, R, s (sqrt(s) + alpha)), s = 1 - alpha."""
    alpha = alpha_from_roughness(roughness)
    s = 1.0 - alpha
    f = s * (op.sqrt(s) + alpha)
    r = op.scale(n, 2.0 * op.dot(n, v)) - v
    return op.normalize(n + op.scale(r - n, f))


# --- the whole world term ---------------------------------------------------------------------------

WORLD_SURFACE = ("N", "V", "Roughness", "Dielectric F0", "Metal F0", "Metallic", "Albedo", "Wrap",
                 "Sheen Color", "Cloth Weight", "Cloth Color")


def world_surface(features):
    """The surface terms the world term of ``features`` reads (``WORLD_SURFACE``; the rough diffuse adds its
    roughness, Zeltner's sheen the sheen roughness)."""
    return (WORLD_SURFACE + (("Diffuse Roughness",) if features.diffuse == "oren_nayar" else ())
            + (("Sheen Roughness",) if features.sheen == "zeltner" else ()))


def world_radiance(tables, features, env, surface, params, ambient_occlusion=None):
    """Radiance towards the viewer from the environment (3-vector).

    ``surface``: RTL Surface outputs (at least ``WORLD_SURFACE``); ``params``: ``WORLD_PARAMETERS``
    names -> values; ``env``: the ``WorldEnvironment``; ``tables``: the LUT set (``lookup.LutSet``);
    ``ambient_occlusion``: the renderer's AO at the point (with ``features.occlusion`` on; ``occluded``)."""
    rotated = WORLD_ROTATION(N=surface["N"], V=surface["V"], Rotation=params["Rotation"])
    n, v = rotated["N"], rotated["V"]
    coeffs = [params[name] for name in SH_NAMES]
    r = surface["Roughness"]
    irradiance = sh_lobe(coeffs, n, indirect.COSINE_LOBE_ZONAL)
    broad, glossy = _occlusion_factors(features, surface, r, ambient_occlusion)

    # diffuse
    if features.diffuse == "lambert":
        diffuse = irradiance
    elif features.diffuse == "wrapped":
        diffuse = sh_lobe(coeffs, n, indirect.wrapped_lobe_zonal(surface["Wrap"]))
    elif features.diffuse == "cod_wrapped":
        # multiscattering wrapped diffuse (indirect.sh_cod_wrapped_diffuse): the wrapped lobe about the CoD LTC axis
        lobe = SH_LTC_COD(tables, N=n, V=v, Roughness=r)
        diffuse = op.scale(sh_lobe(coeffs, lobe["Axis"], indirect.wrapped_lobe_zonal(surface["Wrap"])),
                           lobe["Magnitude"])
    elif features.diffuse == "oren_nayar":
        rough = SH_LTC_OREN_NAYAR(tables, N=n, V=v, **{"Diffuse Roughness": surface["Diffuse Roughness"]})
        diffuse = op.scale(sh_lobe(coeffs, rough["Axis"], indirect.COSINE_LOBE_ZONAL), rough["Magnitude"])
    else:
        lobe = SH_LTC_COD(tables, N=n, V=v, Roughness=r)
        diffuse = op.scale(sh_lobe(coeffs, lobe["Axis"], indirect.COSINE_LOBE_ZONAL), lobe["Magnitude"])

    spec = occluded(_world_specular(tables, features, env, surface, n, v, r, irradiance), glossy)
    if features.cloth:
        lobe = SH_LTC_CLOTH(tables, N=n, V=v, Roughness=r)
        cloth = op.scale(sh_lobe(coeffs, lobe["Axis"], indirect.COSINE_LOBE_ZONAL), lobe["Magnitude"])
        w = surface["Cloth Weight"]
        cloth = occluded(op.scale(op.vmul(surface["Cloth Color"], cloth), w), broad)
        spec = cloth if spec is None else op.scale(spec, 1.0 - w) + cloth
    total = op.vmul(surface["Albedo"], diffuse)
    if features.diffuse == "oren_nayar":
        total = total + _rough_diffuse_multiscatter_world(coeffs, n, surface, rough["MS Weight"])
    total = occluded(total, broad)
    if spec is not None:
        total = spec + total
    if features.sheen != "none":
        if features.sheen == "zeltner":
            lobe = SH_LTC_ZELTNER(tables, N=n, V=v, **{"Sheen Roughness": surface["Sheen Roughness"]})
            sheen_lobe = op.scale(sh_moments(coeffs, lobe), lobe["Albedo"])
        else:
            lobe = (SH_LTC_SHEEN if features.sheen == "disney_talk" else SH_LTC_DISNEY_FITTED)(tables, N=n, V=v)
            sheen_lobe = op.scale(sh_lobe(coeffs, lobe["Axis"], indirect.COSINE_LOBE_ZONAL), lobe["Magnitude"])
        total = layer_sheen(features, surface, total, occluded(op.vmul(surface["Sheen Color"], sheen_lobe), broad),
                            lobe["Albedo"] if features.sheen == "zeltner" else None)
    return op.scale(total, params["Strength"])


def world_irradiance(surface, params):
    """The world's white-Lambert radiance E_SH(N) / pi x Strength (3-vector): the analytic, unshadowed denominator
    of the World term's ratio estimator (addon/shadows.py, ``world=True``), for the same shading normal as the
    diffuse; ``surface`` needs "N" (and the world's "Rotation")."""
    rotated = WORLD_ROTATION(N=surface["N"], V=surface["N"], Rotation=params["Rotation"])
    coeffs = [params[name] for name in SH_NAMES]
    return op.scale(sh_lobe(coeffs, rotated["N"], indirect.COSINE_LOBE_ZONAL), params["Strength"])


def _occlusion_factors(features, surface, roughness, ambient_occlusion):
    """(occlusion of the broad lobes, of the GGX specular) for ``features.occlusion``; (None, None) when off.

    The broad lobes (diffuse, rough diffuse, sheen, cloth) take the ambient occlusion itself: AO is the
    cosine-weighted visible share, exact for Lambert under a uniform world and what engines apply to all of
    them.  The GGX specular takes the specular occlusion of the model (core/occlusion.py)."""
    if features.occlusion == "none":
        return None, None
    if ambient_occlusion is None:
        raise ValueError(f"occlusion {features.occlusion!r} needs the ambient occlusion ({OCCLUSION_INPUT!r})")
    ao = op.saturate(ambient_occlusion)
    n_dot_v = op.saturate(op.dot(surface["N"], surface["V"]))
    return ao, occlusion.SPECULAR_OCCLUSION[features.occlusion](n_dot_v, ao, roughness)


def occluded(radiance, factor):
    """``radiance`` times the occlusion ``factor`` (None: unoccluded; None radiance stays None)."""
    if radiance is None or factor is None:
        return radiance
    return op.scale(radiance, factor)


def _world_specular(tables, features, env, surface, n, v, r, irradiance):
    """The world's specular term, per F0 and mixed by Metallic (None with the specular switched off)."""
    if features.specular == "none":
        return None
    scale_a, bias_b = tables.split_sum(op.saturate(op.dot(n, v)), r)
    prefiltered = prefiltered_function(env)(Direction=dominant_direction(n, v, r), Roughness=r)["Radiance"]
    spec_fn = specular_function(features.specular, getattr(features, "environment_ms", "irradiance"))
    extra = {"Roughness": r} if features.specular == "kulla_conty" else {}
    common = dict(Scale=scale_a, Bias=bias_b, Prefiltered=prefiltered, Irradiance=irradiance, **extra)
    m = surface["Metallic"]
    return op.scale(spec_fn(tables, F0=surface["Dielectric F0"], **common)["Specular"], 1.0 - m) \
        + op.scale(spec_fn(tables, F0=surface["Metal F0"], **common)["Specular"], m)


@functools.lru_cache(maxsize=16)
def shade_world_function(features, env):
    """``RTL Shade World (<features>)``: the environment's radiance towards the viewer."""

    def shade(tables, **kw):
        surface = {k: kw[k] for k in world_surface(features)}
        params = {k: kw[world_input(k)] for k in WORLD_PARAMETERS}
        return {"Radiance": world_radiance(tables, features, env, surface, params, kw.get(OCCLUSION_INPUT))}

    inputs = {k: SURFACE_OUTPUTS[k] for k in world_surface(features)}
    inputs.update({world_input(k): s for k, s in WORLD_PARAMETERS.items()})
    if features.occlusion != "none":
        inputs[OCCLUSION_INPUT] = OCCLUSION_SOCKET
    return NodeFunction(f"RTL Shade World ({features.label()}; {env.name})", shade, inputs,
                        {"Radiance": color((0.0, 0.0, 0.0), "Radiance towards the viewer from the world")},
                        f"The world's image-based lighting on the RT Lit material ({features.label()})",
                        tables=REFERENCES)


def shade_world(tables, features, env, surface, params, ambient_occlusion=None):
    """The world term: ``surface`` the "RTL Surface" outputs, ``params`` the ``WORLD_PARAMETERS``,
    ``ambient_occlusion`` the renderer's AO (with ``features.occlusion`` on); arrays (``tables`` with data, the
    environment's table included) or Exprs."""
    args = {k: surface[k] for k in world_surface(features)}
    args.update({world_input(k): params[k] for k in WORLD_PARAMETERS})
    if features.occlusion != "none":
        if ambient_occlusion is None:
            raise ValueError(f"occlusion {features.occlusion!r} needs the ambient occlusion ({OCCLUSION_INPUT!r})")
        args[OCCLUSION_INPUT] = ambient_occlusion
    return shade_world_function(features, env)(tables, **args)["Radiance"]
