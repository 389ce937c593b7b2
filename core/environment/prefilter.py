"""GGX-prefiltered environment radiance for the split-sum approximation, and the cached bake of an
environment (SH + prefiltered levels) into EXR files.

What is computed
----------------
Karis 2013, "Real Shading in Unreal Engine 4" (SIGGRAPH course notes), eq. 7 and the listing
``PrefilterEnvMap``: with the split sum, the radiance integral is approximated by assuming
N = V = R, and the first factor is

    P(R, r) = sum_k L(l_k) (R.l_k) / sum_k (R.l_k),   h_k ~ D(h)(N.h),  l_k = 2 (R.h_k) h_k - R,

i.e. the normalised convolution  P(R) = int L(l) D(h) max(R.l, 0) dl / int D(h) max(R.l, 0) dl  with
h = normalize(R + l) (the pdf of l is D(h)(N.h)/(4 V.h) = D(h)/4 when N = V), GGX D of alpha =
max(r^2, 1e-4) (core/microfacet.py).  ``prefilter_reference`` evaluates that integral by brute force
over every texel of the source.

How
---
Default (``method="fft"``): exact quadrature of that integral over every texel of the source (Fejer
weights in cos theta, midpoint in phi), the same sum as ``prefilter_reference`` at each output texel
centre, computed per (output row, source row) pair as a circular correlation in longitude with the FFT
(``prefilter_level_fft``): the kernel depends on R.l only, so along a row it is a function of the
longitude difference.  Measured (docs/benchmarks/environment.md): equal to the brute force to ~1e-7
relative, about 1.2 s per level (1024 x 512 source, 128 x 64 output), no noise, no mip bias.
Level r = 0 (and any lobe narrower than a source texel) is the mirror limit: the source area-averaged
to the output resolution.  A source wider than ``PrefilterSettings.max_source_width`` (1024) is first
area-averaged to that width (``prefilter_source``), which bounds the bake's time and memory for 4K-16K
HDRIs; the SH projection always uses the full image.

Alternative (``method="importance"``, kept for the measured comparison): importance sampling of the
GGX NDF (Karis 2013, ``ImportanceSampleGGX``: phi = 2 pi xi_1, cos theta_h = sqrt((1 - xi_2)/(1 +
(alpha^2 - 1) xi_2))) with a 2D Hammersley set (core/sampling.py), each sample looked up in a mip chain
of the source with trilinear filtering at the level (Colbert & Krivanek 2007, "GPU-Based Importance
Sampling", GPU Gems 3 ch. 20, eq. 12-13)

    lod = 1/2 log2(Omega_s / Omega_p) + bias,  Omega_s = 1 / (N pdf(l)),  Omega_p = texel solid angle

with Omega_p the level-0 texel's solid angle at the sample's latitude, (2 pi / W)(pi / H) sin theta
(equirect texels shrink towards the poles), and the level floored at the mip whose resolution is the
output's.  The mip chain is the solid-angle-weighted 2 x 2 average (equirect.downsample).  With 256
samples it is 1-5% (mean relative) from the brute force at 0.6-1 s per level; C&K's bias of 1 level
doubles to triples that error here, so the default bias is 0.

Layout of the prefiltered file
------------------------------
``<name>_ggx_prefiltered.exr``: one float RGBA EXR (core/lut/exr_io.py conventions: rows flipped so
Blender's row j counts from the bottom, ``rtl.`` metadata, content hash).  The L roughness levels are
stacked vertically, each an equirect image of W x H in Blender's mapping (equirect.py): level k
(roughness ``rtl.roughness_levels``[k]) occupies the Blender rows [k H, (k + 1) H); a direction d
(after the world's Mapping rotation, the same Vector as the Environment Texture) maps to
u = 0.5 - atan2(y, x)/(2 pi) (REPEAT), v = (k + clamp(v_d, 0.5/H, 1 - 0.5/H)) / L with
v_d = 1 - acos(z)/pi: the clamp keeps Linear filtering inside the level.  Interpolating across
roughness: the two levels around r, linearly.  Values are in the source image's units (strength 1,
no rotation): the world's strength multiplies and its rotation rotates the lookup, as for the
Environment Texture itself, so neither needs a re-bake.
"""
from __future__ import annotations

