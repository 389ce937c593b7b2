"""What tables exist, their layout, and whether the files on disk are usable.

docs/luts.md describes the same layouts for people; tests check the two agree.

Axes.  u is always Blender roughness r, node i at r = i / (W - 1).  v is mu = cos(theta_view)
for the energy tables (E is an even, smooth function of theta, so a mu-linear axis spends
its nodes where E bends: near grazing at low roughness; measured in docs/luts.md), and
sqrt(1 - mu) for the LTC tables (their matrix entries are odd in theta).
Node i sits at the texel centre (i + 0.5) / W; a shader samples at
    (x * (N - 1) + 0.5) / N
with bilinear filtering and EXTEND, which reconstructs the piecewise-linear table exactly.
"""
from __future__ import annotations

import ast
import hashlib
import io
import json
import shutil
import tokenize
from dataclasses import dataclass, field, replace
from pathlib import Path

from . import exr_io

#: Bumped when the meaning or layout of any table changes (2: E_avg table stores 1 - E_avg).
LAYOUT_VERSION = 2

AXIS_U_ROUGHNESS = "u: Blender roughness r (GGX alpha = max(r^2, 1e-4)); node i at r = i/(W-1), texel centre (i+0.5)/W"
AXIS_V_MU = ("v: mu = cos(theta_view); node j at mu = j/(H-1), texel centre (j+0.5)/H "
             "(Blender row j counted from the bottom)")
AXIS_V_SQRT_ONE_MINUS_MU = ("v: sqrt(1 - mu), mu = cos(theta_view); node j at v = j/(H-1), texel centre (j+0.5)/H "
                            "(Blender row j counted from the bottom); the fit clamps mu >= 1e-3")


@dataclass(frozen=True)
class TableSpec:
    name: str
    filename: str
    group: str
    width: int
    height: int
    channels: str
    description: str
    axis_u: str = AXIS_U_ROUGHNESS
    axis_v: str = AXIS_V_MU

    @property
    def shape(self):
        return (self.height, self.width)


@dataclass(frozen=True)
class BakeGroup:
    """Tables computed together from the same samples (so they are mutually consistent)."""
    name: str
    generator_version: int
    params: dict = field(hash=False)
    sources: tuple  # module files (relative to the package root) whose code defines the values
    #: Measured from another renderer (not computed by numpy): kept as shipped, never re-baked; ``command``
    #: (re)measures it.
    measured: bool = False
    command: str = ""


ENERGY_SIZE = 64

#: Hammersley points per table cell for the GGX energy tables.  A measured choice:
#: scripts/benchmark_luts.py (docs/benchmarks/luts.md) gives the error against a 2^20-point
#: reference for 2^10 .. 2^18.
ENERGY_SAMPLES = 1 << 14

GROUPS = {
    "ggx_energy": BakeGroup(
        name="ggx_energy",
        generator_version=1,
        params={"size": ENERGY_SIZE, "samples": ENERGY_SAMPLES, "sampler": "hammersley-2d+ggx-vndf",
                "mu_min": 1e-4},
        sources=("core/energy.py", "core/microfacet.py", "core/sampling.py", "core/conventions.py",
                 "core/shading_ops.py", "core/ir/semantics.py", "core/lut_bake.py"),
    ),
}

LTC_SIZE = 64

#: Settings of the LTC fit (core/ltc/fit.py), measured in docs/benchmarks/ltc.md.
LTC_FIT = {"size": LTC_SIZE, "moment_samples": 1 << 14, "fit_samples": [384, 384, 96], "exponent": 1.0,
           "max_iter": 300, "fit_mu_min": 1e-3}

_LTC_SOURCES = ("core/ltc/fit.py", "core/ltc/fit_lobes.py", "core/ltc/matrix.py", "core/ltc/optimize.py",
                "core/ltc/sphere_table.py", "core/microfacet.py", "core/sampling.py", "core/conventions.py",
                "core/shading_ops.py", "core/ir/semantics.py", "core/lut_bake.py")
#: The module of each LTC lobe's BRDF beyond GGX (only its own group depends on it).
_LTC_BRDF_SOURCES = {"ltc_cod_diffuse": ("core/diffuse.py",), "ltc_cloth": ("core/cloth.py",),
                     "ltc_oren_nayar": ("core/rough_diffuse.py",)}
