"""Input grids of the conformance checks, shared by the tests of every backend (numpy, node groups, GLSL).

No bpy here: ``ir_operation_graph`` with ``ir_operation_inputs`` (every IR operation once, on a grid with
exact zeros, +-1e-7, integers, zero vectors and out-of-domain values), ``TECHNIQUES`` with ``technique_inputs`` (every technique's function and its argument grid,
with zeros, 1e-7 and the domain's edges), ``punctual_lobe_inputs`` and ``area_lobe_inputs`` (the lobes'
per-texel inputs: edge cases, grazing and below-horizon views, lights below, in the plane of, or tiny),
``shade_inputs`` (one light on the material), ``surface_inputs`` (the RT Lit surface), ``world_inputs`` and
``random_environment`` (the World term's functions).
"""
from __future__ import annotations

import numpy as np

from ...core import cloth, diffuse, falloff, fresnel, microfacet, multiscatter, rough_diffuse
from ...core.conventions import alpha_from_roughness
from ...core import lights
from ...core.environment import equirect
from ...core.ir import Graph
from ...core.ir.expr import OPS, topological_order
from ...core.materials.rt_lit_interface import OCCLUSION_INPUT

#: Side of the square per-texel grids (one render pixel per texel).
SIZE = 48
#: Below this |reference|, backends are compared by absolute error (relative above).
NEAR_ZERO = 1e-2


def max_deviation(got, ref, near_zero=NEAR_ZERO):
    """How far a backend's values are from a reference: (max relative error where |ref| >= near_zero,
    max absolute error elsewhere); 0 for an empty part."""
    got, ref = np.asarray(got, np.float64), np.asarray(ref, np.float64)
    err = np.abs(got - ref)
    big = np.abs(ref) >= near_zero
    rel = float((err[big] / np.abs(ref[big])).max()) if big.any() else 0.0
    absolute = float(err[~big].max()) if (~big).any() else 0.0
    return rel, absolute


def unit_vectors(rng, shape, special=()):
    v = rng.normal(size=shape + (3,))
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    flat = v.reshape(-1, 3)
    for i, s in enumerate(special):
        flat[i] = s
    return v.astype(np.float32)


def _ggx(mu_l, mu_v, n_dot_h, v_dot_h, r, f0):
    return microfacet.ggx_brdf(mu_l, mu_v, n_dot_h, v_dot_h, alpha_from_roughness(r), f0)


#: Every shading technique as (function, argument names): the IR evaluated by the numpy backend must equal
#: the direct numpy evaluation (tests/core/test_ir.py), and the node group the numpy backend
#: (tests/blender/test_node_conformance.py).
TECHNIQUES = {
    "ggx_brdf": (_ggx, ["mu_l", "mu_v", "n_dot_h", "v_dot_h", "r", "f0"]),
    "fresnel_average": (lambda f0: fresnel.fresnel_average(f0), ["f0"]),
    "kulla_conty_brdf": (multiscatter.kulla_conty_brdf, ["one_minus_e_o", "one_minus_e_i", "one_minus_e_avg", "f0"]),
    "turquin": (multiscatter.turquin_compensation, ["f0", "e_v"]),
    "fdez_aguera": (multiscatter.fdez_aguera_env_brdf, ["f0", "scale", "bias"]),
    "fdez_aguera_area": (multiscatter.fdez_aguera_area_scale, ["f0", "e"]),
    "cod_diffuse": (lambda mu_l, mu_v, n_dot_h, l_dot_h, r: diffuse.cod_multiscatter_diffuse(
        0.8, mu_l, mu_v, n_dot_h, l_dot_h, alpha_from_roughness(r)), ["mu_l", "mu_v", "n_dot_h", "l_dot_h", "r"]),
    "wrapped_diffuse": (diffuse.wrapped_diffuse_cosine, ["mu_l", "wrap"]),
    "cloth": (lambda mu_l, mu_v, n_dot_h, r: cloth.ashikhmin_cloth_brdf(mu_l, mu_v, n_dot_h, alpha_from_roughness(r)),
              ["mu_l", "mu_v", "n_dot_h", "r"]),
    "disney_sheen": (cloth.disney_sheen, ["l_dot_h"]),
    "window_falloff": (falloff.window_falloff, ["distance", "radius"]),
    "inverse_square": (lambda distance: falloff.inverse_square_falloff(distance), ["distance"]),
    "cone_falloff": (falloff.cone_falloff, ["cos_to_axis", "inner_angle", "outer_angle"]),
    "projector_distance": (falloff.projector_distance, ["diameter", "outer_angle"]),
}
#: The rough diffuse (core/rough_diffuse.py): single scattering (Fujii) and the multiple-scattering lobe (EON).
TECHNIQUES["oren_nayar_single"] = (rough_diffuse.fon_single_scatter_cos, ["mu_l", "mu_v", "l_dot_v", "r"])
TECHNIQUES["oren_nayar_multi"] = (rough_diffuse.multiscatter_cos, ["mu_l", "mu_v", "r"])


