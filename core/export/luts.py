"""Export the LUTs for game engines: every table in every format and precision, with an exact manifest.

    export(out, lut_dir=None, formats=FORMATS, precisions=PRECISIONS, layout="rtl", progress=None)

Tables (``layout_tables``): the three GGX energy tables, the LTC pairs and the horizon-clipped sphere table on its
own; in the ``rtl`` layout under the catalog's names (core/lut/catalog.py; ``ltc_ggx`` with its band, and
``ltc_ggx_single``), in the ``ltc_code`` layout the LTC pairs packed as selfshadow/ltc_code's published ``ltc_1`` /
``ltc_2`` (Heitz et al. 2016): the same channel order (``ltc_1`` = Minv_xx, Minv_zx, Minv_xz, Minv_zz of the
inverse matrix normalised by its middle element; ``ltc_2`` = magnitude, Fresnel, 0, sphere table), the same axes
(x = roughness r, y = sqrt(1 - cos theta_v), texel centres) and the same memory order (flat index a + 64 t, row t = 0
first), so an engine that reads the published tables swaps ours in unchanged.  The ``ltc_code`` GGX pair is a
**standalone fit in every column** (``ltc_ggx_single``, issue 32): RT Lit's ``ltc_ggx`` holds, for r >= 0.65, the
base LTC of its band, which an engine reading only ``ltc_1`` / ``ltc_2`` would use without the band's second LTC and
so be worse than a table fitted without one (docs/area_lights.md, "Engines that ignore B").  Below r = 0.65 the two
are the same fit, to the bit.

Formats (one file per table and precision, unless noted): ``exr`` (OpenEXR scanline, ZIP, FLOAT or HALF
channels), ``ktx2`` (KTX 2.0, RGBA16F / RGBA32F; core/export/containers.py), ``dds`` (DDS with the DX10
header), ``npz`` (one file per precision: an array per table and the manifest), ``c`` (one C header per
precision: float arrays, IEEE half as uint16, sizes and layout as constants), ``glsl`` / ``hlsl`` (one
include per precision: each table's lookup function written by the shader-text backend).

Row order (``ROW_ORDER``, per format, the same in both layouts; recorded per file in the manifest as ``row_order``):
EXR files store the last table row (v = 1) first, the order in which OpenEXR displays an increasing-y file and in
which three.js' ``EXRLoader`` (it writes scanline y to row H - 1 - y of its data texture, which is not flipped on
upload) and Blender place it at v = 1; KTX 2.0 and DDS store table row 0 (v = 0) first, as a texImage2D upload of
their level places it.  docs/luts.md, "Which engine reads which file", says which engines read which file, from
their loaders' sources (what is verified there and what is inferred).

Half precision (``HALF_ENCODING``, per layout; ``half_encoding`` in the manifest): in the ``rtl`` layout a channel
whose values would fall below the smallest normal half (6.1e-5) is stored multiplied by a power of two
(``decode_scale`` in the manifest: value = stored x decode_scale; exact in float32), chosen so the channel's
largest value stays below 2^15; the lookup functions of the includes multiply it back.  In the ``ltc_code``
layout half values are stored **plain** (decode_scale 1), as an engine that reads the published tables expects
(three.js converts them with ``DataUtils.toHalfFloat`` and reads them as values): round to nearest, relative error
<= 2^-11 for normal values, absolute <= 2^-25 below 6.1e-5 (IEEE 754 binary16).  The errors against float32 are
measured per table and written in the manifest (``precision_vs_f32``: ``as_exported``, ``f16_plain``,
``f16_scaled``).

Output goes to a temporary folder beside ``out`` and replaces ``out`` only when complete, so an
interrupted export leaves the previous export (or nothing).  ``out`` must be empty, absent, or an
earlier export (a folder with this exporter's manifest and nothing else).
"""
from __future__ import annotations

import argparse
import io
import json
import re
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import lut_bake
from ..lut import catalog, exr_io, exr_reader, exr_writer
from ..lut.lookup import LutSet
from . import containers, lut_code
from .folders import replacing_folder

