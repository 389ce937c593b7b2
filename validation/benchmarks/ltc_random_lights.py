"""The LTC benchmark's end-to-end measurements: random quad and disk lights, the LTC estimate against the
true integral per lobe, the sheen models, the exactness of the Zeltner and disk forms."""
from __future__ import annotations

import numpy as np

from ...core.ir import semantics
from ...core.ltc import disk, fit, fit_lobes as lobes, matrix, polygon, reference, shading
from ...core.lut import catalog, lookup
from ...core import cloth
from ...core import sheen


# --- end-to-end: random lights ---------------------------------------------------------------

def _orthonormal(n):
    t = np.cross(n, [0.0, 0.0, 1.0] if abs(n[2]) < 0.9 else [1.0, 0.0, 0.0])
    t /= np.linalg.norm(t)
    return t, np.cross(n, t)


def light_facing_point(kind, rng, direction, distance, max_tilt_deg, quad_side, disk_radius):
    """A seeded light in ``direction`` (unit) from the shading point at the origin, ``distance`` (lo, hi) away, its
    lit side turned towards the point within ``max_tilt_deg``: a quad (4, 3) of sides in ``quad_side`` (ltc_code's
    winding: (c1 - c0) x (c3 - c0) points away from the lit side) or a disk (centre, axis_u, axis_v) of radius in
    ``disk_radius`` (axis_u x axis_v points away from the lit side)."""
    centre = direction * rng.uniform(*distance)
    tilt = rng.normal(size=3)
    tilt -= direction * (tilt @ direction)
    tilt /= np.linalg.norm(tilt)
    ang = np.radians(rng.uniform(0.0, max_tilt_deg))
    normal = -(np.cos(ang) * direction + np.sin(ang) * tilt)          # emits towards the point
    t1, t2 = _orthonormal(normal)
    if kind == "quad":
        w, h = rng.uniform(*quad_side, 2) / 2
        corners = np.array([centre - w * t1 - h * t2, centre + w * t1 - h * t2,
                            centre + w * t1 + h * t2, centre - w * t1 + h * t2])
        if np.cross(corners[1] - corners[0], corners[3] - corners[0]) @ normal > 0:
            corners = corners[::-1]
        return corners
    rad = rng.uniform(*disk_radius)
    u, w2 = t1 * rad, t2 * rad
    if np.cross(u, w2) @ normal > 0:
        w2 = -w2
    return centre, u, w2


def random_lights(kind, count, lobe_name, seed):
    """Seeded random configurations: (r, theta_v, light geometry in the local frame).

    Half the lights are aimed within 60 deg of the lobe's peak (the mirror direction for GGX,
    the normal for the other lobes), half anywhere above -15 deg elevation; distance
    1..4, quads 0.3..3 per side, disk radius 0.15..1.5, facing the point within 45 deg.
    """
    rng = np.random.default_rng(seed)
    out = []
    for i in range(count):
        r = rng.uniform(0.15, 0.95)
        theta = np.radians(rng.uniform(0.0, 80.0))
        v = np.array([np.sin(theta), 0.0, np.cos(theta)])
        if i % 2 == 0:
            peak = np.array([-v[0], 0.0, v[2]]) if lobe_name == "ggx" else np.array([0.0, 0.0, 1.0])
            a = rng.normal(size=3)
            a -= peak * (a @ peak)
            a /= np.linalg.norm(a)
            ang = np.radians(rng.uniform(0.0, 60.0))
            d = np.cos(ang) * peak + np.sin(ang) * a
        else:
            el, az = np.radians(rng.uniform(-15.0, 90.0)), rng.uniform(0.0, 2 * np.pi)
            d = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
        geom = light_facing_point(kind, rng, d, (1.0, 4.0), 45.0, (0.3, 3.0), (0.15, 1.5))
        out.append((r, theta, v, geom))
    return out


def true_integral(kind, f_cos, v, geom, panel_counts=(8, 32)):
    """Brute-force integral of ``f_cos`` over the light: (value, error estimate) at the first of ``panel_counts``
    whose estimate is within 1e-4 of the value (else the last)."""
    for panels in panel_counts:
        q = (reference.brdf_integral_polygon(f_cos, v, geom, panels=panels) if kind == "quad"
             else reference.brdf_integral_disk(f_cos, v, *geom, panels=panels))
        if q.error <= 1e-4 * max(abs(q.value), 1e-6):
            break
    return q.value, q.error