def _diffuse_roughness(rng, shape):
    """Diffuse roughness per texel, with 0, 1e-3 and 1 in the first texels."""
    sigma = rng.random(shape).astype(np.float32)
    sigma.reshape(-1)[:6] = [0.0, 1.0, 1e-3, 1.0, 0.5, 0.0]
    return sigma


def technique_inputs(names, n=4000, seed=0):
    rng = np.random.default_rng(seed)
    extremes = np.array([0.0, 1e-7, 1e-4, 0.5, 1.0 - 1e-7, 1.0])
    vals = {}
    for i, name in enumerate(names):
        # cosines also below the horizon; every other parameter in its domain [0, 1]
        cosine = name.startswith(("mu", "n_dot", "v_dot", "l_dot", "cos"))
        x = rng.uniform(-0.1 if cosine else 0.0, 1.0, n)
        x[: extremes.size * 2] = np.concatenate([extremes, np.roll(extremes, i + 1)])
        if name in ("distance", "radius", "diameter"):
            x = np.abs(x) * 5
        if name in ("inner_angle", "outer_angle"):
            x = np.abs(x) * 3.0
        if name == "one_minus_e_avg":    # the table's range: 1.3e-5 (r = 0) .. 0.59 (r = 1)
            x = np.clip(x, 1e-5, 0.6)
        vals[name] = x
    return vals


def punctual_lobe_inputs(seed=3, size=SIZE):
    """Per-texel N, V, L, roughness and wrap for the punctual lobes, edge cases in the first texels."""
    rng = np.random.default_rng(seed)
    shape = (size, size)
    z = [0.0, 0.0, 1.0]
    n = unit_vectors(rng, shape, special=[z] * 8)
    v = unit_vectors(rng, shape, special=[z, z, [1, 0, 0], [0, 0, -1], z, [0.6, 0, 0.8], z, z])
    l = unit_vectors(rng, shape, special=[z, [0, 0, -1], z, z, [1, 0, 0], [-0.6, 0, 0.8], [0, 0, -1], z])
    # view above the normal in most texels (the material sees front faces), some below
    flip = np.einsum("...i,...i->...", n, v) < 0
    v[flip[..., None].repeat(3, -1) & (rng.random(shape) < 0.8)[..., None].repeat(3, -1)] *= -1
    r = rng.random(shape).astype(np.float32)
    r.reshape(-1)[:8] = [0.0, 1.0, 0.0, 1.0, 0.5, 0.0, 1e-3, 1.0]
    wrap = rng.random(shape).astype(np.float32)
    wrap.reshape(-1)[:3] = [0.0, 1.0, 1.0]
    return {"N": n, "V": v, "L": l, "Roughness": r, "Wrap": wrap, "Diffuse Roughness": _diffuse_roughness(rng, shape),
            "Sheen Roughness": sheen_roughness(rng, shape)}


def sheen_roughness(rng, shape):
    """Sheen roughness per texel: Cycles' floor 1e-3 and the ends of the range first, then random."""
    r = rng.random(shape).astype(np.float32)
    r.reshape(-1)[:6] = [0.0, 1e-3, 1.0, 0.5, 2e-3, 1.0 / 31.0]
    return r


