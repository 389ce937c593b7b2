"""The world suite's per-world studies beside the gated comparison: CoD's SH-LTC against magnitude-only
and brute force, Lambert against Cycles, GGX's split sum against the true integral; their pixel helpers."""
from __future__ import annotations

import time

import numpy as np

from ..harness import metrics
from . import world_cases as vw
from ...core import indirect
from ...core.environment import equirect
from ...core.environment import prefilter
from ...core.materials import world_shading as world_term


ERR_VMAX = 0.2
#: Front-facing pixels (N.V >= this) get their own specular statistics: the split sum's error
#: concentrates at grazing view angles.
FRONT_MU = 0.5


def pool_with_front(entries):
    """``metrics.pool`` plus the median / p90 over the front-facing values (N.V >= FRONT_MU)."""
    out = metrics.pool(entries)
    front = [e["rel_front"] for e in entries if e.get("rel_front") is not None]
    if front:
        f = np.concatenate(front)
        if f.size:
            out.update({"front_values": int(f.size), "front_median": float(np.median(f)),
                        "front_p90": float(np.percentile(f, 90))})
    return out


# --- one world: pixel helpers ------------------------------------------------------------------------

def _pick_pixels(ys, xs, count, rng):
    """At most ``count`` of the pixels (ys, xs): a seeded subset, kept in raster order."""
    if len(ys) > count:
        pick = np.sort(rng.choice(len(ys), count, replace=False))
        ys, xs = ys[pick], xs[pick]
    return ys, xs


def _image_frame(scene, normal, position, R):
    """Unit normals and view directions of pixels (their Normal / Position pass values) in the
    environment image's frame: rotated by the Mapping's R."""
    from ..harness.engines import camera_incoming

    n = normal.astype(np.float64)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    view = camera_incoming(scene, position.astype(np.float64))
    return n @ R.T, np.ascontiguousarray(view @ R.T)


def view_cosine(scene, passes):
    """N.V per pixel of the node render (N the Normal pass, V towards the camera)."""
    from ..harness.engines import camera_incoming

    nrm = passes["Normal"].astype(np.float64)
    return np.sum(nrm * camera_incoming(scene, passes["Position"].astype(np.float64)), axis=-1) / \
        np.maximum(np.linalg.norm(nrm, axis=-1), 1e-12)


# --- one world: studies ------------------------------------------------------------------------------

