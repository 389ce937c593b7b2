"""The RT Lit World term (core/materials/world_shading.py) in numpy and traced.

- furnace: a uniform white environment with F0 = 1 gives 1 for every multiscattering model (and the
  split-sum albedo E for the single-scattering one);
- the prefiltered lookup equals core/environment/prefilter.sample_prefiltered (the bake's own reader);
- the world rotation: a Z-rotated environment equals the environment with Z-rotated SH, and the Euler
  XYZ matrix is Blender's Rz Ry Rx;
- the dielectric and metallic parts are shaded separately, then mixed (not one mixed F0);
- the diffuse models equal core/indirect.py's functions;
- traced graphs evaluate like the direct numpy code (float64 2e-6 as test_ltc_trace, float32 1e-4), with no NaN/Inf,
  and every node function stays under the group-size cap;
- world occlusion: the ambient occlusion scales the broad lobes, the specular occlusion of the chosen model the
  specular; AO = 1 changes nothing; the AO input exists only on occluded materials with a world.
"""
import math
from dataclasses import replace

import numpy as np
import pytest

from rt_lookdev.core import indirect, occlusion
from rt_lookdev.core.environment import prefilter, sh
from rt_lookdev.core.ir.numpy_backend import node_count
from rt_lookdev.core.lut import lookup
from rt_lookdev.core.materials import rt_lit
from rt_lookdev.core.materials import world_shading as world
from rt_lookdev.core.materials.rt_lit_interface import OCCLUSION_INPUT, RT_LIT_INPUTS, Features

LEVELS = tuple(k / 8.0 for k in range(9))
MAX_NODES = 144


TABLES = {}


@pytest.fixture(scope="module", autouse=True)
def _tables(lut_dir):
    TABLES["luts"] = lookup.LutSet.from_folder(lut_dir)
    yield
    TABLES.clear()


def _env_from_levels(levels, name):
    """A WorldEnvironment from (L, H, W, 3) top-first levels, stored as the bake stores them."""
    table = np.concatenate([np.flipud(lv) for lv in levels], axis=0)
    table = np.concatenate([table, np.ones(table.shape[:2] + (1,), np.float32)], axis=-1)
    return world.WorldEnvironment(name, table.astype(np.float32), LEVELS)


def _random_env(rng, h=8, w=16):
    return _env_from_levels(rng.uniform(0.1, 3.0, size=(len(LEVELS), h, w, 3)).astype(np.float32), "env_random")


def _unit(rng, n):
    d = rng.normal(size=(n, 3))
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def _geometry(rng, n=400):
    normals = _unit(rng, n)
    views = _unit(rng, n)
    views = np.where((np.sum(normals * views, -1) < 0)[:, None], -views, views)
    # edge cases: V = N, V in the tangent plane, V below
    normals[:3] = [0.0, 0.0, 1.0]
    views[:3] = [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 0.6, -0.8]]
    return normals, views


def _material(rng, n, **fixed):
    m = {}
    for name, sock in RT_LIT_INPUTS.items():
        if name == "Normal":
            m[name] = np.zeros(3)
        elif sock.kind == "float":
            lo, hi = (1.0, 2.5) if name == "IOR" else (0.0, 1.0)
            m[name] = rng.uniform(lo, hi, n)
        else:
            m[name] = rng.uniform(0.0, 1.0, (n, 3))
    m["Emission Strength"] = np.zeros(n)
    m.update(fixed)
    return m


def _random_case(seed, n):
    """(rng, a random environment, SH coefficients (a bright DC term), normals, views, material values) of ``n``
    shading points drawn in that order from ``seed``; ``rng`` continues after them."""
    rng = np.random.default_rng(seed)
    env = _random_env(rng)
    coeffs = rng.normal(size=(9, 3))
    coeffs[0] += 4.0
    normals, views = _geometry(rng, n)
    return rng, env, coeffs, normals, views, _material(rng, n)


def _params(coeffs, strength=1.0, rotation=(0.0, 0.0, 0.0)):
    p = {f"SH {i}": np.asarray(coeffs[i], np.float64) for i in range(9)}
    p["Strength"] = strength
    p["Rotation"] = np.asarray(rotation, np.float64)
    return p


def _radiance(features, env, params, m, normals, views):
    geo = {"Position": np.zeros(3), "Geometry Normal": normals, "Incoming": views}
    return rt_lit.rt_lit_radiance(TABLES["luts"], features, m, geo, [], world=(env, params))