_LTC_BRDF_SOURCES["ltc_disney_sheen"] = ("core/cloth.py",)

#: LTC lobes: table prefix -> (lobe name in core.ltc.fit_lobes, description)
LTC_LOBES = {
    "ltc_ggx": ("ggx", "single-scattering GGX (F = 1, height-correlated Smith G2)"),
    "ltc_cod_diffuse": ("cod_diffuse", "Call of Duty WWII multiscattering diffuse (albedo 1)"),
    "ltc_cloth": ("cloth", "Ashikhmin velvet + Neubelt-Pettineo visibility (colour 1)"),
    "ltc_oren_nayar": ("oren_nayar", "Fujii's improved Oren-Nayar single scattering (albedo 1)"),
    "ltc_disney_sheen": ("disney_sheen", "Disney sheen (1 - l.h)^5 (colour 1; no roughness: every column alike)"),
}

#: Lobes whose LTC carries a band (docs/area_lights.md, "The band"; issue 15): a second LTC, the fitted Minv with
#: its third column scaled by ``squash`` (``core.ltc.matrix.squash_packed``), mixed in with a weight in [0,
#: ``max_weight``] fitted per cell jointly with Minv and stored in channel B of the ``_mag`` table; columns below
#: ``min_roughness`` keep the fit without a band (w = 0).  Measured: docs/benchmarks/ltc_suite_like.md.
LTC_BANDS = {"ltc_ggx": {"squash": 3.0, "max_weight": 0.9, "min_roughness": 0.65}}

for _prefix, (_lobe, _text) in LTC_LOBES.items():
    _params = dict(LTC_FIT, lobe=_lobe, **({"band": LTC_BANDS[_prefix]} if _prefix in LTC_BANDS else {}))
    GROUPS[_prefix] = BakeGroup(name=_prefix, generator_version=1, params=_params,
                                sources=_LTC_SOURCES + _LTC_BRDF_SOURCES.get(_prefix, ()))

#: The drop-in GGX pair (issue 32): ``ltc_ggx``'s lobe fitted as one standalone LTC in every column, for engines that
#: read only ltc_code's ``ltc_1`` / ``ltc_2`` and so ignore the band (core/export/luts.py, the ``ltc_code`` layout).
#: Refitted, not copied: the same fit and settings as ``ltc_ggx`` without its band (``LTC_FIT``; core/ltc/fit.py,
#: ``fit_table`` with ``band=None``).  Every column's fit is independent of the others', so below the band
#: (r < 0.65, columns 0-40) the values equal ``ltc_ggx``'s to the bit (tests/core/test_ltc_single.py); from r = 0.65 on
#: they are the best single LTC under the fit's objective (L1 of the density difference, the TV distance), where
#: ``ltc_ggx`` holds the base fit of its band.  Not read by shading (which uses the band): only exported.
SINGLE_LTC = {"ltc_ggx_single": ("ltc_ggx", "ggx", "single-scattering GGX (F = 1, height-correlated Smith G2), one "
                                                   "standalone LTC per cell (no band): ltc_code's drop-in")}
for _prefix, (_of, _lobe, _text) in SINGLE_LTC.items():
    GROUPS[_prefix] = BakeGroup(name=_prefix, generator_version=1, params=dict(LTC_FIT, lobe=_lobe),
                                sources=_LTC_SOURCES + _LTC_BRDF_SOURCES.get(_of, ()))