import hashlib
import json
import math
import os
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..lut import catalog, exr_io
from ..microfacet import ggx_distribution
from ..sampling import hammersley_2d
from . import equirect, sh

GENERATOR = "rt_lookdev.core.environment.prefilter"
GENERATOR_VERSION = 1
LAYOUT_VERSION = 1

ROUGHNESS_LEVELS = tuple(k / 8.0 for k in range(9))

_SOURCES = ("core/environment/equirect.py", "core/environment/sh.py", "core/environment/prefilter.py",
            "core/microfacet.py", "core/sampling.py", "core/conventions.py", "core/lut/exr_io.py")
_PACKAGE_ROOT = Path(__file__).resolve().parents[2]


@dataclass(frozen=True)
class PrefilterSettings:
    """Output size per level, roughness levels, samples per texel, Colbert-Krivanek lod bias.
    The defaults are measured (docs/benchmarks/environment.md)."""
    width: int = 128
    height: int = 64
    roughness: tuple = ROUGHNESS_LEVELS
    method: str = "fft"           # "fft" (exact quadrature) or "importance" (Colbert & Krivanek 2007)
    samples: int = 256            # importance only
    lod_bias: float = 0.0         # importance only (C&K use 1; measured worse here)
    max_source_width: int = 1024  # wider sources are area-averaged to this first (``prefilter_source``)

    def __post_init__(self):
        ratio = self.max_source_width / self.width
        if self.max_source_width < self.width or ratio != 2 ** round(math.log2(ratio)):
            raise ValueError(f"max_source_width must be the output width {self.width} times a power of two, "
                             f"got {self.max_source_width}")

    def as_dict(self):
        d = {"width": self.width, "height": self.height, "roughness": list(self.roughness), "method": self.method,
             "max_source_width": self.max_source_width}
        if self.method == "importance":
            d.update(samples=self.samples, lod_bias=self.lod_bias)
        return d


def alpha_of(r):
    return max(float(r) ** 2, 1e-4)


# --- brute force ---------------------------------------------------------------------------------

def prefilter_reference(image, directions, roughness, rule="fejer", chunk=64):
    """Brute-force P(R) = int L D(h) max(R.l, 0) dl / int D(h) max(R.l, 0) dl over every texel of
    ``image`` (H, W, 3), directions R (K, 3) in the image's frame -> (K, 3) float64."""
    image = np.asarray(image, dtype=np.float64)
    h, w = image.shape[:2]
    dirs = equirect.texel_directions(h, w).reshape(-1, 3)
    wts = equirect.quadrature_weights(h, w, rule).reshape(-1)
    lum = image.reshape(-1, 3)
    alpha = alpha_of(roughness)
    R = np.asarray(directions, dtype=np.float64).reshape(-1, 3)
    out = np.empty((len(R), 3))
    for s in range(0, len(R), chunk):
        r = R[s:s + chunk]
        cos_rl = r @ dirs.T                                        # (k, T)
        # n.h with h = (R + l)/|R + l|, |R + l| = sqrt(2 + 2 R.l)
        n_dot_h = np.sqrt(np.maximum(0.5 * (1.0 + cos_rl), 0.0))
        k = ggx_distribution(n_dot_h, alpha) * np.maximum(cos_rl, 0.0) * wts
        out[s:s + chunk] = (k @ lum) / np.maximum(k.sum(axis=1, keepdims=True), 1e-300)
    return out


# --- importance sampling -------------------------------------------------------------------------