ALL_FEATURES = [Features(s, d, sheen, cloth, form)
                for s, d, sheen, cloth, form in (("single", "lambert", False, False, "irradiance"),
                                                 ("turquin", "cod", False, False, "irradiance"),
                                                 ("fdez_aguera", "wrapped", True, False, "irradiance"),
                                                 ("fdez_aguera", "cod", False, True, "radiance"),
                                                 ("none", "wrapped", True, True, "irradiance"),
                                                 ("kulla_conty", "cod", True, True, "irradiance"),
                                                 ("turquin", "cod", "zeltner", False, "irradiance"),
                                                 ("none", "lambert", "disney_fitted", False, "irradiance"))]


def test_white_furnace_multiscattering_is_one():
    rng = np.random.default_rng(1)
    env = _env_from_levels(np.ones((len(LEVELS), 8, 16, 3), np.float32), "env_white")
    coeffs = np.zeros((9, 3))
    coeffs[0] = math.sqrt(4.0 * math.pi)          # L = 1: c_00 = int Y_00 = sqrt(4 pi)
    normals, views = _geometry(rng)
    for r in (0.0, 0.25, 0.5, 0.75, 1.0):
        m = _material(rng, len(normals), **{"Base Color": np.ones(3), "Metallic": 1.0, "Roughness": r,
                                           "Cloth Weight": 0.0, "Sheen Weight": 0.0})
        for spec in ("turquin", "fdez_aguera", "kulla_conty"):
            for form in ("irradiance", "radiance"):
                out = _radiance(Features(spec, "lambert", environment_ms=form), env, _params(coeffs), m,
                                normals, views)
                np.testing.assert_allclose(out, 1.0, atol=1e-9, err_msg=f"{spec} {form} r={r}")
        single = _radiance(Features("single", "lambert"), env, _params(coeffs), m, normals, views)
        mu = np.clip(np.sum(normals * views, -1), 0.0, 1.0)
        a, b = TABLES["luts"].split_sum(mu, r)
        np.testing.assert_allclose(single, np.repeat((a + b)[:, None], 3, 1), atol=1e-9)
        assert single.min() < 0.999 or r == 0.0     # single scattering loses energy


def test_prefiltered_lookup_matches_the_bake_reader():
    rng = np.random.default_rng(2)
    levels = rng.uniform(0.0, 5.0, size=(len(LEVELS), 8, 16, 3)).astype(np.float32)
    env = _env_from_levels(levels, "env_lookup")
    d = _unit(rng, 2000)
    d[:4] = [[0, 0, 1], [0, 0, -1], [-1, 1e-9, 0], [-1, -1e-9, 0]]      # poles and the u seam
    fn = world.prefiltered_function(env)
    for r in (0.0, 0.1, 0.125, 0.3, 0.999, 1.0):
        got = fn(Direction=d, Roughness=np.full(len(d), r))["Radiance"]
        want = prefilter.sample_prefiltered(levels, LEVELS, d, r)
        np.testing.assert_allclose(got, want, rtol=1e-5, atol=1e-6, err_msg=f"r = {r}")


def test_euler_rotation_is_blenders_rz_ry_rx():
    a, b, c = 0.3, -1.1, 2.0
    rx = np.array([[1, 0, 0], [0, math.cos(a), -math.sin(a)], [0, math.sin(a), math.cos(a)]])
    ry = np.array([[math.cos(b), 0, math.sin(b)], [0, 1, 0], [-math.sin(b), 0, math.cos(b)]])
    rz = np.array([[math.cos(c), -math.sin(c), 0], [math.sin(c), math.cos(c), 0], [0, 0, 1]])
    rows = world.euler_xyz_rows(np.array([a, b, c]))
    np.testing.assert_allclose(np.array(rows), rz @ ry @ rx, atol=1e-12)


def test_z_rotation_equals_rotated_sh():
    rng = np.random.default_rng(3)
    coeffs = rng.normal(size=(9, 3))
    normals, views = _geometry(rng, 200)
    m = _material(rng, len(normals), Metallic=0.0, **{"Cloth Weight": 0.0, "Sheen Weight": 0.0})
    white = _env_from_levels(np.ones((len(LEVELS), 4, 8, 3), np.float32), "env_white_small")
    angle = 0.7
    f = Features("single", "cod")
    rotated = _radiance(f, white, _params(coeffs, rotation=(0.0, 0.0, angle)), m, normals, views)
    # L(d) = image(R d): the world's coefficients are the image's rotated by -angle (sh_rotate_z's sense)
    world_coeffs = sh.sh_rotate_z(coeffs, angle)
    plain = _radiance(f, white, _params(world_coeffs), m, normals, views)
    np.testing.assert_allclose(rotated, plain, rtol=1e-9, atol=1e-9)


