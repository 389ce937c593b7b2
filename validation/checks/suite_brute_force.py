"""(c) by brute force: the true BRDF integrated over each light with a Gauss-Legendre rule, clipped at the
shading point's horizon, at seeded pixels of a case's passes."""
from __future__ import annotations

import functools
import time

import numpy as np

from .suite_scene import numpy_material, scene_light_params
from ...core import lights as core_lights
from ...core.ltc import reference
from ...core.materials import light_shading
from ...core.materials.rt_lit_interface import RT_LIT_INPUTS
from ...core.materials.surface import SURFACE


# --- (c) brute-force ground truth -------------------------------------------------------------

def _area_geometry(kind, params, position=None):
    """The light's true emitter, as Cycles samples it, for the brute-force integral: geometry and radiance without
    its options' falloff (``core.lights.control_factor``) and without the spread (its weight is taken per direction:
    ``_direction_weight``); a sphere light's or a sun's disk facing ``position``, a spot sphere's without its cone
    (taken per direction too)."""
    base = core_lights.base_kind(kind)
    data = core_lights.LIGHT_DATA["sphere" if base == "spot_sphere" else base]
    args = {k: np.float64(v) for k, v in params.items() if k in data.input_sockets}
    if "Position" in data.input_sockets:
        args["Position"] = np.asarray(position, np.float64)
    out = {k: np.asarray(v, np.float64) for k, v in data(**args).items()}
    if "p0" in out:
        return {"corners": np.stack([out[f"p{i}"] for i in range(4)]), "radiance": out["Radiance"]}
    return {"center": out["Center"], "u": out["Axis U"], "v": out["Axis V"], "radiance": out["Radiance"]}


def _direction_weight(kind, params, position, dirs, light_normal):
    """What Cycles multiplies the radiance of each direction ``dirs`` (from ``position`` towards the light) by: the
    spread's weight (kernel/light/area.h ``area_light_spread_attenuation``, core/light_spread.py) and a spot
    sphere's cone attenuation of the direction (kernel/light/spot.h); 1 for the other lights."""
    from ...core import light_spread, lights as core_lights

    base, options = core_lights.split_kind(kind)
    weight = np.ones(len(dirs))
    if "spread" in options:
        h = float(np.clip(params["Spread"] * 0.5, light_spread.MIN_HALF_SPREAD, light_spread.MAX_HALF_SPREAD))
        if params["Spread"] < np.pi - 1e-6:
            cos_a = np.clip(dirs @ light_normal, 1e-12, 1.0)
            tan_a = np.sqrt(np.maximum(1.0 - cos_a * cos_a, 0.0)) / cos_a
            weight *= np.maximum(1.0 - tan_a / np.tan(h), 0.0) * np.tan(h) / (np.tan(h) - h)
    if base == "spot_sphere":
        loc = np.array([params["Location X"], params["Location Y"], params["Location Z"]])
        if np.sum((loc - position) ** 2) > params["Radius"] ** 2:
            c = core_lights.spot_cosine(position, position + dirs, *(params[f"Rotation {a}"] for a in "WXYZ"),
                                        *(params[f"Scale {a}"] for a in "XYZ"), params["Determinant"])
            weight *= core_lights.spot_attenuation(c, params["Spot Size"], params["Spot Blend"])
    return weight


def quadrature_rule(kind, geo, p, clip_normal, panels, order):
    """Points relative to p (M, 3), area weights (M,), unit light normal, or None if unlit."""
    if kind == "quad":
        rel = geo["corners"] - p
        normal = reference.newell_normal(rel)
        if rel[0] @ normal < 0.0:
            return None
        x, w = reference.polygon_rule(rel, clip_normal, panels, order)
    else:
        c = geo["center"] - p
        normal = np.cross(geo["u"], geo["v"])
        if c @ normal < 0.0:
            return None
        x, w = reference.disk_rule(c, geo["u"], geo["v"], clip_normal, panels, order)
    return x, w, normal / np.linalg.norm(normal)


def _surface(features, material, n, v):
    return SURFACE(**{k: material[k] for k in RT_LIT_INPUTS}, **{"Geometry Normal": n, "Incoming": v})


