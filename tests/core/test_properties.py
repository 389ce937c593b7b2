"""Property-based tests (Hypothesis, fixed seed, bounded examples) of the techniques and the whole RT Lit
material, and the named regression examples of what the robustness campaign found (docs/robustness.md).

Properties: finite; non-negative; at most the light under an area light on a white surface (the white
furnace); reciprocal where the BRDF is; continuous at the light's horizon; the direct numpy evaluation and
the IR's agree.  The long sweeps are scripts/robustness_sweep.py, not tests.
"""
import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from rt_lookdev.core import cloth, diffuse, microfacet
from rt_lookdev.core.conventions import alpha_from_roughness
from rt_lookdev.core.materials import rt_lit
from rt_lookdev.core.materials.rt_lit_interface import RADIANCE_OUTPUT, Features
from rt_lookdev.validation.checks import robustness, robustness_inputs

#: Fixed seed (derandomize) and a bounded number of examples: the suite stays fast and repeatable.
PROPERTIES = settings(max_examples=40, derandomize=True, deadline=None, database=None,
                      suppress_health_check=[HealthCheck.too_slow])

EDGE_COSINES = [0.0, 1e-7, -1e-7, 1.0, 1.0 - 1e-7, -1.0]
roughness = st.one_of(st.sampled_from([0.0, 1.0, 1e-7, 1.0 - 1e-7]), st.floats(0.0, 1.0))


@st.composite
def directions(draw):
    """Unit vectors, with the horizon, the pole and +-1e-7 elevations drawn often."""
    z = draw(st.one_of(st.sampled_from(EDGE_COSINES), st.floats(-1.0, 1.0)))
    phi = draw(st.floats(0.0, 2.0 * np.pi))
    s = np.sqrt(max(0.0, 1.0 - z * z))
    return np.array([s * np.cos(phi), s * np.sin(phi), z])


def _cosines(l, v):
    h = l + v
    h = h / np.linalg.norm(h) if np.linalg.norm(h) > 0 else h
    return l[2], v[2], h[2], float(np.clip(v @ h, 0.0, 1.0))


BRDFS = {
    "ggx": lambda mu_l, mu_v, nh, vh, r: microfacet.ggx_brdf(mu_l, mu_v, nh, vh, alpha_from_roughness(r)),
    "cod": lambda mu_l, mu_v, nh, vh, r: diffuse.cod_multiscatter_diffuse(1.0, mu_l, mu_v, nh, vh,
                                                                         alpha_from_roughness(r)),
    "cloth": lambda mu_l, mu_v, nh, vh, r: cloth.ashikhmin_cloth_brdf(mu_l, mu_v, nh, alpha_from_roughness(r)),
}


@pytest.mark.parametrize("name", sorted(BRDFS))
@PROPERTIES
@given(l=directions(), v=directions(), r=roughness, dtype=st.sampled_from([np.float32, np.float64]))
def test_brdfs_finite_non_negative_reciprocal(name, l, v, r, dtype):
    f = BRDFS[name]
    args = [dtype(x) for x in _cosines(l, v)] + [dtype(r)]
    back = [dtype(x) for x in _cosines(v, l)] + [dtype(r)]
    with np.errstate(all="ignore"):
        a, b = np.float64(f(*args)), np.float64(f(*back))
    assert np.isfinite(a) and a >= 0.0
    assert np.isclose(a, b, rtol=1e-4 if dtype == np.float32 else 1e-9, atol=1e-30), (a, b)


def test_cod_diffuse_never_negative():
    """Regression: Chan's retro-reflection quadratic is negative for gloss 0.71 < g < 1 (r ~ 0.05-0.13);
    with light and view grazing from the same side the BRDF went negative."""
    r = np.linspace(0.0, 0.2, 201)[:, None]
    mu = np.array([1e-4, 1e-3, 1e-2, 0.05])[None, :]
    f = diffuse.cod_multiscatter_diffuse(1.0, mu, mu, mu, 1.0, alpha_from_roughness(r))   # l = v: h = l
    assert f.min() >= 0.0
    assert diffuse.retro_reflection_scale(np.array([0.5, 0.71, 0.85, 1.0])).min() >= 0.0