def test_strength_scales_linearly():
    rng = np.random.default_rng(4)
    env = _random_env(rng)
    coeffs = rng.normal(size=(9, 3))
    normals, views = _geometry(rng, 100)
    m = _material(rng, len(normals))
    f = ALL_FEATURES[-1]
    one = _radiance(f, env, _params(coeffs), m, normals, views)
    np.testing.assert_allclose(_radiance(f, env, _params(coeffs, strength=2.5), m, normals, views), 2.5 * one,
                               rtol=1e-12)


def test_dielectric_and_metal_are_shaded_separately():
    rng = np.random.default_rng(5)
    env = _random_env(rng)
    coeffs = rng.normal(size=(9, 3))
    normals, views = _geometry(rng, 200)
    for spec in ("turquin", "fdez_aguera", "kulla_conty"):
        f = Features(spec, "lambert")
        base = _material(rng, len(normals), **{"Cloth Weight": 0.0, "Sheen Weight": 0.0, "Roughness": 0.6})
        out = {}
        for metallic in (0.0, 0.5, 1.0):
            m = dict(base, Metallic=metallic)
            out[metallic] = _radiance(f, env, _params(coeffs), m, normals, views)
        # specular is linear in metallic after each part is shaded; the diffuse albedo is base (1 - m)
        np.testing.assert_allclose(out[0.5], 0.5 * (out[0.0] + out[1.0]), rtol=1e-9, atol=1e-12)

    # ... which differs from shading one mixed F0 (the bug this avoids): Turquin at metallic 0.5
    r = 0.8
    mu = np.clip(np.sum(normals * views, -1), 0.0, 1.0)
    a, b = TABLES["luts"].split_sum(mu, r)
    f0_d, f0_m = 0.04, 1.0
    channel = world._channel_specular("turquin", "irradiance")
    separate = 0.5 * channel(f0_d, a, b, 1.0, 1.0, 0.0) + 0.5 * channel(f0_m, a, b, 1.0, 1.0, 0.0)
    mixed = channel(0.5 * (f0_d + f0_m), a, b, 1.0, 1.0, 0.0)
    assert np.max(np.abs(mixed / separate - 1.0)) > 0.1


def test_diffuse_models_equal_core_indirect():
    rng = np.random.default_rng(6)
    env = _random_env(rng)
    coeffs = rng.normal(size=(9, 3))
    coeffs[0] += 5.0
    normals, views = _geometry(rng, 300)
    n = len(normals)
    m = _material(rng, n, **{"Metallic": 0.0, "Cloth Weight": np.ones(n), "Cloth Color": np.zeros(3),
                             "Sheen Weight": 0.0, "Roughness": 0.4, "Wrap": 0.3})
    albedo = np.asarray(m["Base Color"])
    tables = TABLES["luts"]
    want = {"lambert": indirect.sh_lambert(list(coeffs), normals, albedo),
            "wrapped": indirect.sh_wrapped_diffuse(list(coeffs), normals, albedo, 0.3),
            "cod": indirect.sh_cod_diffuse(tables, list(coeffs), normals, views, 0.4, albedo)}
    for diffuse, expected in want.items():
        got = _radiance(Features("single", diffuse, cloth=True), env, _params(coeffs), m, normals, views)
        np.testing.assert_allclose(got, expected, rtol=1e-9, atol=1e-12, err_msg=diffuse)


def _function_values(material, m, normals, views, params):
    """The material function's inputs: the material values ``m``, the geometry and the world's ``params``."""
    n = len(normals)
    inputs = dict(m, Position=np.zeros((n, 3)), **{"Geometry Normal": normals, "Incoming": views})
    inputs.update({material.world_inputs[k]: (np.broadcast_to(v, (n, 3)) if np.ndim(v) else np.full(n, v))
                   for k, v in params.items()})
    inputs["Normal"] = np.zeros((n, 3))
    return inputs