#: Cycles' sheen (Zeltner, Burley & Chiang 2022): the LTC (a, b) and albedo of each (mu, r), measured from
#: Cycles renders (validation/benchmarks/sheen_table.py); 32 x 32 nodes at i/31 as Cycles' own table, so a bilinear
#: lookup reproduces Cycles' exactly.  ``params`` say what was measured, with which Blender.
ZELTNER_SHEEN_SIZE = 32
#: Measured groups, apart from ``GROUPS`` (what ``core.lut_bake`` computes): ``keep_measured`` keeps them.
MEASURED_GROUPS = {}
MEASURED_GROUPS["zeltner_sheen"] = BakeGroup(
    name="zeltner_sheen", generator_version=1,
    params={"size": ZELTNER_SHEEN_SIZE, "source": "Cycles Sheen BSDF (Microfiber), Blender 5.2.3",
            "method": "sun (angle 0) renders, 1 sample, direct light; linear least squares per cell",
            "paper": "Zeltner, Burley, Chiang 2022, Practical Multiple-Scattering Sheen Using LTCs",
            "derived": "zeltner_sheen_sh1/sh2: moments of each cell's LTC, 128 x 256 product rule (sh_moments)"},
    sources=(), measured=True, command="python scripts/measure_sheen_table.py")

LTC_INV_CHANNELS = ("R = c0 = Minv_xx, G = c1 = Minv_zx, B = c2 = Minv_xz, A = c3 = Minv_zz "
                    "(Minv normalised so that Minv_yy = 1)")
LTC_MAG_CHANNELS = ("R = magnitude = int f cos, G = fresnel = int f cos (1 - v.h)^5, B = 0, "
                    "A = horizon-clipped sphere ratio on its own axes (u = z/2 + 1/2, v = |F|)")


def ltc_mag_channels(prefix):
    """The channels of ``prefix``'s ``_mag`` table: ``LTC_MAG_CHANNELS``, with B the band's weight for a lobe that
    has one (``LTC_BANDS``)."""
    band = LTC_BANDS.get(prefix)
    if band is None:
        return LTC_MAG_CHANNELS
    return LTC_MAG_CHANNELS.replace("B = 0", "B = band weight w (integral = (1 - w) I(Minv) + w I(Minv diag(1, 1, "
                                              f"{band['squash']:g})))")

TABLES = {
    spec.name: spec
    for spec in (
        TableSpec(
            name="ggx_one_minus_E", filename="ggx_one_minus_E.exr", group="ggx_energy",
            width=ENERGY_SIZE, height=ENERGY_SIZE,
            channels="R = G = B = 1 - E(mu, r); A = 1",
            description="1 - directional albedo of single-scattering GGX with F = 1 "
                        "(height-correlated Smith G2); Kulla-Conty and Turquin input"),
        TableSpec(
            name="ggx_one_minus_E_avg", filename="ggx_one_minus_E_avg.exr", group="ggx_energy",
            width=ENERGY_SIZE, height=1,
            channels="R = G = B = 1 - E_avg(r); A = 1",
            description="1 - E_avg(r), E_avg = 2 int E(mu) mu dmu of the piecewise-linear E that "
                        "ggx_one_minus_E reconstructs (exact furnace for the Kulla-Conty lobe)",
            axis_v="v: none (one row; sample at v = 0.5)"),
        TableSpec(
            name="ggx_split_sum", filename="ggx_split_sum.exr", group="ggx_energy",
            width=ENERGY_SIZE, height=ENERGY_SIZE,
            channels="R = scale, G = bias (int f mu_l dl = F0 * scale + F90 * bias); B = 0; A = 1",
            description="split-sum environment BRDF of single-scattering GGX (Karis 2013); "
                        "scale + bias = E from the same samples"),
    )
}
TABLES["zeltner_sheen"] = TableSpec(
    name="zeltner_sheen", filename="zeltner_sheen.exr", group="zeltner_sheen",
    width=ZELTNER_SHEEN_SIZE, height=ZELTNER_SHEEN_SIZE,
    channels="R = a, G = b (LTC inverse matrix [[a, 0, b], [0, a, 0], [0, 0, 1]]), B = albedo; A = 1",
    description="Zeltner 2022 sheen as Cycles shades it (measured from Cycles): f cos = albedo x the LTC's "
                "density; sheen roughness clamped to [1e-3, 1]",
    axis_u="u: sheen roughness r (Cycles clamps it to >= 1e-3); node i at r = i/(W-1), texel centre (i+0.5)/W",
    axis_v=AXIS_V_MU)