# --- the whole material ---------------------------------------------------------------------------------

@PROPERTIES
@given(family=st.sampled_from(robustness.FAMILIES), kind=st.sampled_from(robustness.LIGHT_KINDS),
       seed=st.integers(0, 2 ** 16))
def test_material_finite_non_negative_bounded(tables, family, kind, seed):
    """The RT Lit material at scene-like and adversarial points (validation/checks/robustness.py's draw)."""
    values, unit, material = robustness.scene_inputs(family, kind, 256, seed)
    got = robustness.evaluate_numpy(material, values, tables, np.float32)
    ref = robustness.evaluate_numpy(material, values, tables, np.float64)
    c = robustness.count(family, kind, "numpy float32", got, ref, unit, values, material)
    assert got.dtype == np.float32
    assert c.failures == 0, c


@PROPERTIES
@given(name=st.sampled_from(["Base Color", "Metallic", "Roughness", "IOR", "Specular IOR Level", "Specular Tint",
                             "Wrap", "Sheen Weight", "Sheen Tint", "Cloth Weight", "Cloth Color",
                             "Emission Color", "Emission Strength", "Normal"]),
       special=st.sampled_from([np.nan, np.inf, -np.inf, 1e30, -1e30, 1e-45, -1.0, 0.0]),
       kind=st.sampled_from(robustness.LIGHT_KINDS))
@example(name="Roughness", special=np.nan, kind="quad")
@example(name="Base Color", special=-1.0, kind="disk")
@example(name="Emission Strength", special=np.inf, kind="sun")
@example(name="Normal", special=np.inf, kind="point")       # regression: NaN under point and sun lights
@example(name="Normal", special=-np.inf, kind="sun")
def test_nan_and_inf_inputs_finite(tables, name, special, kind):
    """Regression: a NaN or infinite material input (a texture, a driver) reached the pixel."""
    family = robustness.FAMILIES[-1]
    values, unit, material = robustness.scene_inputs(family, kind, 64, 5)
    values[name] = np.full_like(values[name], special)
    with np.errstate(all="ignore"):
        got = robustness.evaluate_numpy(material, values, tables, np.float32)
    assert np.isfinite(got).all() and got.min() >= 0.0


def test_negative_and_huge_colours(tables):
    """Regression: colours outside [0, 1] gave negative radiance or more than the white furnace."""
    family = robustness.FAMILIES[4]                    # Lambert alone, white: at most the light
    values, unit, material = robustness.scene_inputs(family, "quad", 512, 9)
    for colour in (-2.0, 5.0):
        values["Base Color"] = np.full_like(values["Base Color"], colour)
        got = robustness.evaluate_numpy(material, values, tables, np.float32)
        c = robustness.count(family, "quad", "numpy float32", got, got, unit, values, material)
        assert c.negative == 0 and c.over_bound == 0, (colour, c)


def test_denormal_normal_falls_back(tables):
    """Regression: |Normal| ~ 1e-40 used an arbitrary direction in float64 and the geometry's in float32."""
    family = robustness.FAMILIES[4]
    values, unit, material = robustness.scene_inputs(family, "sun", 64, 3)
    values["Normal"] = np.full_like(values["Normal"], 1e-40)
    a = robustness.evaluate_numpy(material, values, tables, np.float32)
    values["Normal"] = np.zeros_like(values["Normal"])
    b = robustness.evaluate_numpy(material, values, tables, np.float64)
    assert np.allclose(a, b, rtol=1e-4, atol=1e-6 * np.abs(b).max())