@pytest.mark.parametrize("features", ALL_FEATURES, ids=lambda f: f.label())
def test_traced_world_equals_numpy(features):
    rng, env, coeffs, normals, views, m = _random_case(7, 300)
    n = len(normals)
    params = _params(coeffs, 1.7, (0.2, -0.4, 1.3))
    want = _radiance(features, env, params, m, normals, views)
    material = rt_lit.build_rt_lit(features, (), env)          # the whole material as the node groups get it
    inputs = _function_values(material, m, normals, views, params)
    got64 = material.evaluate(inputs, TABLES["luts"], np.float64)["Radiance"]
    np.testing.assert_allclose(got64, want, rtol=2e-6, atol=1e-9)   # as test_ltc_trace (float32 tables)
    got32 = material.evaluate(inputs, TABLES["luts"], np.float32)["Radiance"]
    assert np.all(np.isfinite(got32))
    np.testing.assert_allclose(got32, want, rtol=1e-4, atol=1e-5)


def test_world_functions_are_small():
    rng = np.random.default_rng(8)
    env = _random_env(rng)
    fns = [world.prefiltered_function(env), world.WORLD_ROTATION, world.SH_LOBE, world.SH_LTC_COD,
           world.SH_LTC_CLOTH, world.SH_LTC_SHEEN, world.SH_LTC_ZELTNER, world.SH_LTC_DISNEY_FITTED, world.SH_MOMENTS]
    fns += [world.specular_function(s, form) for s in ("single", "turquin", "fdez_aguera", "kulla_conty")
            for form in ("irradiance", "radiance")]
    fns += [world.shade_world_function(f, env) for f in ALL_FEATURES]
    fns += [world.shade_world_function(replace(f, occlusion=model), env) for f in ALL_FEATURES[-3:]
            for model in ("lagarde", "cones", "cones_clipped")]
    for fn in fns:
        count = node_count(tuple(fn.function.outputs.values()))
        assert count <= MAX_NODES, (fn.name, count)


def test_environment_validation():
    with pytest.raises(ValueError):
        world.WorldEnvironment("bad", np.zeros((10, 4, 4), np.float32), LEVELS)
    with pytest.raises(ValueError):
        world.WorldEnvironment("bad", np.zeros((9, 4, 4), np.float32), (0.0, 0.3, 1.0))
    with pytest.raises(ValueError):
        Features(environment_ms="both")


# --- world occlusion (Features.occlusion; issue 29) -----------------------------------------------------------------

OCCLUDED = ("lagarde", "cones", "cones_clipped")


def _occluded_radiance(features, env, params, m, normals, views, ao):
    geo = {"Position": np.zeros(3), "Geometry Normal": normals, "Incoming": views, OCCLUSION_INPUT: ao}
    return rt_lit.rt_lit_radiance(TABLES["luts"], features, m, geo, [], world=(env, params))


@pytest.mark.parametrize("model", OCCLUDED)
def test_occlusion_scales_the_diffuse_by_ao_and_the_specular_by_its_specular_occlusion(model):
    """world(AO) = AO x (the world without specular) + SO(N.V, AO, r) x (the specular part), SO from core/occlusion.py:
    the diffuse and the specular each take their own factor, nothing else changes."""
    rng, env, coeffs, normals, views, m = _random_case(11, 300)
    n = len(normals)
    params = _params(coeffs, 1.3, (0.3, 0.1, -0.7))
    ao = rng.uniform(0.0, 1.0, n)
    base = Features("turquin", "cod")
    everything = _radiance(base, env, params, m, normals, views)
    diffuse = _radiance(replace(base, specular="none"), env, params, m, normals, views)
    n_dot_v = np.clip(np.sum(normals * views, -1), 0.0, 1.0)
    so = occlusion.SPECULAR_OCCLUSION[model](n_dot_v, ao, m["Roughness"])
    want = ao[:, None] * diffuse + so[:, None] * (everything - diffuse)
    got = _occluded_radiance(replace(base, occlusion=model), env, params, m, normals, views, ao)
    np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-12)
    assert np.all(got <= everything + 1e-9)


@pytest.mark.parametrize("model", ("lagarde", "cones_clipped"))
def test_occlusion_at_ao_one_changes_nothing(model):
    """AO = 1 (nothing around the point): the occluded world equals the unoccluded one for the models that keep the
    whole lobe then (plain cones darken lobes reaching under the horizon: docs/benchmarks/specular_occlusion.md)."""
    rng, env, coeffs, normals, views, m = _random_case(12, 200)
    params = _params(coeffs)
    features = Features("fdez_aguera", "cod", "zeltner", True)
    want = _radiance(features, env, params, m, normals, views)
    got = _occluded_radiance(replace(features, occlusion=model), env, params, m, normals, views, np.ones(len(normals)))
    np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-14)