def area_lobe_inputs(kind, seed=5, size=SIZE):
    """Shading points on the unit sphere seen from outside; lights of many sizes, tilts and
    positions, some below the horizon, in the tangent plane, or degenerate.  ``kind`` "quad" or "disk", or either
    with "+spread": the light's spread 0.5-180 deg (a few at 180, where it changes nothing), the geometry its data
    function hands the lobes (``core.lights.spread_geometry``)."""
    base, options = lights.split_kind(kind)
    rng = np.random.default_rng(seed)
    shape = (size, size)
    count = size * size
    n = unit_vectors(rng, shape).reshape(-1, 3)
    p = n.copy()
    v = n + rng.normal(size=(count, 3)) * 0.6
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    center = p + rng.normal(size=(count, 3)) * 2.0
    center[:8] = p[:8] + n[:8] * np.array([2.0, -1.0, 0.0, 1e-3, 5.0, 0.5, 1.0, 2.0])[:, None]   # above, below,
    u = rng.normal(size=(count, 3)) * rng.uniform(0.01, 1.5, (count, 1))                        # in plane, ...
    w = rng.normal(size=(count, 3))
    w -= u * (np.sum(u * w, -1) / np.maximum(np.sum(u * u, -1), 1e-12))[:, None]
    w *= rng.uniform(0.01, 1.5, (count, 1)) / np.maximum(np.linalg.norm(w, axis=-1, keepdims=True), 1e-12)
    u[8], w[8] = 0.0, 0.0                        # degenerate: zero size
    u[9], w[9] = [1e-4, 0, 0], [0, 1e-4, 0]      # tiny
    r = rng.random(count)
    r[:6] = [0.0, 1.0, 0.0, 1.0, 0.5, 1e-3]
    vals = {"Position": p, "N": n, "V": v, "Roughness": r, "Wrap": rng.random(count),
            "Sheen Roughness": sheen_roughness(rng, (count,))}
    vals["Diffuse Roughness"] = _diffuse_roughness(rng, count)
    if base == "quad":
        corners = [center - u - w, center + u - w, center + u + w, center - u + w]
        light = {f"p{i}": c for i, c in enumerate(corners)}
        light["Center"] = center
    else:
        light = {"Center": center, "Axis U": u, "Axis V": w}
    if "spread" in options:
        spread = np.radians(rng.uniform(0.5, 180.0, count))
        spread[10:14] = np.pi
        light = dict(lights.spread_geometry(base, dict(light, Radiance=np.ones((count, 3))), p, spread))
        light.pop("Radiance")
    vals.update(light)
    return {k: np.asarray(a, np.float32).reshape(shape + np.shape(a)[1:]) for k, a in vals.items()}


def ir_operation_inputs(size=64):
    """size x size grid: a in [-3, 3] x b in [-2, 2] with exact zeros, integers and domain edges; random
    vectors u, v with zero vectors in the first texels (normalize(0) = 0)."""
    a = np.linspace(-3.0, 3.0, size, dtype=np.float32)
    b = np.linspace(-2.0, 2.0, size, dtype=np.float32)
    a[:8] = [0.0, -0.0, 1.0, -1.0, 2.0, 0.5, 1e-7, -1e-7]
    b[:8] = [0.0, 2.0, -1.0, 3.0, 0.5, -0.5, 1.0, 1e-7]
    A, B = np.meshgrid(a, b, indexing="xy")
    rng = np.random.default_rng(7)
    u = rng.normal(size=(size, size, 3)).astype(np.float32)
    v = rng.normal(size=(size, size, 3)).astype(np.float32)
    u[0, :4] = 0.0
    return {"a": A, "b": B, "u": u, "v": v}


def ir_operation_graph():
    """One output per IR operation (every entry of ``expr.OPS`` but the table reads), inputs a, b (float)
    and u, v (vector): {output name -> Expr}."""
    g = Graph()
    a, b, u, v = g.input("a"), g.input("b"), g.input("u", "vector"), g.input("v", "vector")
    binary = ("add", "subtract", "multiply", "divide", "power", "minimum", "maximum", "less_than", "greater_than",
              "arctan2")
    unary = ("sqrt", "inverse_sqrt", "exponent", "log2", "absolute", "floor", "arccosine", "arcsine", "sine",
             "cosine", "tangent")
    outputs = {op: g.make(op, (a, b)) for op in binary}
    outputs.update({op: g.make(op, (a,)) for op in unary})
    cond = g.make("greater_than", (a, b))
    outputs["select"] = g.make("select", (cond, a, g.make("multiply", (b, b))))
    outputs["vselect"] = g.make("vselect", (cond, u, v))
    outputs["combine"] = g.make("combine", (a, b, g.make("multiply", (a, b))))
    for c in "xyz":
        outputs[c] = g.make(c, (u,))
    outputs.update({op: g.make(op, (u, v)) for op in ("vadd", "vsubtract", "vmultiply", "dot", "cross")})
    outputs["vscale"] = g.make("vscale", (u, a))
    outputs["length"] = g.make("length", (u,))
    outputs["normalize"] = g.make("normalize", (u,))
    outputs["const_arg"] = g.make("power", (g.const(2.0), a))          # a constant on a socket
    outputs["vconst_arg"] = g.make("cross", (g.vconst((0.0, 0.0, 1.0)), u))
    covered = {n.op for n in topological_order(list(outputs.values()))}
    missing = set(OPS) - covered - {"lut", "texel"}
    if missing:
        raise AssertionError(f"operations not covered: {sorted(missing)}")
    return outputs