def _aimed_light(kind, location, target, size, power):
    """Driver values of one light at ``location`` aimed at ``target``."""
    q = robustness_inputs._facing(None, np.asarray([location], float), np.asarray([target], float), 1)[0]
    vals = {"Location X": location[0], "Location Y": location[1], "Location Z": location[2], "Rotation W": q[0],
            "Rotation X": q[1], "Rotation Y": q[2], "Rotation Z": q[3], "Scale X": 1.0, "Scale Y": 1.0,
            "Scale Z": 1.0, "Power": power, "Color R": 1.0, "Color G": 1.0, "Color B": 1.0, "Size": size,
            "Size Y": size, "Spot Size": np.pi, "Spot Blend": 0.0, "Strength": 1.0, "Exposure": 0.0, "Normalize": 1.0,
            "Determinant": 1.0}
    return {p: vals[p] for p in rt_lit.light_parameters(kind)}


def _point_values(material_values, view):
    """Inputs of one shading point at the origin, normal +Z, viewed from ``view``: the defaults, then
    ``material_values``."""
    values = {n: np.asarray(s.default if s.kind == "float" else s.default[:3], np.float32)
              for n, s in rt_lit.RT_LIT_INPUTS.items()}
    values.update({k: np.asarray(v, np.float32) for k, v in material_values.items()})
    values.update({"Normal": np.zeros(3, np.float32), "Position": np.zeros(3, np.float32),
                   "Geometry Normal": np.array([0, 0, 1], np.float32), "Incoming": np.asarray(view, np.float32)})
    return values


def _radiance_over_light(tables, features, material_values, kind, location, size, view):
    material = rt_lit.build_rt_lit(features, (kind,))
    values = _point_values(material_values, view)
    power = 100.0
    for p, v in _aimed_light(kind, location, (0.0, 0.0, 0.0), size, power).items():
        values[material.light_inputs[0][p]] = np.asarray(v, np.float32)
    area = size * size * (1.0 if kind == "quad" else np.pi / 4.0)
    radiance = material.evaluate(values, tables)[RADIANCE_OUTPUT]
    return np.asarray(radiance, np.float64).max() / (power / (np.pi * area))


@pytest.mark.parametrize("kind", ["quad", "disk"])
@pytest.mark.parametrize("r", [0.0, 0.005, 0.02])
def test_kulla_conty_area_bounded(tables, kind, r):
    """Regression: a near-mirror white metal under a light whose centre sits near its horizon returned
    about 20x the light (f_ms at the centre's mu times the whole form factor)."""
    white_metal = {"Metallic": 1.0, "Base Color": np.ones(3), "Roughness": r}
    view = (np.sin(1.2), 0.0, np.cos(1.2))
    for elevation in (1e-3, 0.02, 0.1):
        location = (3.0 * np.cos(elevation), 0.0, 3.0 * np.sin(elevation))
        ratio = _radiance_over_light(tables, Features("kulla_conty", "lambert"), white_metal, kind, location, 2.0,
                                     view)
        assert ratio <= 1.0 + robustness.BOUND_TOLERANCE, (elevation, ratio)


@pytest.mark.parametrize("kind", ["quad", "disk"])
def test_grazing_mirror_furnace(tables, kind):
    """Regression: GGX (LTC magnitude 0.99) + Kulla-Conty (1 - E from the energy table, 0.39) reached 1.39
    of a large light at a grazing view of a near-mirror."""
    white_metal = {"Metallic": 1.0, "Base Color": np.ones(3), "Roughness": 1e-6}
    view = (np.sqrt(1.0 - 1e-16), 0.0, 1e-8)
    for location in ((-0.5, 0.0, 0.3), (0.0, 0.0, 0.2), (-0.3, 0.2, -0.2)):
        ratio = _radiance_over_light(tables, Features("kulla_conty", "lambert"), white_metal, kind, location, 50.0,
                                     view)
        assert ratio <= 1.0 + robustness.BOUND_TOLERANCE, (location, ratio)


@pytest.mark.parametrize("kind", ["quad", "disk"])
def test_cod_area_furnace(tables, kind):
    """Regression: Chan's CoD fit reflects up to 1.14 of the light at r = 1 and grazing views (its own albedo
    exceeds 1); under area lights the LTC magnitude is bounded by 1."""
    diffuse_alone = {"Metallic": 0.0, "Base Color": np.ones(3), "Roughness": 1.0, "Cloth Weight": 1.0,
                     "Cloth Color": np.zeros(3)}
    view = (np.sqrt(1.0 - 1e-4), 0.0, 1e-2)
    ratio = _radiance_over_light(tables, Features("single", "cod", cloth=True), diffuse_alone, kind,
                                 (0.0, 0.0, 1.0), 200.0, view)
    assert 0.9 < ratio <= 1.0 + robustness.BOUND_TOLERANCE