FORMATS = ("exr", "ktx2", "dds", "npz", "c", "glsl", "hlsl")
PRECISIONS = ("f32", "f16")
LAYOUTS = ("rtl", "ltc_code")
MANIFEST = "manifest.json"
MANIFEST_FORMAT = "rt-lookdev-luts"
MANIFEST_VERSION = 1
DTYPES = {"f32": np.dtype("<f4"), "f16": np.dtype("<f2")}
HALF_MIN_NORMAL = 2.0 ** -14
HALF_EPSILON = 2.0 ** -11            # half's relative rounding bound (round to nearest): 2^-11
HALF_SUBNORMAL_STEP = 2.0 ** -24
SCALE_CEILING = 2.0 ** 15            # scaled channels stay below this
SPHERE_TABLE = "ltc_sphere"
#: The ltc_code layout's GGX pair (``ltc_1`` / ``ltc_2``): the standalone fit in every column (catalog.SINGLE_LTC).
LTC_CODE_GGX_SOURCE = "ltc_ggx_single"
#: Half tables per layout: rtl scales small channels (``decode_scale``), ltc_code stores plain values (a drop-in).
HALF_ENCODING = {"rtl": "scaled", "ltc_code": "plain"}
#: Row order of the files, per format (the same in both layouts): ``v_descending``, the first stored row is the last
#: table row (v = 1), as OpenEXR's loaders in three.js and Babylon.js and Blender's image orientation place it (they put
#: the first scanline of an increasing-y file at the top, v = 1); ``v_ascending``, the first stored row is table row 0
#: (v = 0), as texImage2D uploads a KTX 2.0 or DDS level (docs/luts.md, "Which engine reads which file").
ROW_ORDER = {"exr": "v_descending", "ktx2": "v_ascending", "dds": "v_ascending"}
ENCODING = {"exr": {"f32": "OpenEXR FLOAT (32-bit) channels R, G, B, A", "f16": "OpenEXR HALF (16-bit) channels R, G, B, A"},
            "ktx2": {"f32": "VK_FORMAT_R32G32B32A32_SFLOAT (109)", "f16": "VK_FORMAT_R16G16B16A16_SFLOAT (97)"},
            "dds": {"f32": "DXGI_FORMAT_R32G32B32A32_FLOAT (2), DX10 header",
                    "f16": "DXGI_FORMAT_R16G16B16A16_FLOAT (10), DX10 header"}}

CITATIONS = {
    "energy": ["Kulla & Conty 2017, Revisiting Physically Based Shading at Imageworks",
               "Karis 2013, Real Shading in Unreal Engine 4 (split sum)",
               "Heitz 2014, Understanding the Masking-Shadowing Function (height-correlated Smith G2)"],
    "ltc": ["Heitz, Dupuy, Hill & Neubelt 2016, Real-Time Polygonal-Light Shading with Linearly Transformed Cosines",
            "Hill & Heitz 2016, Real-Time Area Lighting: a Journey from Research to Production"],
    "sphere": ["Snyder 1996, Area Light Sources for Real-Time Graphics (MSR-TR-96-11)",
               "Hill & Heitz 2017, LTC: clipless horizon handling with the sphere table"],
}
#: The rough-diffuse LTC pair's lobe (core/rough_diffuse.py).
CITATIONS["oren_nayar"] = ["Fujii, A tiny improvement of Oren-Nayar reflectance model (improved Oren-Nayar)",
                           "Portsmouth, Kutz & Hill 2025, EON: A Practical Energy-Preserving Rough Diffuse BRDF (JCGT 14(1))"]
CITATIONS["sheen"] = ["Zeltner, Burley & Chiang 2022, Practical Multiple-Scattering Sheen Using Linearly Transformed "
                      "Cosines (the fit, measured from Blender's Cycles)"] + CITATIONS["ltc"]


class LutExportError(RuntimeError):
    """The export cannot be done as asked; the message says why and what to do."""


@dataclass
class ExportTable:
    """One exported table: (H, W, 4) float32 ``data`` with row 0 = table row 0, its meaning and origin."""
    name: str
    source: str
    data: np.ndarray = field(repr=False)
    channels: str
    description: str
    axes: dict
    citations: list
    origin: dict
    #: How the half export stores it: "scaled" (small channels multiplied by a power of two, ``decode_scale``) or
    #: "plain" (the values themselves, as engines reading a published table expect; the ltc_code layout)
    half_encoding: str = "scaled"

    @property
    def shape(self):
        return self.data.shape[:2]

    def encode(self, precision):
        """(stored array, decode scales) of this table in ``precision``, with its half encoding."""
        return encode(self.data, precision, scaled=self.half_encoding == "scaled")