def _frame(n):
    """Orthonormal (t, b) with t x b = n for unit n (..., 3) (Duff et al. 2017, "Building an
    Orthonormal Basis, Revisited", JCGT 6(1), listing 3)."""
    x, y, z = n[..., 0], n[..., 1], n[..., 2]
    sign = np.where(z >= 0.0, 1.0, -1.0)
    a = -1.0 / (sign + z)
    b = x * y * a
    t = np.stack([1.0 + sign * x * x * a, sign * b, -sign * x], axis=-1)
    bb = np.stack([b, sign + y * y * a, -y], axis=-1)
    return t, bb


def ggx_sample_set(alpha, n):
    """Local light directions (K, 3) of the split-sum estimator (N = V = +Z), their weights N.l and
    pdf(l) = D(h)/4, from the n-point Hammersley set (Karis 2013, ``ImportanceSampleGGX``); samples
    below the horizon are dropped (weight 0 in Karis' sum)."""
    xi1, xi2 = hammersley_2d(n)
    a2 = alpha * alpha
    cos_h = np.sqrt((1.0 - xi2) / (1.0 + (a2 - 1.0) * xi2))
    sin_h = np.sqrt(np.maximum(1.0 - cos_h * cos_h, 0.0))
    phi = 2.0 * np.pi * xi1
    hvec = np.stack([sin_h * np.cos(phi), sin_h * np.sin(phi), cos_h], axis=-1)
    l = 2.0 * cos_h[:, None] * hvec - np.array([0.0, 0.0, 1.0])
    keep = l[:, 2] > 0.0
    pdf = ggx_distribution(cos_h, alpha) / 4.0
    return l[keep], l[keep, 2], pdf[keep]


def _trilinear(mips, x_unit, y_unit, lod):
    """Sample the mip chain at unit coordinates (u, row fraction from the top) with trilinear
    filtering at fractional ``lod`` (all (...,)); returns (..., 3)."""
    out = np.zeros(lod.shape + (3,), dtype=np.float32)
    top = len(mips) - 1
    lod = np.clip(lod, 0.0, top)
    lo = np.floor(lod).astype(np.int64)
    frac = (lod - lo).astype(np.float32)
    for k in range(top + 1):
        wk = np.where(lo == k, 1.0 - frac, 0.0) + np.where(lo + 1 == k, frac, 0.0)
        idx = np.nonzero(wk > 0.0)
        if not idx[0].size:
            continue
        img = mips[k]
        hk, wk_ = img.shape[:2]
        val = equirect.bilinear(img, x_unit[idx] * wk_ - 0.5, y_unit[idx] * hk - 0.5)
        out[idx] += wk[idx][:, None].astype(np.float32) * val
    return out