@pytest.mark.parametrize("features", [Features("turquin", "cod", occlusion="cones_clipped"),
                                      Features("kulla_conty", "oren_nayar", "zeltner", True, occlusion="lagarde")],
                         ids=lambda f: f.label())
def test_traced_occluded_world_equals_numpy(features):
    """The material function has the AO input exactly when the world is shaded and occluded, and evaluates like
    the direct numpy code (as test_traced_world_equals_numpy), float32 included."""
    rng, env, coeffs, normals, views, m = _random_case(13, 300)
    n = len(normals)
    params = _params(coeffs, 0.8, (0.2, -0.4, 1.3))
    ao = rng.uniform(0.0, 1.0, n)
    ao[:2] = (0.0, 1.0)
    want = _occluded_radiance(features, env, params, m, normals, views, ao)
    material = rt_lit.build_rt_lit(features, (), env)
    assert material.occlusion_inputs == (OCCLUSION_INPUT,) and OCCLUSION_INPUT in material.internal_inputs
    assert rt_lit.build_rt_lit(features, ("point",), None).occlusion_inputs == ()     # no world: nothing occluded
    inputs = _function_values(material, m, normals, views, params)
    with pytest.raises(KeyError):
        material.evaluate(inputs, TABLES["luts"], np.float64)
    inputs[OCCLUSION_INPUT] = ao
    np.testing.assert_allclose(material.evaluate(inputs, TABLES["luts"], np.float64)["Radiance"], want,
                               rtol=2e-6, atol=1e-9)
    got32 = material.evaluate(inputs, TABLES["luts"], np.float32)["Radiance"]
    assert np.all(np.isfinite(got32))
    np.testing.assert_allclose(got32, want, rtol=1e-4, atol=1e-5)


def test_occlusion_switch_validates_and_names_the_group():
    with pytest.raises(ValueError, match="occlusion"):
        Features(occlusion="ssao")
    assert Features(occlusion="cones_clipped").label() == "turquin, cod, cones-clipped AO"
    assert Features.from_dict({"specular": "single"}).occlusion == "none"      # materials stored before the switch


@pytest.mark.parametrize("rotation", [(0.0, 0.0, 0.0), (0.2, -0.4, 1.3)])
def test_world_irradiance_output_is_the_sh_cosine_lobe_about_the_rotated_normal(rotation):
    """The World shadows' denominator (``build_rt_lit(world_irradiance=True)``, addon/shadows.py): E_SH(N) / pi x
    Strength (Ramamoorthi & Hanrahan 2001's cosine lobe, the world's rotation applied to the normal as its diffuse
    does), in float64 and float32; the radiance is the same as without the extra output."""
    rng, env, coeffs, normals, views, m = _random_case(11, 200)
    params = _params(coeffs, 1.7, rotation)
    rows = [np.asarray(r, np.float64) for r in world.euler_xyz_rows(np.asarray(rotation, np.float64))]
    rotated = np.stack([normals @ r for r in rows], -1)
    want = 1.7 * indirect.sh_cosine_lobe_eval(coeffs, rotated)
    material = rt_lit.build_rt_lit(Features(), (), env, world_irradiance=True)
    inputs = _function_values(material, m, normals, views, params)
    both = ("Radiance", rt_lit.WORLD_IRRADIANCE_OUTPUT)
    out = material.evaluate(inputs, TABLES["luts"], np.float64, outputs=both)
    # rtol 1e-6: at the grazing views of _geometry's edge cases the shading normal (core/materials/surface.py) is
    # the geometric one moved by its guard, by ~1e-7
    np.testing.assert_allclose(out[rt_lit.WORLD_IRRADIANCE_OUTPUT], want, rtol=1e-6, atol=1e-12)
    plain = rt_lit.build_rt_lit(Features(), (), env)
    np.testing.assert_array_equal(out["Radiance"], plain.evaluate(inputs, TABLES["luts"], np.float64)["Radiance"])
    out32 = material.evaluate(inputs, TABLES["luts"], np.float32, outputs=both)[rt_lit.WORLD_IRRADIANCE_OUTPUT]
    assert out32.dtype == np.float32
    np.testing.assert_allclose(out32, want, rtol=1e-5, atol=1e-5)