# --- the tables --------------------------------------------------------------------------------------

def _axes(spec):
    w, h = spec.width, spec.height
    u = {"parameter": "r (Blender roughness; GGX alpha = max(r^2, 1e-4))", "nodes": w, "node": "r = i / (W - 1)"}
    if spec.axis_u == catalog.AXIS_U_DIFFUSE_ROUGHNESS:
        u = {"parameter": "sigma (diffuse roughness: Principled's Diffuse Roughness)", "nodes": w,
             "node": "sigma = i / (W - 1)"}
    if spec.name.startswith("zeltner_sheen"):
        u["parameter"] = "r (sheen roughness, clamped to [1e-3, 1] before the lookup)"
    if spec.height == 1:
        v = {"parameter": "none (one row)", "nodes": 1, "node": "sample at v = 0.5"}
    elif spec.axis_v == catalog.AXIS_V_SQRT_ONE_MINUS_MU:
        v = {"parameter": "sqrt(1 - mu), mu = cos(theta_view)", "nodes": h, "node": "sqrt(1 - mu) = j / (H - 1)"}
    else:
        v = {"parameter": "mu = cos(theta_view)", "nodes": h, "node": "mu = j / (H - 1)"}
    return {"u": u, "v": v, "texel_centre": "node k of an axis of N nodes sits at (k + 0.5) / N; sample a parameter "
                                            "x at (x (N - 1) + 0.5) / N, bilinear, clamp to edge"}


def _origin(path):
    meta = exr_io.read_header(path)
    return {k: meta.get(k) for k in ("inputs_hash", "content_hash", "generator", "generator_version",
                                     "layout_version", "samples", "sampler")}


def _catalog_table(luts, name, export_name=None):
    spec = catalog.TABLES[name]
    kind = "ltc" if name.startswith("ltc_") else "sheen" if name.startswith("zeltner_sheen") else "energy"
    return ExportTable(export_name or name, name, luts.array(name).astype(np.float32), spec.channels,
                       spec.description, _axes(spec), CITATIONS[kind] + (CITATIONS["sphere"] if name.endswith("_mag") else [])
                       + (CITATIONS["oren_nayar"] if name.startswith("ltc_oren_nayar") else []),
                       _origin(luts[name].source))


def _sphere_table(luts):
    mag = luts["ltc_ggx_mag"]
    data = np.zeros(mag.require_data().shape, np.float32)
    data[..., 0] = mag.require_data()[..., 3]
    data[..., 3] = 1.0
    n = mag.width
    axes = {"u": {"parameter": "z = cos(elevation of the vector form factor F)", "nodes": n, "node": "z = 2 i / (W - 1) - 1"},
            "v": {"parameter": "length of the vector form factor F = sin^2(cap half-angle)", "nodes": mag.height,
                  "node": "length = j / (H - 1)"},
            "texel_centre": "as the other tables: sample (z/2 + 1/2, length) at (x (N - 1) + 0.5) / N"}
    return ExportTable(SPHERE_TABLE, "ltc_ggx_mag", data, "R = clipped form factor of the cap / length "
                       "(max(z, 0) at length 0); G = B = 0; A = 1 (the A channel of every *_mag table)",
                       "horizon-clipped sphere table: the clipped form factor of a spherical cap = length x R",
                       axes, CITATIONS["sphere"], _origin(mag.source))


def layout_tables(luts, layout="rtl"):
    """The tables of ``layout`` from ``luts`` (a LutSet with data), in export order."""
    if layout not in LAYOUTS:
        raise LutExportError(f"unknown layout {layout!r}; choose one of {', '.join(LAYOUTS)}")
    out = [_catalog_table(luts, n) for n in ("ggx_one_minus_E", "ggx_one_minus_E_avg", "ggx_split_sum")]
    for prefix in catalog.LTC_LOBES:
        if layout == "rtl":
            out += [_catalog_table(luts, prefix + "_inv"), _catalog_table(luts, prefix + "_mag")]
        else:
            # the GGX pair is the standalone fit (ltc_ggx_single): an engine reading ltc_1 / ltc_2 has no band
            source = LTC_CODE_GGX_SOURCE if prefix == "ltc_ggx" else prefix
            name = "ltc" if prefix == "ltc_ggx" else prefix
            out += [_catalog_table(luts, source + "_inv", f"{name}_1"), _catalog_table(luts, source + "_mag", f"{name}_2")]
    if layout == "rtl":
        out += [_catalog_table(luts, LTC_CODE_GGX_SOURCE + "_inv"), _catalog_table(luts, LTC_CODE_GGX_SOURCE + "_mag")]
    out += [_catalog_table(luts, n) for n in ("zeltner_sheen", "zeltner_sheen_sh1", "zeltner_sheen_sh2")]
    out.append(_sphere_table(luts))
    for table in out:
        table.half_encoding = HALF_ENCODING[layout]
    return out