def technique_function_inputs(seed=12, size=SIZE):
    """Per-texel inputs of the stand-alone technique node functions (multiple-scattering scales, falloffs)."""
    rng = np.random.default_rng(seed)
    shape = (size, size)
    vals = {"F0": rng.random(shape + (3,)), "E": rng.uniform(0.0, 1.0, shape), "N.V": rng.random(shape),
            "Roughness": rng.random(shape), "Distance": rng.uniform(0.0, 3.0, shape),
            "Radius": rng.uniform(-0.5, 3.0, shape), "Cos To Axis": rng.uniform(-1, 1, shape),
            "Inner Angle": rng.uniform(0, 3, shape), "Outer Angle": rng.uniform(0, 3, shape),
            "Diameter": rng.uniform(0, 2, shape)}
    vals["E"].reshape(-1)[:3] = [0.0, 1.0, 1e-3]
    return {k: np.asarray(v, np.float32) for k, v in vals.items()}


def shade_inputs(kind, seed=9, size=SIZE):
    """Per-texel inputs of ``RTL Shade <kind>``: the area-lobe geometry plus random colours, weights, light
    radiance / irradiance and a unit light direction L."""
    rng = np.random.default_rng(seed)
    shape = (size, size)
    vals = dict(area_lobe_inputs("disk" if kind == "disk" else "quad", size=size))
    vals.update({"F0": rng.random(shape + (3,)), "Albedo": rng.random(shape + (3,)),
                 "Sheen Color": rng.random(shape + (3,)), "Cloth Color": rng.random(shape + (3,)),
                 "Cloth Weight": rng.random(shape), "Radiance": rng.random(shape + (3,)) * 10,
                 "Irradiance": rng.random(shape + (3,)) * 10, "L": unit_vectors(rng, shape)})
    # the split specular models' inputs (light_shading.SPLIT_F0_MODELS), drawn after the others so they keep
    # their values
    vals.update({"Dielectric F0": rng.random(shape + (3,)) * 0.1, "Metal F0": rng.random(shape + (3,)),
                 "Metallic": rng.random(shape)})
    return {k: np.asarray(v, np.float32) for k, v in vals.items()}


def surface_inputs(names, seed=2, size=SIZE):
    """Per-texel inputs of "RTL Surface" (``names``: its input sockets, name -> Socket): factors beyond
    [0, 1], IOR below 1, unnormalised vectors, and a zero Normal in the first row (the geometry's)."""
    rng = np.random.default_rng(seed)
    shape = (size, size)
    vals = {}
    for name, sock in names.items():
        vals[name] = rng.uniform(-0.2, 1.2, shape) if sock.kind == "float" else rng.normal(size=shape + (3,))
    vals["IOR"] = rng.uniform(0.5, 3.0, shape)
    vals["Normal"][:8] = 0.0
    return {k: np.asarray(v, np.float32) for k, v in vals.items()}


#: Roughness of the levels of ``random_environment``.
ENVIRONMENT_LEVELS = tuple(k / 8.0 for k in range(9))


def random_environment(seed=11, height=16, width=32):
    """A prefiltered-environment table of random radiance (9 levels of height x width, alpha 1): (L H, W, 4)."""
    rng = np.random.default_rng(seed)
    table = rng.uniform(0.05, 4.0, size=(len(ENVIRONMENT_LEVELS) * height, width, 4)).astype(np.float32)
    table[..., 3] = 1.0
    return table


def smooth_environment(height=16, width=32):
    """A prefiltered-environment table that varies slowly with direction (as real prefiltered levels do):
    (L H, W, 4), rows in Blender order (row 0 at the bottom), alpha 1.  Unlike ``random_environment``, a
    one-ulp difference in the direction-to-texel mapping (arccosine, atan2) moves its lookups by about
    one ulp, not by the contrast between two random texels."""
    d = equirect.texel_directions(height, width)                       # top row first
    levels = [np.stack([1.5 + d[..., 0] * (1.0 - k / 10), 1.2 + 0.5 * d[..., 2], 1.0 + 0.3 * d[..., 1]], -1)
              for k in range(len(ENVIRONMENT_LEVELS))]
    table = np.concatenate([np.flipud(lv) for lv in levels], 0)
    return np.concatenate([table, np.ones(table.shape[:2] + (1,))], -1).astype(np.float32)