def cod_study(spec, bake, image, variants, block, scene, passes, index, a, args, rng, tables, technique="cod"):
    """Item 2 on up to ``--cod-pixels`` seeded pixels of every CoD sphere (``technique`` "cod", or "cod_wrapped":
    the multiscattering wrapped diffuse at the variant's wrap): the SH-LTC lobe (numpy float64, and (a)) and the
    magnitude-only baseline vs the brute-force integrals of the true BRDF under the SH environment and under the
    area-averaged image.  Image frame: n, v rotated by the Mapping's R."""
    R = vw.euler_xyz_matrix(spec.rotation)
    coeffs = np.asarray(bake.sh_image, np.float64)
    quad = vw.image_quadrature(image, (args.cod_image, args.cod_image // 2))
    rows, parts = [], {k: [] for k in ("ltc", "mag", "node", "ref_sh", "ref_img")}
    t0 = time.perf_counter()
    for i, v in enumerate(variants):
        if v.technique != technique:
            continue
        ys, xs = _pick_pixels(*np.nonzero(index == i), args.cod_pixels, rng)
        ni, vi = _image_frame(scene, passes["Normal"][ys, xs], passes["Position"][ys, xs], R)
        wrap = v.wrap if technique == "cod_wrapped" else None
        vals = _cod_values(spec, tables, coeffs, quad, ni, vi, v.roughness, a[ys, xs], wrap)
        for k in parts:
            parts[k].append(vals[k])
        rows.append(_cod_row(vals, v.roughness, len(ys), args))
    if not rows:
        return None
    return {"per_roughness": rows, "pooled": _cod_pooled_stats(parts, args),
            "image_quadrature": [args.cod_image, args.cod_image // 2], "seconds": time.perf_counter() - t0}


def _cod_values(spec, tables, coeffs, quad, ni, vi, roughness, node, wrap=None):
    """One CoD sphere's pixels: the SH-LTC lobe and the magnitude-only baseline (numpy float64), the node
    render's values, and the brute-force references under the SH environment and under the image; ``wrap``: the
    multiscattering wrapped diffuse's (None: the CoD diffuse)."""
    r = np.full(len(ni), roughness)
    white = np.ones(3)
    s = spec.strength
    if wrap is not None:
        cl = indirect.coefficient_list(coeffs)
        return {"ltc": s * indirect.sh_cod_wrapped_diffuse(tables, cl, ni, vi, roughness, white, wrap),
                "mag": s * indirect.sh_cod_wrapped_diffuse_magnitude_only(tables, cl, ni, vi, roughness, white, wrap),
                "node": node.astype(np.float64),
                "ref_sh": s * indirect.cod_wrapped_diffuse_reference(coeffs, ni, vi, r, wrap),
                "ref_img": s * vw.cod_reference_image(quad, ni, vi, r, wrap=wrap)}
    return {"ltc": s * indirect.sh_cod_diffuse(tables, indirect.coefficient_list(coeffs), ni, vi, roughness, white),
            "mag": s * indirect.sh_cod_diffuse_magnitude_only(tables, indirect.coefficient_list(coeffs), ni, vi,
                                                              roughness, white),
            "node": node.astype(np.float64),
            "ref_sh": s * indirect.cod_diffuse_reference(coeffs, ni, vi, r),
            "ref_img": s * vw.cod_reference_image(quad, ni, vi, r)}


def _cod_row(vals, roughness, pixels, args):
    """One CoD sphere's errors: each model vs each reference, (a) vs numpy, and the two references."""
    return {"roughness": roughness, "pixels": int(pixels),
            **{f"{m}_vs_{ref}": vw.rel_stats(vals[m], vals[ref], args.floor)
               for m in ("ltc", "mag") for ref in ("ref_sh", "ref_img")},
            "node_vs_ltc_numpy": vw.rel_stats(vals["node"], vals["ltc"], args.floor_wide),
            "sh_ref_vs_img_ref": vw.rel_stats(vals["ref_sh"], vals["ref_img"], args.floor)}


def _cod_pooled_stats(parts, args):
    """The CoD errors over all the world's CoD spheres, at both floors."""
    cat = {k: np.concatenate(v) for k, v in parts.items()}
    pooled = {f"{m}_vs_{ref}": vw.rel_stats(cat[m], cat[ref], args.floor) for m in ("ltc", "mag")
              for ref in ("ref_sh", "ref_img")}
    pooled.update({f"{m}_vs_{ref}_wide": vw.rel_stats(cat[m], cat[ref], args.floor_wide) for m in ("ltc", "mag")
                   for ref in ("ref_sh", "ref_img")})
    pooled["node_vs_ltc_numpy"] = vw.rel_stats(cat["node"], cat["ltc"], args.floor_wide)
    return pooled


def lambert_study(spec, image, variants, block, scene, passes, index, a, truth_cell, mask_cell, args):
    """SH truncation (a vs the texel-sum Lambert) and the harness check (texel sum vs Cycles) on the
    Lambert sphere's pixels."""

    i = next((k for k, v in enumerate(variants) if v.technique == "lambert"), None)
    if i is None:
        return None
    R = vw.euler_xyz_matrix(spec.rotation)
    quad = vw.image_quadrature(image, (args.lambert_image, args.lambert_image // 2))
    na = block.cell(passes["Normal"], i).astype(np.float64)
    sel = mask_cell
    n = na[sel] / np.linalg.norm(na[sel], axis=-1, keepdims=True)
    ref = spec.strength * vw.lambert_reference_image(quad, n @ R.T)
    a_cell = block.cell(a, i)[sel]
    out = {"sh_vs_image": vw.rel_stats(a_cell, ref, args.floor),
           "image_quadrature": [args.lambert_image, args.lambert_image // 2]}
    if truth_cell is not None:
        out["image_vs_cycles"] = vw.rel_stats(ref, truth_cell[sel], args.floor)
    return out


def ggx_study(spec, image, variants, block, scene, passes, a, truth, closures, args, rng, tables):
    """Harness of the specular comparison on ``--ggx-pixels`` seeded pixels of every single-scattering
    sphere with r >= 0.25: the brute-force integral of the true GGX BRDF (F = 1) over the image
    (area-averaged to ``--ggx-image`` texels) vs Cycles Glossy GGX (must agree to the noise), and the
    split sum (a) vs that integral (its error without Monte Carlo noise), split into the split sum's
    own approximation (the exact split sum E(N.V) P(dominant direction), P the brute-force prefilter
    integral over the same texels, vs the integral) and the stored levels' lookup (a vs that exact
    split sum: 128 x 64 levels, bilinear, linear between roughness levels)."""
    if args.ggx_pixels <= 0:
        return None
    R = vw.euler_xyz_matrix(spec.rotation)
    quad = vw.image_quadrature(image, (args.ggx_image, args.ggx_image // 2))
    small = equirect.downsample(np.asarray(image, np.float32), image.shape[1] // args.ggx_image)
    rows = []
    t0 = time.perf_counter()
    for i, v in enumerate(variants):
        if v.technique != "ggx" or v.roughness < 0.25:
            continue
        j = closures.index(v.closure) if truth is not None else None
        normal, position = block.cell(passes["Normal"], i), block.cell(passes["Position"], i)
        ys, xs = _pick_pixels(*np.nonzero(np.linalg.norm(normal, axis=-1) > 0.5), args.ggx_pixels, rng)
        ni, vi = _image_frame(scene, normal[ys, xs], position[ys, xs], R)
        cycles = truth["block"].cell(truth["mean"], j)[ys, xs] if truth is not None else None
        rows.append(_ggx_row(spec, tables, quad, small, ni, vi, v.roughness, block.cell(a, i)[ys, xs], cycles, args))
    return {"rows": rows, "image_quadrature": [args.ggx_image, args.ggx_image // 2],
            "seconds": time.perf_counter() - t0} if rows else None


def _ggx_row(spec, tables, quad, small, ni, vi, roughness, node, cycles, args):
    """One ggx sphere's pixels: the split sum (a), the exact split sum and Cycles (``cycles``, None
    without a truth) vs the brute-force GGX integral, and (a) vs the exact split sum."""
    ref = spec.strength * vw.ggx_reference_image(quad, ni, vi, roughness)
    mu = np.clip(np.sum(ni * vi, axis=-1), 0.0, 1.0)
    scale_a, bias_b = tables.split_sum(mu, np.full(len(mu), roughness))
    dom = np.asarray(world_term.dominant_direction(ni, vi, np.full(len(mu), roughness)), np.float64)
    exact = spec.strength * (np.asarray(scale_a + bias_b, np.float64)[:, None]
                             * prefilter.prefilter_reference(small, dom, roughness, rule="area"))
    row = {"roughness": roughness, "pixels": int(len(ni)),
           "split_sum_vs_brute": vw.rel_stats(node, ref, args.floor),
           "exact_split_sum_vs_brute": vw.rel_stats(exact, ref, args.floor),
           "split_sum_vs_exact_split_sum": vw.rel_stats(node, exact, args.floor),
           "bias_exact_split_sum_vs_brute": float(np.sum(exact - ref) / np.sum(ref))}
    if cycles is not None:
        row["brute_vs_cycles"] = vw.rel_stats(ref, cycles, args.floor)
    return row