def _power_of_two_source(image, width):
    """The source as an image whose width is width * 2^k (k >= 0), resampled bilinearly if needed,
    so that its mip chain reaches the output resolution exactly."""
    h, w = image.shape[:2]
    k = max(0, math.ceil(math.log2(w / width)))
    target_w = width * 2 ** k
    if target_w == w and h * 2 == w:
        return image
    dirs = equirect.texel_directions(target_w // 2, target_w)
    return equirect.sample_equirect(image, dirs).astype(np.float32)


def prefilter_source(image, settings):
    """The source the levels are computed from: an image wider than ``settings.max_source_width`` is
    area-averaged (``equirect.resample_area``) to max_source_width x max_source_width / 2, any other
    goes through ``_power_of_two_source``.  The quadrature's time grows with the source's texel count
    (FFT: O(H_o H_s W_s log W_s)) and its memory with an output chunk times the source, so at the
    default cap a 4K or 8K HDRI costs what a 1024 x 512 one does.  docs/benchmarks/environment.md
    measures time, peak memory and the levels' difference with and without the cap."""
    image = np.asarray(image, dtype=np.float32)
    if image.shape[1] > settings.max_source_width:
        return equirect.resample_area(image, settings.max_source_width // 2, settings.max_source_width)
    return _power_of_two_source(image, settings.width)


def prefilter_level(mips, roughness, width, height, samples, lod_bias=0.0, rows=None):
    """One prefiltered level (height, width, 3) float32 in the image frame (or only ``rows``)."""
    alpha = alpha_of(roughness)
    h0, w0 = mips[0].shape[:2]
    lod_min = math.log2(w0 / width)
    l_local, weight, pdf = ggx_sample_set(alpha, samples)
    half_log_omega_s = 0.5 * np.log2(1.0 / (samples * pdf))                # (S,)
    omega_p_scale = (2.0 * np.pi / w0) * (np.pi / h0)
    rows = range(height) if rows is None else rows
    theta, phi = equirect.texel_angles(height, width)
    out = np.empty((len(rows), width, 3), np.float32)
    wsum = weight.sum()
    for i, row in enumerate(rows):
        st, ct = np.sin(theta[row]), np.cos(theta[row])
        R = np.stack([st * np.cos(phi), st * np.sin(phi), np.full_like(phi, ct)], axis=-1)   # (W, 3)
        t, b = _frame(R)
        L = (l_local[None, :, 0, None] * t[:, None, :] + l_local[None, :, 1, None] * b[:, None, :]
             + l_local[None, :, 2, None] * R[:, None, :])                                   # (W, S, 3)
        z = np.clip(L[..., 2], -1.0, 1.0)
        sin_t = np.sqrt(np.maximum(1.0 - z * z, 1e-12))
        u = 0.5 - np.arctan2(L[..., 1], L[..., 0]) / (2.0 * np.pi)
        y = np.arccos(z) / np.pi                                                            # row fraction from the top
        lod = half_log_omega_s[None, :] - 0.5 * np.log2(omega_p_scale * sin_t) + lod_bias
        lod = np.maximum(lod, lod_min)
        val = _trilinear(mips, u, y, lod)                                                   # (W, S, 3)
        out[i] = np.einsum("wsc,s->wc", val, weight.astype(np.float32)) / wsum
    return out


def prefilter_level_fft(image, roughness, width, height, rows=None, chunk=8, progress=None):
    """One prefiltered level (height, width, 3) float32 by exact quadrature of the split-sum integral
    over every texel of ``image`` (the brute force of ``prefilter_reference`` at the output texel
    centres, to rounding), computed row by row as circular correlations in longitude with the FFT.

    The kernel K(R, l) = D(h) max(R.l, 0) depends on R.l = cos t_o cos t_s + sin t_o sin t_s cos(dphi)
    only, so for an output row t_o and a source row t_s it is a function of the longitude difference;
    with the source width W_s = f x width, the output centres sit at fixed offsets
    dphi_n = 2 pi (n + 1/2 - f/2) / W_s from the source columns, and the sum over the row is the
    circular correlation sum_n K[n] L[n + f i], one FFT per (t_o, t_s) pair instead of W_s^2 products
    (convolution theorem).  Cost O(H_o H_s W_s log W_s): about 2 s per level for a 1024 x 512 source
    and a 128 x 64 output.  Weights: Fejer in cos theta x midpoint in phi (equirect.quadrature_weights)."""
    image = _power_of_two_source(np.asarray(image, dtype=np.float32), width)
    hs, ws = image.shape[:2]
    f = ws // width
    alpha = alpha_of(roughness)
    theta_s = np.pi * (np.arange(hs) + 0.5) / hs
    w_s = equirect.fejer_weights(hs) * (2.0 * np.pi / ws)
    delta = 2.0 * np.pi * (np.arange(ws) + 0.5 - 0.5 * f) / ws
    cos_d = np.cos(delta)
    lhat = np.fft.rfft(image.astype(np.float64), axis=1)                      # (hs, F, 3)
    theta_o = np.pi * (np.arange(height) + 0.5) / height
    rows = np.arange(height) if rows is None else np.asarray(rows)
    out = np.empty((len(rows), width, 3), np.float32)
    cs, ss = np.cos(theta_s), np.sin(theta_s)
    for start in range(0, len(rows), chunk):
        ro = rows[start:start + chunk]
        co, so = np.cos(theta_o[ro]), np.sin(theta_o[ro])
        cos_rl = (co[:, None, None] * cs[None, :, None]
                  + (so[:, None] * ss[None, :])[:, :, None] * cos_d[None, None, :])     # (o, s, n)
        n_dot_h = np.sqrt(np.maximum(0.5 * (1.0 + cos_rl), 0.0))
        k = ggx_distribution(n_dot_h, alpha) * np.maximum(cos_rl, 0.0) * w_s[None, :, None]
        den = k.sum(axis=(1, 2))
        khat = np.fft.rfft(k, axis=-1)                                            # (o, s, F)
        corr = np.fft.irfft(np.einsum("osf,sfc->ofc", np.conj(khat), lhat), n=ws, axis=1)   # (o, ws, 3)
        out[start:start + len(ro)] = (corr[:, ::f, :] / den[:, None, None]).astype(np.float32)
        if progress:
            progress(start + len(ro), len(rows))
    return out


def prefilter(image, settings=PrefilterSettings(), progress=None):
    """All levels: (L, height, width, 3) float32 in the image frame (row 0 = zenith).  ``progress(done,
    total)`` after every level."""
    if settings.method not in ("fft", "importance"):
        raise ValueError(f"unknown prefilter method {settings.method!r} (fft, importance)")
    image = prefilter_source(image, settings)
    mips = equirect.mip_chain(image)
    mirror = mips[int(round(math.log2(image.shape[1] / settings.width)))]
    out = np.empty((len(settings.roughness), settings.height, settings.width, 3), np.float32)
    for k, r in enumerate(settings.roughness):
        if alpha_of(r) < np.pi / image.shape[0]:
            # A lobe narrower than a source texel: the mirror limit, the source area-averaged to the
            # output's resolution (the kernel cannot be point-sampled on the source grid).
            out[k] = mirror
        elif settings.method == "fft":
            out[k] = prefilter_level_fft(image, r, settings.width, settings.height)
        else:
            out[k] = prefilter_level(mips, r, settings.width, settings.height, settings.samples, settings.lod_bias)
        if progress:
            progress(k + 1, len(settings.roughness))
    return out


def sample_prefiltered(levels, roughness_levels, directions, roughness, rotation_z=0.0, strength=1.0):
    """Look up prefiltered radiance as a shader would: world directions (..., 3) rotated by the world's
    Mapping rotation, bilinear within a level, linear across the two levels around ``roughness``
    (scalar), times strength."""
    d = np.asarray(directions, dtype=np.float64)
    if rotation_z:
        d = d @ equirect.rotation_z(rotation_z).T
    rl = np.asarray(roughness_levels, dtype=np.float64)
    r = float(np.clip(roughness, rl[0], rl[-1]))
    k = int(np.clip(np.searchsorted(rl, r, side="right") - 1, 0, len(rl) - 2))
    f = (r - rl[k]) / (rl[k + 1] - rl[k])
    a = equirect.sample_equirect(levels[k], d)
    b = equirect.sample_equirect(levels[k + 1], d)
    return strength * ((1.0 - f) * a + f * b)


# --- cached bake -----------------------------------------------------------------------------------

@dataclass
class EnvironmentBake:
    name: str
    source: str
    source_hash: str
    sh_image: np.ndarray          # (9, 3) coefficients of the image (strength 1, no rotation)
    sh_path: Path
    sh_json_path: Path
    prefiltered_path: Path
    states: dict = field(default_factory=dict)      # "sh" / "prefiltered" -> "baked" or "cached"
    seconds: dict = field(default_factory=dict)     # read, sh, prefiltered, total
    prefiltered_hash: str = ""    # inputs_hash of the prefiltered file (source, parameters, code)

    @property
    def table_name(self):
        """Name of the prefiltered table as shading code and Blender images know it: env_<hash>, from
        the file's inputs hash, so another image, other settings or other code give another name."""
        return f"env_{self.prefiltered_hash[:12]}"

    def world_sh(self, rotation_z=0.0, strength=1.0):
        """Coefficients of the world radiance strength * image(R_z(rotation_z) d)."""
        return strength * sh.sh_rotate_z(self.sh_image, rotation_z)


def inputs_hash(kind, source_hash, params):
    """SHA-256 of the source image's content hash, the parameters and the code that computes the file
    (without comments and docstrings: ``core.lut.catalog.code_text``)."""
    hsh = hashlib.sha256()
    hsh.update(json.dumps({"kind": kind, "layout": LAYOUT_VERSION, "generator": GENERATOR_VERSION,
                           "source": source_hash, "params": params}, sort_keys=True).encode())
    for rel in _SOURCES:
        hsh.update(rel.encode())
        hsh.update(catalog.code_text(_PACKAGE_ROOT / rel).encode())
    return hsh.hexdigest()


def _is_current(path, expected):
    try:
        _, meta = exr_io.read_table(path)
    except exr_io.LutError:
        return False
    return meta.get("inputs_hash") == expected


def read_prefiltered(path):
    """(levels (L, H, W, 3) float32 top row first, roughness levels, metadata) of a prefiltered file."""
    table, meta = exr_io.read_table(path)
    rl = json.loads(meta["roughness_levels"])
    h = table.shape[0] // len(rl)
    levels = np.stack([np.flipud(table[k * h:(k + 1) * h, :, :3]) for k in range(len(rl))])
    return levels, rl, meta


def read_sh(path):
    """(9, 3) coefficients of an SH file (image frame, strength 1) and its metadata."""
    table, meta = exr_io.read_table(path)
    return table[0, :, :3].astype(np.float64), meta


def _log_progress(stage, done, total):
    pass


def bake_environment(hdri, out_dir, settings=PrefilterSettings(), progress=None, force=False, sh_rule="fejer"):
    """Bake (or find cached) the SH coefficients and the prefiltered levels of one equirect HDRI.

    ``hdri``: a studio HDRI name or an EXR path, read with ``equirect.read_equirect`` and baked by
    ``bake_environment_image`` under the file's stem (``seconds["read"]`` includes the reading)."""
    t_start = time.perf_counter()
    path = equirect.resolve_hdri(hdri)
    image = equirect.read_equirect(path)
    read = time.perf_counter() - t_start
    bake = bake_environment_image(image, path.stem, str(path), out_dir, settings, progress, force, sh_rule)
    bake.seconds["read"] += read
    bake.seconds["total"] += read
    return bake


def bake_environment_image(image, name, source, out_dir, settings=PrefilterSettings(), progress=None, force=False,
                           sh_rule="fejer"):
    """Bake (or find cached) the SH coefficients and the prefiltered levels of an equirect image.

    ``image``: (H, W, 3) float32, top scanline first (as ``equirect.read_equirect`` returns);
    ``name``: the file-name stem; ``source``: where the image came from (recorded in the metadata).
    Files in ``out_dir``: ``<name>_sh.exr`` (9 x 1 RGBA, texel i = coefficient i), ``<name>_sh.json``
    (the same numbers, readable), and ``<name>_ggx_prefiltered.exr`` (module docstring).  Each file
    is skipped when it reads back intact and its ``inputs_hash`` (source content hash + parameters +
    code) matches: a re-run with the same inputs only hashes the image and reads the headers.
    ``progress(stage, done, total)``."""
    progress = progress or _log_progress
    t_start = time.perf_counter()
    image = np.asarray(image, dtype=np.float32)
    if image.ndim != 3 or image.shape[2] != 3:
        raise ValueError(f"expected an (H, W, 3) image, got shape {image.shape}")
    source = str(source)
    source_hash = equirect.image_hash(image)
    image = equirect.replicate_to_minimum(image)              # tiny images: the same world, integrable
    seconds = {"read": time.perf_counter() - t_start}          # hashing (bake_environment adds the file read)
    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    states = {}

    sh_params = {"rule": sh_rule, "order": "l<=2 (0,0),(1,-1),(1,0),(1,1),(2,-2),(2,-1),(2,0),(2,1),(2,2)"}
    sh_hash = inputs_hash("sh9", source_hash, sh_params)
    sh_path = out_dir / f"{name}_sh.exr"
    sh_json = out_dir / f"{name}_sh.json"
    t0 = time.perf_counter()
    if not force and _is_current(sh_path, sh_hash) and sh_json.is_file():
        coeffs, _ = read_sh(sh_path)
        states["sh"] = "cached"
    else:
        progress("sh", 0, 1)
        coeffs = sh.sh_project(image, rule=sh_rule)
        table = np.concatenate([coeffs, np.ones((9, 1))], axis=1)[None].astype(np.float32)
        exr_io.write_table(sh_path, table, {
            "table": "env_sh9", "description": f"L2 SH radiance coefficients of {name} (R&H 2001), image frame, strength 1",
            "channels": "texel i = coefficient i (order " + sh_params["order"] + "), RGB; A = 1",
            "axis_u": "coefficient index", "axis_v": "none", "layout_version": LAYOUT_VERSION,
            "generator": GENERATOR, "generator_version": GENERATOR_VERSION, "params": json.dumps(sh_params),
            "inputs_hash": sh_hash, "source": source, "source_hash": source_hash})
        coeffs = table[0, :, :3].astype(np.float64)          # the stored (float32) values
        tmp = sh_json.with_name(f"{sh_json.name}.{os.getpid()}.tmp")
        tmp.write_text(json.dumps({"source": source, "source_hash": source_hash, "order": sh_params["order"],
                                   "frame": "image (apply world rotation and strength at use)",
                                   "coefficients_rgb": coeffs.tolist(), "inputs_hash": sh_hash}, indent=1))
        tmp.replace(sh_json)
        states["sh"] = "baked"
        progress("sh", 1, 1)
    seconds["sh"] = time.perf_counter() - t0

    params = settings.as_dict()
    pf_hash = inputs_hash("ggx_prefiltered", source_hash, params)
    pf_path = out_dir / f"{name}_ggx_prefiltered.exr"
    t0 = time.perf_counter()
    if not force and _is_current(pf_path, pf_hash):
        states["prefiltered"] = "cached"
    else:
        levels = prefilter(image, settings, progress=lambda d, t: progress("prefiltered", d, t))
        table = np.concatenate([np.flipud(lv) for lv in levels], axis=0)
        table = np.concatenate([table, np.ones(table.shape[:2] + (1,), np.float32)], axis=-1)
        exr_io.write_table(pf_path, table, {
            "table": "env_ggx_prefiltered",
            "description": f"split-sum GGX prefiltered radiance of {name} (Karis 2013), image frame, strength 1",
            "channels": "RGB radiance; A = 1",
            "axis_u": "u = 0.5 - atan2(y, x)/(2 pi) (Blender equirect), REPEAT",
            "axis_v": (f"level k of {len(settings.roughness)} in rows [k H, (k+1) H), H = {settings.height}; "
                       "v = (k + clamp(1 - acos(z)/pi, 0.5/H, 1 - 0.5/H)) / L"),
            "roughness_levels": json.dumps(list(settings.roughness)),
            "layout_version": LAYOUT_VERSION, "generator": GENERATOR, "generator_version": GENERATOR_VERSION,
            "method": (f"importance: {settings.samples} hammersley-2d+ggx-ndf samples, trilinear mip lookups "
                       "(Colbert-Krivanek 2007)" if settings.method == "importance" else
                       "fft: exact quadrature over the source texels (prefilter_level_fft)"),
            "source_size": f"{image.shape[1]} x {image.shape[0]}, prefiltered from "
                           f"{min(image.shape[1], settings.max_source_width)} wide",
            "params": json.dumps(params, sort_keys=True), "inputs_hash": pf_hash,
            "source": source, "source_hash": source_hash})
        states["prefiltered"] = "baked"
    seconds["prefiltered"] = time.perf_counter() - t0
    seconds["total"] = time.perf_counter() - t_start
    return EnvironmentBake(name, source, source_hash, coeffs, sh_path, sh_json, pf_path, states, seconds, pf_hash)