# --- half precision ----------------------------------------------------------------------------------

def decode_scales(data, precision, scaled=True):
    """Per channel, the power of two the stored values are multiplied by when read (1 for f32, and for f16 stored
    plain: ``scaled`` False)."""
    if precision == "f32" or not scaled:
        return [1.0] * data.shape[2]
    scales = []
    for c in range(data.shape[2]):
        a = np.abs(data[..., c].astype(np.float64))
        small = a[(a > 0) & (a < HALF_MIN_NORMAL)]
        top = a.max()
        k = 0
        if small.size and top > 0:
            k = int(np.floor(np.log2(SCALE_CEILING / top)))
            k = max(0, min(k, int(np.ceil(np.log2(HALF_MIN_NORMAL / small.min())))))
        scales.append(2.0 ** -k)
    return scales


def encode(data, precision, scaled=True):
    """(stored array in the precision's dtype, decode scales); ``scaled`` False stores half values plain."""
    scales = decode_scales(data, precision, scaled)
    stored = (data.astype(np.float64) / np.asarray(scales)).astype(DTYPES[precision])
    if not np.isfinite(stored).all():
        raise LutExportError(f"a table does not fit {precision} (values beyond its range)")
    return stored, scales


def decode(stored, scales):
    return stored.astype(np.float32) * np.asarray(scales, np.float32)


def rounding_bound(data, scales, precision):
    """The largest |decoded - data| the precision allows per value (0 for f32)."""
    if precision == "f32":
        return np.zeros(data.shape, np.float64)
    a = np.abs(data.astype(np.float64)) / np.asarray(scales)
    return np.maximum(a * HALF_EPSILON, HALF_SUBNORMAL_STEP / 2) * np.asarray(scales)


def precision_errors(table):
    """Half against float32 for one table, stored as is and with the decode scales: max abs error, max
    relative error over the non-zero values, and how many lose more than half's 2^-11 (subnormals)."""
    def errors(decoded):
        err = np.abs(decoded.astype(np.float64) - table.data)
        nonzero = table.data != 0
        rel = err[nonzero] / np.abs(table.data[nonzero]) if nonzero.any() else np.zeros(1)
        return {"max_abs": float(err.max()), "max_rel": float(rel.max()),
                "values_beyond_half_epsilon": int((rel > HALF_EPSILON * (1 + 1e-6)).sum())}

    stored, scales = encode(table.data, "f16")
    out = {"f16_plain": errors(table.data.astype(np.float16)), "f16_scaled": errors(decode(stored, scales)),
           "decode_scale": scales, "values_below_half_normal": int(((np.abs(table.data) > 0)
                                                                   & (np.abs(table.data) < HALF_MIN_NORMAL)).sum())}
    out["half_encoding"] = table.half_encoding
    out["as_exported"] = out["f16_" + table.half_encoding]
    out["decode_scale"] = table.encode("f16")[1]
    return out


# --- files -------------------------------------------------------------------------------------------

def _orientation(fmt, layout):
    """The row order of ``fmt``'s files as words (the same in both layouts: ``ROW_ORDER``)."""
    if ROW_ORDER[fmt] == "v_descending":
        return ("scanline 0 is table row H - 1 (v = 1): EXR stores the top row first, and Blender and three.js' "
                "EXRLoader put it at v = 1")
    return "row 0 first: the first row of the data is table row 0 (v = 0)"


def _file_info(table, fmt, precision, layout):
    return {"file": _file_name(table, fmt, precision), "orientation": _orientation(fmt, layout),
            "row_order": ROW_ORDER[fmt], "encoding": ENCODING[fmt][precision],
            "half_encoding": table.half_encoding if precision == "f16" else "none (float32)"}