for _name, _channels in (("zeltner_sheen_sh1", "R = E[x], G = E[z], B = E[x z]; A = 1"),
                          ("zeltner_sheen_sh2", "R = E[x^2], G = E[y^2], B = E[z^2]; A = 1")):
    TABLES[_name] = TableSpec(
        name=_name, filename=_name + ".exr", group="zeltner_sheen", width=ZELTNER_SHEEN_SIZE,
        height=ZELTNER_SHEEN_SIZE, channels=_channels,
        description="moments of the Zeltner sheen's normalised LTC per (mu, r) in the local frame (N = +Z, V towards "
                    "+X), derived from zeltner_sheen: the world term's exact L2 SH integral",
        axis_u=TABLES["zeltner_sheen"].axis_u, axis_v=AXIS_V_MU)
_LTC_TEXTS = {**{p: text for p, (_, text) in LTC_LOBES.items()}, **{p: text for p, (_, _, text) in SINGLE_LTC.items()}}
for _prefix, _text in _LTC_TEXTS.items():
    TABLES[_prefix + "_inv"] = TableSpec(
        name=_prefix + "_inv", filename=_prefix + "_inv.exr", group=_prefix, width=LTC_SIZE, height=LTC_SIZE,
        channels=LTC_INV_CHANNELS, description=f"LTC inverse matrix fitted to {_text}",
        axis_v=AXIS_V_SQRT_ONE_MINUS_MU)
    TABLES[_prefix + "_mag"] = TableSpec(
        name=_prefix + "_mag", filename=_prefix + "_mag.exr", group=_prefix, width=LTC_SIZE, height=LTC_SIZE,
        channels=ltc_mag_channels(_prefix),
        description=f"LTC magnitude and Fresnel of {_text}; sphere table in A",
        axis_v=AXIS_V_SQRT_ONE_MINUS_MU)

#: The rough-diffuse table's u axis is the diffuse roughness (Principled "Diffuse Roughness"), not the GGX one.
AXIS_U_DIFFUSE_ROUGHNESS = ("u: diffuse roughness sigma (Principled \"Diffuse Roughness\", Fujii's sigma); node i at "
                            "sigma = i/(W-1), texel centre (i+0.5)/W")
for _name in ("ltc_oren_nayar_inv", "ltc_oren_nayar_mag"):
    TABLES[_name] = replace(TABLES[_name], axis_u=AXIS_U_DIFFUSE_ROUGHNESS)

_PACKAGE_ROOT = Path(__file__).resolve().parents[2]


def default_lut_dir():
    """The ``luts/`` folder shipped with the extension."""
    return _PACKAGE_ROOT / "luts"


def code_text(path):
    """The code of a Python file without its comments, docstrings and blank lines: what a hash of
    "the code that computes a table" should see (editing a comment does not make a table stale).
    Comments are found with ``tokenize`` and docstrings with ``ast``, whose positions are the same in
    every supported Python version (token strings are not: f-strings tokenise differently in 3.12+)."""
    source = Path(path).read_text(encoding="utf-8")
    lines = source.splitlines()
    drop = set()
    for node in ast.walk(ast.parse(source)):
        body = getattr(node, "body", None)
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and body:
            first = body[0]
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant) \
                    and isinstance(first.value.value, str):
                drop.update(range(first.lineno - 1, first.end_lineno))
    cut = {}
    for tok in tokenize.generate_tokens(io.StringIO(source).readline):
        if tok.type == tokenize.COMMENT:
            cut[tok.start[0] - 1] = tok.start[1]
    kept = []
    for i, line in enumerate(lines):
        if i in drop:
            continue
        line = line[:cut[i]] if i in cut else line
        if line.strip():
            kept.append(line.rstrip())
    return "\n".join(kept)


def bake_group(name):
    """The ``BakeGroup`` called ``name``, computed (``GROUPS``) or measured (``MEASURED_GROUPS``)."""
    return GROUPS[name] if name in GROUPS else MEASURED_GROUPS[name]


def inputs_hash(group_name):
    """Hash of everything that determines a bake group's values: parameters and the code (without
    comments and docstrings: ``code_text``) of the modules that compute it."""
    group = bake_group(group_name)
    h = hashlib.sha256()
    h.update(json.dumps({"layout": LAYOUT_VERSION, "group": group.name,
                         "generator": group.generator_version, "params": group.params},
                        sort_keys=True).encode())
    for rel in group.sources:
        h.update(rel.encode())
        h.update(code_text(_PACKAGE_ROOT / rel).encode())
    return h.hexdigest()