def test_huge_light_just_above_is_not_edge_on(tables):
    """Regression: a quad 10^4 m wide 1 cm above the point (form factor ~1) counted as seen edge-on and gave 0:
    the side test took corner p0, 7 km away, instead of the light's centre."""
    white = {"Metallic": 0.0, "Base Color": np.ones(3), "Cloth Weight": 1.0, "Cloth Color": np.zeros(3)}
    ratio = _radiance_over_light(tables, Features("single", "lambert", cloth=True), white, "quad",
                                 (0.0, 0.0, 0.01), 1e4, (0.0, 0.0, 1.0))
    assert ratio > 0.99


@PROPERTIES
@given(r=roughness, kind=st.sampled_from(["point", "sun", "quad"]))
def test_continuous_at_the_light_horizon(tables, r, kind):
    """A light sinking through the receiver's plane fades out: no jump at the horizon."""
    family = robustness.FAMILIES[9]                    # dielectric, Lambert + GGX
    white = {"Metallic": 0.0, "Base Color": np.ones(3), "Roughness": r}
    view = (0.6, 0.0, 0.8)
    values = []
    for elevation in (1e-4, 0.0, -1e-4):
        location = (-3.0 * np.cos(elevation), 0.0, 3.0 * np.sin(elevation))
        if kind == "quad":
            values.append(_radiance_over_light(tables, family.features, white, kind, location, 0.01, view))
        else:
            values.append(_punctual_response(tables, family.features, white, kind, location, view))
    assert max(values) <= 1e-2, values


def _punctual_response(tables, features, material_values, kind, location, view):
    material = rt_lit.build_rt_lit(features, (kind,))
    values = _point_values(material_values, view)
    params = _aimed_light(kind, location, (0.0, 0.0, 0.0), 0.0, 100.0)
    for p, name in material.light_inputs[0].items():
        values[name] = np.asarray(params[p], np.float32)
    radiance = np.asarray(material.evaluate(values, tables)[RADIANCE_OUTPUT], np.float64).max()
    unit = 1.0 if kind == "sun" else 100.0 / (4.0 * np.pi * 9.0)
    return radiance / unit


@PROPERTIES
@given(family=st.sampled_from(robustness.FAMILIES), kind=st.sampled_from(robustness.LIGHT_KINDS),
       seed=st.integers(0, 2 ** 16))
def test_direct_numpy_and_ir_agree(tables, family, kind, seed):
    """The material evaluated directly on arrays (core/materials/rt_lit.py rt_lit_radiance) and through the
    traced IR (the numpy backend) give the same radiance."""
    values, _, material = robustness.scene_inputs(family, kind, 128, seed)
    values = {k: v.astype(np.float64) for k, v in values.items()}
    via_ir = robustness.evaluate_numpy(material, values, tables, np.float64)
    names = material.light_inputs[0]
    with np.errstate(all="ignore"):
        direct = rt_lit.rt_lit_radiance(
            tables, family.features, {k: values[k] for k in rt_lit.RT_LIT_INPUTS},
            {k: values[k] for k in ("Position", "Geometry Normal", "Incoming")},
            [(kind, {p: values[n] for p, n in names.items()})])
    direct = np.broadcast_to(np.asarray(direct, np.float64), via_ir.shape)
    # The IR stores its constants as float32 (as Blender's sockets do), the direct path keeps float64 ones: a
    # 6e-8 relative change of a constant, times the condition number of the point (up to ~1e3 for near-mirror
    # lobes under lights a few micrometres wide), so 1e-6 almost everywhere and 1e-3 at every point.
    atol = 1e-12 * np.abs(via_ir).max()
    close = np.isclose(direct, via_ir, rtol=1e-6, atol=atol).all(-1)
    assert close.mean() >= 0.99, (close.mean(), np.where(~close)[0][:5])
    assert np.allclose(direct, via_ir, rtol=1e-3, atol=atol)