def _ltc_estimate(kind, inv_table, mag_table, sphere, r, mu, geom, use_fresnel=False, scale=1.0, band=None):
    u, w = lookup.ltc_lut_uv(np.array(mu), np.array(r))
    packed = semantics.sample_bilinear(inv_table, u, w)
    mag = semantics.sample_bilinear(mag_table, u, w)
    c = tuple(packed[..., i] for i in range(4))          # the shader path: packed Minv, traceable code

    def integral(c):
        if kind == "quad":
            return polygon.ltc_polygon_integral_packed(c, list(geom), False, sphere)
        return disk.ltc_disk_integral_packed(c, *geom, False, sphere)

    value = integral(c)
    if band is not None:                                 # the table's band (catalog.LTC_BANDS), weight in B
        value = shading.mix_band(value, integral(matrix.squash_packed(c, band["squash"])), mag[2])
    return float(value) * float(mag[1] if use_fresnel else mag[0]) * scale


def error_stats(est, truth, albedo, theta):
    est, truth, albedo, theta = map(np.asarray, (est, truth, albedo, theta))
    rel_sel = truth > 0.1 * albedo
    rel = np.abs(est - truth)[rel_sel] / truth[rel_sel]
    absn = np.abs(est - truth) / albedo
    if rel.size == 0:                # no light carries 10% of the albedo (a few lights, a grazing lobe)
        rel = np.array([np.nan])
    out = {"lights": int(truth.size), "lights_over_10pct": int(rel_sel.sum()),
           "rel_median": float(np.median(rel)), "rel_p90": float(np.quantile(rel, 0.9)), "rel_max": float(rel.max()),
           "abs_over_albedo_median": float(np.median(absn)), "abs_over_albedo_p90": float(np.quantile(absn, 0.9)),
           "abs_over_albedo_max": float(absn.max()), "by_view_angle": {}}
    deg = np.degrees(theta)
    for lo, hi in ((0, 30), (30, 60), (60, 81)):
        sel = (deg >= lo) & (deg < hi) & rel_sel
        if sel.any():
            r = np.abs(est - truth)[sel] / truth[sel]
            out["by_view_angle"][f"{lo}-{min(hi, 80)}"] = {"n": int(sel.sum()), "rel_median": float(np.median(r)),
                                                         "rel_p90": float(np.quantile(r, 0.9))}
    return out


def stats_by_roughness(rows_by_r, names):
    """``error_stats`` per estimate name: per roughness and pooled (every roughness's lights together), from
    ``rows_by_r[r] = {"truth", "albedo", "theta", name: estimates}``."""
    result = {}
    for name in names:
        per_r = {str(r): error_stats(rows[name], rows["truth"], rows["albedo"], rows["theta"])
                 for r, rows in rows_by_r.items()}
        pooled = [sum((list(rows[k]) for rows in rows_by_r.values()), []) for k in (name, "truth", "albedo", "theta")]
        result[name] = {"per_roughness": per_r, "pooled": error_stats(*pooled)}
    return result


def end_to_end(tables, published, n_quads, n_disks, seed=2019, prefixes=None):
    results = {}
    for prefix, (lobe_name, _) in catalog.LTC_LOBES.items():
        if prefixes is not None and prefix not in prefixes:
            continue
        lobe = lobes.LOBES[lobe_name]
        sphere = tables[prefix + "_mag"][..., 3]
        for kind, count in (("quad", n_quads), ("disk", n_disks)):
            rows = {"ours": [], "published": [], "truth": [], "albedo": [], "theta": [], "truth_err": []}
            for r, theta, v, geom in random_lights(kind, count, lobe_name, seed):
                mu = float(v[2])
                f_cos = (lambda l, vv, r=r: lobe.eval_cos(l, vv, np.array(r)))
                truth, err = true_integral(kind, f_cos, v, geom)
                albedo = float(fit.lobe_integrals(lobe, max(mu, fit.FIT_MU_MIN), np.array([r]), 1 << 12)[0][0])
                rows["truth"].append(truth)
                rows["truth_err"].append(err)
                rows["albedo"].append(albedo)
                rows["theta"].append(theta)
                rows["ours"].append(_ltc_estimate(kind, tables[prefix + "_inv"], tables[prefix + "_mag"], sphere,
                                                  r, mu, geom, band=catalog.LTC_BANDS.get(prefix)))
                if prefix == "ltc_ggx" and published is not None:
                    rows["published"].append(_ltc_estimate(kind, published[0], published[1], published[1][..., 3],
                                                           r, mu, geom))
            entry = {"ours": error_stats(rows["ours"], rows["truth"], rows["albedo"], rows["theta"]),
                     "reference_max_error_estimate": float(np.max(rows["truth_err"]))}
            if rows["published"]:
                entry["published"] = error_stats(rows["published"], rows["truth"], rows["albedo"], rows["theta"])
            results[f"{lobe_name}/{kind}"] = entry
    return results