@dataclass(frozen=True)
class LutStatus:
    name: str
    path: Path
    state: str  # "ok", "missing", "stale", "corrupt" or "mismatch"
    message: str


def table_status(spec, lut_dir, expected_hash=None):
    path = Path(lut_dir) / spec.filename
    try:
        _, meta = exr_io.read_table(path, expected_table=spec.name, expected_shape=spec.shape)
    except exr_io.LutMissingError as exc:
        return LutStatus(spec.name, path, "missing", _measured_hint(spec, str(exc)))
    except exr_io.LutCorruptError as exc:
        return LutStatus(spec.name, path, "corrupt", _measured_hint(spec, str(exc)))
    except exr_io.LutMismatchError as exc:
        return LutStatus(spec.name, path, "mismatch", str(exc))
    if meta.get("layout_version") != LAYOUT_VERSION:
        return LutStatus(spec.name, path, "mismatch",
                         f"{path}: layout version {meta.get('layout_version')}, this code reads "
                         f"{LAYOUT_VERSION}. Re-bake with `{exr_io.BAKE_COMMAND} --force`.")
    expected_hash = expected_hash or inputs_hash(spec.group)
    group = bake_group(spec.group)
    if group.measured and meta.get("inputs_hash") != expected_hash:
        return LutStatus(spec.name, path, "stale",
                         f"{path}: a measured table from other inputs than the catalog's ({group.params}). "
                         f"It is not baked: re-measure with `{group.command}` or restore the shipped file.")
    if meta.get("inputs_hash") != expected_hash:
        return LutStatus(spec.name, path, "stale",
                         f"{path}: baked from other inputs than the current code and settings. "
                         f"Re-bake with `{exr_io.BAKE_COMMAND}`.")
    return LutStatus(spec.name, path, "ok", f"{path.name}: ok")


def _measured_hint(spec, message):
    """A measured table's missing / corrupt message: it cannot be baked, say how to get it back."""
    group = bake_group(spec.group)
    if not group.measured:
        return message
    return (f"{message.split(' Re-bake')[0]} This table is measured, not baked (scripts/bake_luts.py copies "
            f"the shipped one, {default_lut_dir() / spec.filename}): restore that file or re-measure it with "
            f"`{group.command}` (needs Blender's Cycles).")


def lut_status(lut_dir=None):
    """Status of every table in ``lut_dir`` (default: the shipped folder)."""
    lut_dir = Path(lut_dir) if lut_dir is not None else default_lut_dir()
    hashes = {g: inputs_hash(g) for g in list(GROUPS) + list(MEASURED_GROUPS)}
    return [table_status(spec, lut_dir, hashes[spec.group]) for spec in TABLES.values()]


def keep_measured(lut_dir, log=print):
    """Measured tables are never computed by the bake (``core.lut_bake`` knows only ``GROUPS``): in
    ``lut_dir`` each is kept when current, else copied from the shipped folder when that one is intact;
    otherwise ``log`` says how to get it back.  Returns {group: "kept" | "copied" | "missing"}."""
    out = {}
    shipped = default_lut_dir()
    for name, group in MEASURED_GROUPS.items():
        specs = [s for s in TABLES.values() if s.group == name]
        ok = lambda folder: all(table_status(s, folder).state == "ok" for s in specs)   # noqa: E731
        if ok(lut_dir):
            out[name] = "kept"
        elif Path(lut_dir).resolve() != shipped.resolve() and ok(shipped):
            Path(lut_dir).mkdir(parents=True, exist_ok=True)
            for spec in specs:
                shutil.copyfile(shipped / spec.filename, Path(lut_dir) / spec.filename)
            out[name] = "copied"
        else:
            out[name] = "missing"
        if out[name] != "missing":
            log(f"[bake] {name}: measured table, {out[name]} ({', '.join(s.filename for s in specs)})")
        for spec in specs if out[name] == "missing" else ():
            log(f"[bake] {name}: {table_status(spec, lut_dir).message}")
    return out