def world_inputs(seed=5, size=SIZE):
    """Per-texel inputs of every World-term function: directions over the whole sphere with the poles and
    the equirect seam, roughness 0 and 1 and between levels, V below the horizon, rotations, SH."""
    rng = np.random.default_rng(seed)
    shape = (size, size)
    z = [0.0, 0.0, 1.0]
    n = unit_vectors(rng, shape, special=[z, [0, 0, -1], [-1, 1e-7, 0], [-1, -1e-7, 0], z, z, [1, 0, 0], z])
    v = unit_vectors(rng, shape, special=[z, z, z, z, [1, 0, 0], [0, 0.6, -0.8], z, [0.6, 0, 0.8]])
    flip = np.einsum("...i,...i->...", n, v) < 0
    v[flip & (rng.random(shape) < 0.8)] *= -1
    r = rng.random(shape).astype(np.float32)
    r.reshape(-1)[:8] = [0.0, 1.0, 0.125, 0.5, 1e-3, 0.999, 0.0, 1.0]
    vals = {"N": n, "V": v, "Direction": unit_vectors(rng, shape, special=[z, [0, 0, -1], [-1, 1e-7, 0],
                                                                             [-1, -1e-7, 0]]),
            "Axis": unit_vectors(rng, shape), "Roughness": r,
            "Lambda 1": rng.uniform(0.3, 0.7, shape), "Lambda 2": rng.uniform(0.0, 0.25, shape),
            "Rotation": rng.uniform(-3.5, 3.5, shape + (3,)),
            "F0": rng.random(shape + (3,)), "Scale": rng.uniform(0.0, 1.0, shape),
            "Bias": rng.uniform(0.0, 0.2, shape), "Prefiltered": rng.random(shape + (3,)) * 5,
            "Irradiance": rng.random(shape + (3,)) * 5,
            "Dielectric F0": rng.uniform(0.0, 0.1, shape + (3,)), "Metal F0": rng.random(shape + (3,)),
            "Metallic": rng.random(shape), "Albedo": rng.random(shape + (3,)), "Wrap": rng.random(shape),
            "Sheen Color": rng.random(shape + (3,)), "Cloth Weight": rng.random(shape),
            "Cloth Color": rng.random(shape + (3,)), "World Strength": rng.uniform(0.1, 3.0, shape),
            "World Rotation": rng.uniform(-3.5, 3.5, shape + (3,))}
    vals["Sheen Roughness"] = sheen_roughness(rng, shape)
    vals.update(distribution_moments(rng, shape))
    vals["Scale"] = vals["Scale"] * (1.0 - vals["Bias"])
    coeffs = rng.normal(size=(9, 3))
    coeffs[0] += 4.0
    for i in range(9):
        vals[f"SH {i}"] = np.broadcast_to(coeffs[i], shape + (3,)).copy()
        vals[f"World SH {i}"] = vals[f"SH {i}"]
    vals["Diffuse Roughness"] = _diffuse_roughness(rng, shape)
    vals[OCCLUSION_INPUT] = ambient_occlusion(np.random.default_rng(seed + 1), shape)
    return {k: np.asarray(a, np.float32) for k, a in vals.items()}


def ambient_occlusion(rng, shape):
    """The renderer's AO over its whole range, both ends (0: nothing visible, 1: nothing occluded) included."""
    ao = rng.uniform(0.0, 1.0, shape)
    ao.reshape(-1)[:4] = (0.0, 1.0, 1e-6, 1.0 - 1e-6)
    return ao


def distribution_moments(rng, shape, k=6):
    """First and second moments ("Mean", "XX", "YY", "ZZ", "XY", "YZ", "XZ") of random distributions of unit
    directions (each the average of ``k`` random unit vectors): what ``world_shading.SH_MOMENTS`` takes."""
    d = unit_vectors(rng, shape + (k,))
    out = {"Mean": d.mean(axis=-2)}
    for name, (i, j) in (("XX", (0, 0)), ("YY", (1, 1)), ("ZZ", (2, 2)), ("XY", (0, 1)), ("YZ", (1, 2)),
                         ("XZ", (0, 2))):
        out[name] = (d[..., i] * d[..., j]).mean(axis=-1)
    return out