def _disney_sheen_f_cos(l, vv):
    h = l + vv
    h /= np.linalg.norm(h, axis=-1, keepdims=True)
    return cloth.disney_sheen(np.sum(l * h, axis=-1)) * np.maximum(l[..., 2], 0.0)


def _cosine_albedo(f_cos, v, n=256):
    """int f cos over the hemisphere by cosine-weighted quadrature (n x n stratified points)."""
    u1, u2 = (a.ravel() for a in np.meshgrid((np.arange(n) + 0.5) / n, (np.arange(n) + 0.5) / n))
    z, rr = np.sqrt(1 - u1), np.sqrt(u1)
    l = np.stack([rr * np.cos(2 * np.pi * u2), rr * np.sin(2 * np.pi * u2), z], -1)
    return float(np.mean(f_cos(l, np.broadcast_to(v, l.shape)) / (z / np.pi)))


def sheen_via_diffuse_table(tables, n_quads, seed=2020):
    """Disney sheen (1 - l.h)^5 under quads: brute force vs the talk's CoD-table approximation."""
    est, truth, albedo, theta = [], [], [], []
    for r, th, v, geom in random_lights("quad", n_quads, "cod_diffuse", seed):
        t, _ = true_integral("quad", _disney_sheen_f_cos, v, geom)
        truth.append(t)
        albedo.append(_cosine_albedo(_disney_sheen_f_cos, v))
        theta.append(th)
        est.append(_ltc_estimate("quad", tables["ltc_cod_diffuse_inv"], tables["ltc_cod_diffuse_mag"],
                                 tables["ltc_cod_diffuse_mag"][..., 3], shading.SHEEN_TABLE_ROUGHNESS, float(v[2]),
                                 geom, use_fresnel=True, scale=np.pi))
    return error_stats(est, truth, albedo, theta)


def disney_sheen_models(tables, n_quads, n_disks, seed=2020):
    """Disney sheen under quads and disks: brute force vs the talk's CoD-table approximation ("talk") and vs
    its own fitted LTC ("fitted", table ltc_disney_sheen read at r = 0), on the same random lights."""
    out = {}
    for kind, count in (("quad", n_quads), ("disk", n_disks)):
        rows = {"talk": [], "fitted": [], "truth": [], "albedo": [], "theta": []}
        for r, th, v, geom in random_lights(kind, count, "cod_diffuse", seed):
            rows["truth"].append(true_integral(kind, _disney_sheen_f_cos, v, geom)[0])
            rows["albedo"].append(_cosine_albedo(_disney_sheen_f_cos, v))
            rows["theta"].append(th)
            mu = float(v[2])
            rows["talk"].append(_ltc_estimate(kind, tables["ltc_cod_diffuse_inv"], tables["ltc_cod_diffuse_mag"],
                                              tables["ltc_cod_diffuse_mag"][..., 3], shading.SHEEN_TABLE_ROUGHNESS,
                                              mu, geom, use_fresnel=True, scale=np.pi))
            rows["fitted"].append(_ltc_estimate(kind, tables["ltc_disney_sheen_inv"], tables["ltc_disney_sheen_mag"],
                                                tables["ltc_disney_sheen_mag"][..., 3], 0.0, mu, geom))
        out[kind] = {m: error_stats(rows[m], rows["truth"], rows["albedo"], rows["theta"]) for m in ("talk", "fitted")}
    return out