def test_nan_lookup_gives_a_value(tables):
    """Regression: a NaN texture coordinate raised IndexError for the whole vectorised batch."""
    r = np.array([0.5, np.nan, 0.2])
    mu = np.array([np.nan, 0.5, 0.3])
    out = tables.one_minus_e(mu, r)
    assert out.shape == (3,) and np.isfinite(out).all()


def test_sweep_script_writes_its_report(tmp_path):
    """The README's `python scripts/robustness_sweep.py` (numpy only, a few points): report, JSON, 0 failures."""
    import json
    import subprocess
    import sys
    from pathlib import Path

    repo = Path(__file__).resolve().parents[2]
    out = tmp_path / "robustness.md"
    run = subprocess.run([sys.executable, str(repo / "scripts" / "robustness_sweep.py"), "--points", "200",
                          "--backends", "numpy", "--out", str(out)], capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stdout + run.stderr
    result = json.loads(out.with_suffix(".json").read_text())
    assert result["failures"] == 0 and "| Kulla-Conty multiple scattering |" in out.read_text()
    assert sum(c["points"] for c in result["counts"]) == 200 * len(robustness.LIGHT_KINDS) * len(robustness.FAMILIES) + 200


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_large_disk_just_above_is_fully_lit(dtype):
    """Regression: a disk 10^5 m wide 10 um above the point returned about half its light in float32 (the cone
    axis lost the centre against the semi-axes); its form factor is ~1, with the axis straight up."""
    from rt_lookdev.core.ltc import disk

    for radius, height, offset in ((1e5, 1e-5, 0.0), (5e4, 1e-5, 3e-6), (1e3, 1e-4, 0.0)):
        c = np.array([offset, 0.0, height], dtype)
        u, v = np.array([radius, 0.0, 0.0], dtype), np.array([0.0, radius, 0.0], dtype)
        with np.errstate(over="raise", invalid="raise", divide="raise", under="ignore"):
            got = disk.ltc_disk_integral(np.eye(3, dtype=dtype), c, u, v)
        exact = radius ** 2 / (radius ** 2 + height ** 2 + offset ** 2)
        assert abs(float(got) - exact) < 1e-6, (radius, height, float(got))


@pytest.mark.parametrize("kind", ["quad", "disk"])
def test_light_centred_on_the_point_is_edge_on(tables, kind):
    """Regression: a light whose centre is the shading point lies in its plane there (the point touches it):
    it gives 0, as every other point of the plane does, in float32 and float64 alike."""
    values = _point_values({"Metallic": 0.0, "Base Color": np.ones(3), "Roughness": 0.4}, (0.0, 0.6, 0.8))
    material = rt_lit.build_rt_lit(Features("turquin", "lambert"), (kind,))
    q = np.array([np.cos(0.3), np.sin(0.3), 0.0, 0.0])            # tilted, centred on the point
    light = {"Location X": 0.0, "Location Y": 0.0, "Location Z": 0.0, "Rotation W": q[0], "Rotation X": q[1],
             "Rotation Y": q[2], "Rotation Z": q[3], "Scale X": 1.0, "Scale Y": 1.0, "Scale Z": 1.0, "Power": 10.0,
             "Color R": 1.0, "Color G": 1.0, "Color B": 1.0, "Size": 2e-6, "Size Y": 1e-7, "Exposure": 0.0,
                 "Normalize": 1.0, "Determinant": 1.0}
    for p, name in material.light_inputs[0].items():
        values[name] = np.asarray(light[p], np.float32)
    for dtype in (np.float32, np.float64):
        radiance = material.evaluate({k: v.astype(dtype) for k, v in values.items()}, tables, dtype=dtype)
        assert np.all(np.asarray(radiance[RADIANCE_OUTPUT]) == 0.0), dtype