def _file_name(table, fmt, precision):
    return f"{table.name}_{precision}.{fmt}"


def _table_file(table, fmt, precision, layout, manifest_entry):
    stored, _ = table.encode(precision)
    if fmt == "exr":
        rows = np.flipud(stored) if ROW_ORDER["exr"] == "v_descending" else stored
        planes = {c: np.ascontiguousarray(rows[..., i]) for i, c in enumerate("RGBA")}
        attrs = {"rtl.table": table.name, "rtl.layout": layout, "rtl.precision": precision,
                 "rtl.row_order": ROW_ORDER["exr"], "rtl.manifest": containers.json_value(manifest_entry)}
        return exr_writer.encode(planes, attrs, "zip", "half" if precision == "f16" else "float")
    if fmt == "ktx2":
        return containers.ktx2_bytes(stored, stored.dtype, {"rtl.table": table.name, "rtl.layout": layout,
                                                             "rtl.manifest": containers.json_value(manifest_entry)})
    if fmt == "dds":
        return containers.dds_bytes(stored, stored.dtype)
    raise LutExportError(f"{fmt} is not a per-table format")


def _npz_bytes(tables, precision, manifest):
    arrays = {t.name: t.encode(precision)[0] for t in tables}
    arrays["manifest_json"] = np.frombuffer(json.dumps(manifest).encode(), np.uint8)
    buf = io.BytesIO()
    np.savez(buf, **arrays)
    return buf.getvalue()


def _entry(table, layout, precision, formats, errors):
    stored, scales = table.encode(precision)
    return {"name": table.name, "source_table": table.source, "width": table.shape[1], "height": table.shape[0],
            "channels": table.channels, "description": table.description, "axes": table.axes,
            "units": "dimensionless (albedos, matrix entries, form factors)", "precision": precision,
            "decode_scale": scales, "decode": "value = stored * decode_scale (per channel R, G, B, A)",
            "half_encoding": table.half_encoding if precision == "f16" else "none (float32)",
            "files": {fmt: _file_info(table, fmt, precision, layout) for fmt in formats if fmt in ("exr", "ktx2", "dds")},
            "layout": layout, "layout_version": catalog.LAYOUT_VERSION, "origin": table.origin,
            "content_hash_exported": exr_io.content_hash(decode(stored, scales)), "citations": table.citations,
            "precision_vs_f32": errors}


def manifest(tables, layout, precisions, formats, generator_version):
    entries = {}
    for table in tables:
        errors = precision_errors(table)
        for precision in precisions:
            entries[f"{table.name}_{precision}"] = _entry(table, layout, precision, formats,
                                                          errors if precision == "f16" else {"max_abs": 0.0, "max_rel": 0.0})
    return {"format": MANIFEST_FORMAT, "version": MANIFEST_VERSION, "generator": f"RT Lookdev {generator_version}",
            "date": time.strftime("%Y-%m-%d"), "layout": layout, "precisions": list(precisions),
            "formats": list(formats), "tables": entries,
            "conventions": {"texel_centres": "node k of N at (k + 0.5) / N", "filtering": "bilinear, clamp to edge, no "
                            "mipmaps (the lookup functions fetch four texels and weight them)",
                            "rows": "row j of a table covers v in [j / H, (j + 1) / H)",
                            "row_order": {"v_descending": "the first stored row is table row H - 1 (v = 1)",
                                          "v_ascending": "the first stored row is table row 0 (v = 0)"},
                            "half_encoding": {"scaled": "value = stored * decode_scale",
                                              "plain": "value = stored (decode_scale 1)"}}}


def _generator_version():
    text = (Path(__file__).resolve().parents[2] / "blender_manifest.toml").read_text()
    m = re.search(r'^version\s*=\s*"([^"]+)"', text, re.M)
    return m.group(1) if m else "unknown"


def _check_sources(lut_dir, rebake, log):
    bad = [s for s in catalog.lut_status(lut_dir) if s.state != "ok"]
    if not bad:
        return
    if not rebake:
        raise LutExportError("the source tables are not usable: " + "; ".join(s.message for s in bad)
                             + " (re-bake them, or export with --rebake)")
    (log or print)(f"export: re-baking {', '.join(s.name for s in bad)} in {lut_dir}")
    lut_bake.bake(lut_dir, log=log or print)