def zeltner_exactness(lut_dir, n_quads, n_disks, seed=2022):
    """The Zeltner sheen's area form vs brute force of the same lobe (the LTC density times the albedo at the
    same table values): the LTC integral with the sphere table's horizon ("sphere table") and with the exact
    horizon RT Lit shades it with ("exact horizon": quads clipped, disks by their closed form above the
    horizon and the clipped ellipse's boundary integral where they cross it).  Random sheen roughness in [0.05, 1]."""
    tables = lookup.LutSet.from_folder(lut_dir)
    sheen_table = tables.array("zeltner_sheen")
    sphere = tables.array("ltc_ggx_mag")[..., 3]
    out = {}
    for kind, count in (("quad", n_quads), ("disk", n_disks)):
        rows = {"sphere table": [], "exact horizon": [], "truth": [], "albedo": [], "theta": []}
        for r, th, v, geom in random_lights(kind, count, "cod_diffuse", seed):
            r = 0.05 + 0.95 * (r - 0.15) / 0.8
            mu = float(v[2])
            size = catalog.ZELTNER_SHEEN_SIZE
            a, b, alb = semantics.sample_bilinear(sheen_table, lookup.lut_coordinate(np.array(r), size),
                                                  lookup.lut_coordinate(np.array(mu), size))[:3]
            if alb < 1e-4:               # no lobe (Cycles' cut-off, or below it): nothing to integrate
                continue

            def f_cos(l, vv, a=float(a), b=float(b), alb=float(alb)):
                return alb * sheen.zeltner_density(l[..., 0], l[..., 1], l[..., 2], a, b)

            rows["truth"].append(true_integral(kind, f_cos, v, geom)[0])
            rows["albedo"].append(float(alb))
            rows["theta"].append(th)
            c = sheen.zeltner_packed_inverse(float(a), float(b))
            if kind == "quad":
                clipless = polygon.ltc_polygon_integral_packed(c, list(geom), False, sphere)
                exact = polygon.polygon_integral_horizon_clipped([matrix.transform_packed(c, q) for q in geom], 0.0,
                                                                 list(geom))
            else:
                clipless = disk.ltc_disk_integral_packed(c, *geom, False, sphere)
                exact = disk.disk_integral_horizon_clipped(*(matrix.transform_packed(c, q) for q in geom), 0.0, sphere)
            rows["sphere table"].append(float(clipless) * float(alb))
            rows["exact horizon"].append(float(exact) * float(alb))
        out[kind] = {m: error_stats(rows[m], rows["truth"], rows["albedo"], rows["theta"])
                     for m in ("sphere table", "exact horizon")}
    return out


def sheen_markdown(res):
    """The sheen sections of ltc.md (``disney_sheen_models`` and ``zeltner_exactness`` results)."""
    lines = ["## Sheen: Disney sheen's fitted LTC vs the talk's approximation, and Zeltner's own LTC", "",
             "Same random lights for both Disney sheen models (brute force of (1 - l.h)^5 cos over the light); "
             "Zeltner: the LTC integral of the measured lobe vs brute force of the same lobe (what the horizon "
             "handling costs).", "",
             "| lobe / light | model | n (>10%) | rel median | rel p90 | rel max | abs/albedo median | abs/albedo p90 |",
             "|---|---|---|---|---|---|---|---|"]
    for kind, e in res["disney_sheen_models"].items():
        for model in ("talk", "fitted"):
            lines.append(f"| disney_sheen/{kind} | {model} | {fmt_stats(e[model])}")
    for kind, e in res["zeltner_exactness"].items():
        for model, stats in e.items():
            lines.append(f"| zeltner/{kind} | own LTC, {model} | {fmt_stats(stats)}")
    return lines + [""]


def disk_exactness(tables, n, seed=7):
    """Disks above the transformed horizon: closed-form F.z vs numeric integration of the same LTC."""
    worst = 0.0
    count = 0
    for r, theta, v, geom in random_lights("disk", n, "ggx", seed):
        u, w = lookup.ltc_lut_uv(np.array(v[2]), np.array(r))
        minv = matrix.unpack_inverse(semantics.sample_bilinear(tables["ltc_ggx_inv"], u, w))
        centre, a, b = geom
        # entirely above the transformed horizon: every boundary point has (Minv x).z > 0
        ts = np.linspace(0, 2 * np.pi, 256)
        boundary = centre + np.cos(ts)[:, None] * a + np.sin(ts)[:, None] * b
        if np.min(boundary @ minv[2]) <= 0 or np.min(boundary[:, 2]) <= 0:
            continue
        closed = float(disk.ltc_disk_vector_form_factor(minv, centre, a, b)[2])
        numeric = reference.ltc_integral_disk(minv, centre, a, b, panels=16).value
        worst = max(worst, abs(closed / numeric - 1))
        count += 1
    return {"disks_above_horizon": count, "max_rel_diff_closed_form_vs_numeric": worst}


def fmt_stats(s):
    return (f"{s['lights_over_10pct']}/{s['lights']} | {100 * s['rel_median']:.2f}% | {100 * s['rel_p90']:.1f}% | "
            f"{100 * s['rel_max']:.1f}% | {100 * s['abs_over_albedo_median']:.2f}% | {100 * s['abs_over_albedo_p90']:.2f}% |")