def ltc_integral_inputs(ltc_table, size=SIZE, seed=13):
    """Per-texel inputs of the LTC integral functions: the packed inverse matrix (c0..c3) of random texels
    of ``ltc_table`` (an (H, W, 4) LTC matrix table), the light relative to the shading point (the
    area-lobe grids' quads and disks), one- and two-sided."""
    rng = np.random.default_rng(seed)
    shape = (size, size)
    h, w = ltc_table.shape[:2]
    texels = ltc_table[rng.integers(0, h, shape), rng.integers(0, w, shape)]
    vals = {f"c{i}": texels[..., i] for i in range(4)}
    quad, disk = area_lobe_inputs("quad", size=size), area_lobe_inputs("disk", size=size)
    vals.update({f"p{i}": quad[f"p{i}"] - quad["Position"] for i in range(4)})
    vals.update({"Center": disk["Center"] - disk["Position"], "Axis U": disk["Axis U"], "Axis V": disk["Axis V"],
                 "Two Sided": (rng.random(shape) < 0.3).astype(np.float32)})
    return {k: np.asarray(v, np.float32) for k, v in vals.items()}


def light_data_inputs(function, size=SIZE, seed=17):
    """Per-texel driver values of a light-data function (core/lights.py): locations, unit and non-unit
    quaternions, negative and zero scales, powers, colours, sizes (zero included), cone angles, positions."""
    rng = np.random.default_rng(seed)
    shape = (size, size)
    vals = {}
    for name in function.input_sockets:
        if name == "Position":
            vals[name] = rng.normal(size=shape + (3,)) * 2.0
        elif name.startswith("Location"):
            vals[name] = rng.normal(size=shape) * 3.0
        elif name.startswith("Rotation"):
            vals[name] = rng.normal(size=shape)
        elif name.startswith("Scale"):
            vals[name] = rng.uniform(-2.0, 2.0, shape)
        elif name == "Spot Size":
            vals[name] = rng.uniform(0.0, np.pi, shape)
        elif name in ("Spot Blend",) or name.startswith("Color"):
            vals[name] = rng.random(shape)
        elif name in ("Cone Inner", "Cone Outer"):           # the light controls (core/lights.py light_data)
            vals[name] = rng.uniform(0.0, np.pi, shape)
            vals[name].reshape(-1)[:2] = (0.0, np.pi)
        elif name == "Range":
            vals[name] = rng.uniform(0.0, 8.0, shape)
            vals[name].reshape(-1)[:1] = 0.0
        else:                                  # Power, Strength, Size, Size Y
            vals[name] = rng.uniform(0.0, 5.0, shape) * (100.0 if name == "Power" else 1.0)
        if name in ("Size", "Size Y", "Power", "Scale X"):
            vals[name].reshape(-1)[:2] = 0.0
    return {k: np.asarray(v, np.float32) for k, v in vals.items()}


def material_inputs(material, size=SIZE, seed=21):
    """Per-texel inputs of a whole RT Lit material (``core.materials.rt_lit.RtLitMaterial``): surface
    inputs, points on the unit sphere seen from outside, every light's driver values, the world's."""
    rng = np.random.default_rng(seed)
    shape = (size, size)
    vals = surface_inputs({n: s for n, s in material.function.sockets[0].items() if n in material.material_inputs},
                          size=size, seed=seed)
    n = unit_vectors(rng, shape)
    vals.update({"Position": n, "Geometry Normal": n + rng.normal(size=shape + (3,)) * 0.01,
                 "Incoming": unit_vectors(rng, shape)})
    flip = np.einsum("...i,...i->...", n, vals["Incoming"]) < 0
    vals["Incoming"][flip & (rng.random(shape) < 0.9)] *= -1
    for kind, names in zip(material.light_kinds, material.light_inputs):
        drivers = light_data_inputs(lights.light_data(kind), size=size, seed=int(rng.integers(1 << 30)))
        for param, name in names.items():
            value = drivers[param]
            if param.startswith("Location"):          # lights outside the unit sphere
                value = value + np.float32(3.0) * np.sign(value)
            vals[name] = value
    world = world_inputs(size=size, seed=int(rng.integers(1 << 30)))
    for param, name in material.world_inputs.items():
        vals[name] = world[name] if name in world else world[param]
    for name in material.occlusion_inputs:
        vals[name] = ambient_occlusion(rng, shape)
    return {k: np.asarray(v, np.float32) for k, v in vals.items()}