def _check_target(out):
    """``out`` as a Path, if it may be (re)written: absent, empty, or an earlier export and nothing else."""
    out = Path(out)
    if out.exists():
        if not out.is_dir():
            raise LutExportError(f"{out} exists and is not a folder")
        names = {p.name for p in out.iterdir()}
        known = set()
        if MANIFEST in names:
            try:
                data = json.loads((out / MANIFEST).read_text())
                known = {MANIFEST} | set(data.get("files", []))
            except (OSError, ValueError):
                known = set()
        if names and not names <= known:
            raise LutExportError(f"{out} holds files that are not an earlier LUT export "
                                 f"({', '.join(sorted(names - known)[:5])}); choose an empty or new folder")
    return out


@dataclass
class ExportResult:
    folder: Path
    files: dict            # file name -> bytes
    manifest: dict


def export(out, lut_dir=None, formats=FORMATS, precisions=PRECISIONS, layout="rtl", progress=None, rebake=False,
           log=None):
    """Export the LUTs of ``lut_dir`` (default: the shipped ones) into ``out``; returns an ExportResult.
    ``progress(done, total, what)`` is called as files are written."""
    formats, precisions = tuple(formats), tuple(precisions)
    for value, allowed, what in ((formats, FORMATS, "format"), (precisions, PRECISIONS, "precision")):
        unknown = [v for v in value if v not in allowed]
        if unknown or not value:
            raise LutExportError(f"unknown or no {what}s {unknown or list(value)}; choose from {', '.join(allowed)}")
    if layout not in LAYOUTS:
        raise LutExportError(f"unknown layout {layout!r}; choose one of {', '.join(LAYOUTS)}")
    lut_dir = Path(lut_dir) if lut_dir is not None else catalog.default_lut_dir()
    _check_sources(lut_dir, rebake, log)
    tables = layout_tables(LutSet.from_folder(lut_dir), layout)
    target = _check_target(out)
    info = manifest(tables, layout, precisions, formats, _generator_version())
    jobs = [(t, f, p) for p in precisions for t in tables for f in formats if f in ("exr", "ktx2", "dds")]
    jobs += [(None, f, p) for p in precisions for f in formats if f not in ("exr", "ktx2", "dds")]
    sizes = {}
    with replacing_folder(target, LutExportError) as tmp:
        for done, (table, fmt, precision) in enumerate(jobs):
            if table is not None:
                name = _file_name(table, fmt, precision)
                data = _table_file(table, fmt, precision, layout, info["tables"][f"{table.name}_{precision}"])
            elif fmt == "npz":
                name, data = f"rtl_luts_{precision}.npz", _npz_bytes(tables, precision, info)
            else:
                stored = {t.name: t.encode(precision)[0] for t in tables}
                name, data = lut_code.source_file(tables, fmt, precision, layout, info, stored)
            (tmp / name).write_bytes(data)
            sizes[name] = len(data)
            if progress:
                progress(done + 1, len(jobs), name)
        info["files"] = sorted(sizes)
        info["sizes"] = sizes
        (tmp / MANIFEST).write_text(json.dumps(info, indent=1))
    if log:
        log(f"export: {len(sizes)} files, {sum(sizes.values()) / 1e6:.2f} MB, layout {layout}, into {target}")
    return ExportResult(target, sizes, info)


def manifest_markdown(luts_set):
    """The tables of both layouts as docs/luts.md shows them (checked against this by the tests): exported
    name, source, size, axes, and the half export's decode scales."""
    lines = ["| layout | exported table | from | W x H | u: node i | v: node j | half decode scale (log2 R, G, B, A) |",
             "|---|---|---|---|---|---|---|"]
    for layout in LAYOUTS:
        for t in layout_tables(luts_set, layout):
            scales = ", ".join(str(int(np.log2(x))) for x in t.encode("f16")[1])
            lines.append(f"| {layout} | `{t.name}` | `{t.source}` | {t.shape[1]} x {t.shape[0]} | {t.axes['u']['node']} | "
                         f"{t.axes['v']['node']} | {scales} |")
    lines += ["", "| format | row order (both layouts) | encoding f32 / f16 | half values (rtl / ltc_code) |",
              "|---|---|---|---|"]
    for fmt in ("exr", "ktx2", "dds"):
        lines.append(f"| {fmt} | `{ROW_ORDER[fmt]}`: {_orientation(fmt, 'rtl')} | {ENCODING[fmt]['f32']} / "
                     f"{ENCODING[fmt]['f16']} | {HALF_ENCODING['rtl']} / {HALF_ENCODING['ltc_code']} |")
    return "\n".join(lines)