def brute_force_radiance(case, scene, passes, index, pixel_cap, rng, tables, panels=8, order=8, only=None,
                         chunk=24):
    """(c) for the brute-force variants on at most ``pixel_cap`` seeded pixels per sphere.

    Returns (image with NaN where not computed, quadrature error estimate image, seconds per
    variant).  The error estimate is |I(panels) - I(panels / 2)| (reference._converged's check).
    Pixels are evaluated in chunks: the rule's points of ``chunk`` pixels go through one call of
    the shading function (numpy, float64; ``tables`` the LUT set the punctual GGX reads E from)."""
    from ..harness.engines import camera_incoming

    import bpy

    pos = passes["Position"].astype(np.float64)
    nrm = passes["Normal"].astype(np.float64)
    img = np.full(pos.shape, np.nan)
    qerr = np.full(pos.shape, np.nan)
    seconds = {}
    levels = (panels, max(panels // 2, 1))
    for i, variant in enumerate(case.variants):
        if (only is None and variant.truth != "brute") or (only is not None and i not in only):
            continue
        t0 = time.perf_counter()
        ys, xs = np.nonzero(index == i)
        if len(ys) > pixel_cap:
            pick = np.sort(rng.choice(len(ys), pixel_cap, replace=False))
            ys, xs = ys[pick], xs[pick]
        features = variant.features
        material = numpy_material(variant)
        lights = scene_light_params(scene, bpy.data.objects.get(f"RTL_val_sphere_{i}"))
        shade = functools.partial(light_shading.shade_function("sun", features), tables)
        unclipped = features.diffuse in ("wrapped", "cod_wrapped")
        P = pos[ys, xs]
        N = nrm[ys, xs] / np.linalg.norm(nrm[ys, xs], axis=-1, keepdims=True)
        V = camera_incoming(scene, P)
        surface = _surface(features, material, N, V)
        sums = np.zeros((len(levels), len(ys), 3))
        for kind, params in lights:
            form = core_lights.shading_form(kind)
            if form in ("quad", "disk"):
                facing = "Position" in core_lights.LIGHT_DATA[core_lights.base_kind(kind)].input_sockets
                geo = None if facing else _area_geometry(kind, params)
                # the options' falloff is constant over the light for one shading point
                control = np.broadcast_to(np.asarray(core_lights.control_factor(
                    kind, P, {k: np.float64(v) for k, v in params.items()}), np.float64), (len(ys),))
                for lev, level in enumerate(levels):
                    for start in range(0, len(ys), chunk):
                        owner, dirs, irr = [], [], []
                        for k in range(start, min(start + chunk, len(ys))):
                            light = _area_geometry(kind, params, P[k]) if facing else geo
                            rule = quadrature_rule(form, light, P[k], None if unclipped else N[k], level, order)
                            if rule is None or len(rule[1]) == 0:
                                continue
                            xr, w, ln = rule
                            r = np.linalg.norm(xr, axis=-1)
                            unit = xr / r[:, None]
                            weight = _direction_weight(kind, params, P[k], unit, ln)
                            owner.append(np.full(len(w), k))
                            dirs.append(unit)
                            irr.append((w * weight * np.abs(xr @ ln) / r ** 3)[:, None] * light["radiance"] * control[k])
                        if owner:
                            owner = np.concatenate(owner)
                            rad = _shade(shade, surface, owner, np.concatenate(dirs), np.concatenate(irr))
                            for ch in range(3):
                                sums[lev, :, ch] += np.bincount(owner, rad[:, ch], minlength=len(ys))
            else:
                # punctual: the true BRDF at the one light direction (no integral)
                args = {k: np.full(len(ys), v, np.float64) for k, v in params.items()}
                if "Position" in core_lights.light_data(kind).input_sockets:
                    args["Position"] = P
                light = core_lights.light_data(kind)(**args)
                L = np.broadcast_to(np.asarray(light["L"], np.float64), P.shape)
                E = np.broadcast_to(np.asarray(light["Irradiance"], np.float64), P.shape)
                sums += _shade(shade, surface, np.arange(len(ys)), L, E)[None]
        img[ys, xs] = sums[0]
        qerr[ys, xs] = np.abs(sums[0] - sums[1])
        seconds[i] = time.perf_counter() - t0
    return img, qerr, seconds


def _shade(shade, surface, owner, l, irradiance):
    """The material's punctual shading (radiance, (M, 3)) for directions l (M, 3) with irradiance
    (M, 3); surface values per pixel, ``owner`` the pixel of each direction."""
    kw = {}
    for name in shade.func.input_sockets:
        if name == "L":
            kw[name] = l
        elif name == "Irradiance":
            kw[name] = irradiance
        elif name == "Position":
            kw[name] = np.zeros(l.shape)
        else:
            val = np.asarray(surface[name], np.float64)
            if val.ndim == 0:
                kw[name] = np.full(len(owner), float(val))
            elif val.ndim == 1 and val.shape[0] == 3 and name not in ("N", "V"):
                kw[name] = np.broadcast_to(val, l.shape)
            else:
                kw[name] = val[owner]
    return np.asarray(shade(**kw)["Radiance"], np.float64).reshape(-1, 3)