# --- reading back ----------------------------------------------------------------------------------

def read_table_file(path):
    """The stored (H, W, 4) float32 values of an exported table file (exr, ktx2, dds) in table row order (an EXR
    whose header says ``rtl.row_order`` v_descending, or an rtl-layout EXR of an earlier export, flipped back)."""
    path = Path(path)
    data = path.read_bytes()
    if path.suffix == ".ktx2":
        return containers.read_ktx2(data)[0]
    if path.suffix == ".dds":
        return containers.read_dds(data)
    if path.suffix == ".exr":
        attrs, planes = exr_reader.read(path)
        table = np.stack([planes[c] for c in "RGBA"], -1).astype(np.float32)
        descending = attrs.get("rtl.row_order", "v_descending" if attrs.get("rtl.layout") == "rtl" else "v_ascending")
        return np.flipud(table) if descending == "v_descending" else table
    raise LutExportError(f"{path}: not a table file")


def verify(folder, lut_dir=None):
    """Read every table file of an export back: {file: {"max_abs", "within_bound"}} against the source
    tables (decoded with the manifest's scales; f32 must be exact, f16 within half's rounding)."""
    folder = Path(folder)
    info = json.loads((folder / MANIFEST).read_text())
    tables = {t.name: t for t in layout_tables(LutSet.from_folder(lut_dir or catalog.default_lut_dir()), info["layout"])}
    report = {}
    for key, entry in info["tables"].items():
        table, scales = tables[entry["name"]], entry["decode_scale"]
        bound = rounding_bound(table.data, scales, entry["precision"])
        for fmt, f in entry["files"].items():
            got = read_table_file(folder / f["file"]) * np.asarray(scales, np.float32)
            err = np.abs(got.astype(np.float64) - table.data)
            report[f["file"]] = {"max_abs": float(err.max()), "within_bound": bool((err <= bound).all())}
        npz = folder / f"rtl_luts_{entry['precision']}.npz"
        if npz.exists():
            with np.load(npz) as data:
                got = data[entry["name"]].astype(np.float32) * np.asarray(scales, np.float32)
            err = np.abs(got.astype(np.float64) - table.data)
            report[f"{npz.name}:{entry['name']}"] = {"max_abs": float(err.max()), "within_bound": bool((err <= bound).all())}
    return report


# --- command line ----------------------------------------------------------------------------------

def parse_args(argv):
    p = argparse.ArgumentParser(description="Export the LUTs for game engines, with a manifest (core/export/luts.py)")
    p.add_argument("--out", type=Path, required=True, help="folder to write (empty, new, or an earlier export)")
    p.add_argument("--formats", default=",".join(FORMATS), help=f"comma-separated, from {', '.join(FORMATS)}")
    p.add_argument("--precision", default=",".join(PRECISIONS), help=f"comma-separated, from {', '.join(PRECISIONS)}")
    p.add_argument("--layout", default="rtl", choices=LAYOUTS)
    p.add_argument("--lut-dir", type=Path, default=None, help="the source tables (default: the shipped luts/)")
    p.add_argument("--rebake", action="store_true", help="re-bake missing, stale or corrupt source tables first")
    return p.parse_args(argv)


def run_args(args, log=print):
    """scripts/export_luts.py; the exit code (2: the export was refused, with the reason)."""
    def progress(done, total, name):
        if done == total or done % max(1, total // 10) == 0:
            log(f"  {done}/{total} {name}")

    try:
        result = export(args.out, args.lut_dir, [f for f in args.formats.split(",") if f],
                        [p for p in args.precision.split(",") if p], args.layout, progress, args.rebake, log)
    except LutExportError as exc:
        print(f"export_luts: {exc}", file=sys.stderr)
        return 2
    bad = [f for f, r in verify(result.folder, args.lut_dir).items() if not r["within_bound"]]
    if bad:
        print(f"export_luts: read back differs from the source: {bad}", file=sys.stderr)
        return 1
    log("read back: every file equals its source (f32) or is within half rounding (f16)")
    return 0
