"""The Zeltner sheen (core/sheen.py) in its three forms, the sheen models' switch and Principled's layering.

Cheap numpy checks (~1 s): the punctual form is the LTC density times the albedo (integrates to the albedo);
the area form is that lobe's integral over the light (brute force, quads and disks, exact horizon); the world
form is its exact integral against an L2 SH radiance at table nodes; stored switches keep their meaning.
"""
from __future__ import annotations

import numpy as np
import pytest

from rt_lookdev.core import indirect, sheen
from rt_lookdev.core.lut.lookup import LutSet
from rt_lookdev.core.ltc import polygon, reference, shading
from rt_lookdev.core.materials import light_shading, lobes
from rt_lookdev.core.materials import world_shading as world
from rt_lookdev.core.materials.rt_lit_interface import Features


@pytest.fixture(scope="module")
def tables():
    return LutSet.from_folder()


def _view(mu):
    return np.array([np.sqrt(1.0 - mu * mu), 0.0, mu])


@pytest.mark.parametrize("mu, r", [(0.1, 0.2), (0.5, 0.5), (0.9, 0.9), (0.3, 1.0)])
def test_punctual_lobe_integrates_to_its_albedo(tables, mu, r):
    local, w = indirect.hemisphere_quadrature(256, 512)
    n, v = np.array([0.0, 0.0, 1.0]), _view(mu)
    out = lobes.ZELTNER.function("sun")(tables, N=np.broadcast_to(n, local.shape), V=np.broadcast_to(v, local.shape),
                                        L=local, **{"Sheen Roughness": np.full(len(local), r)})
    assert np.allclose(out["Sheen Albedo"], out["Sheen Albedo"][0])
    assert np.sum(out["Sheen"] * w) == pytest.approx(out["Sheen Albedo"][0], rel=2e-3)


def test_area_form_is_the_lobes_integral(tables):
    """Lights crossing the horizon included: quads clipped exactly, disks by the closed form or the clipped
    ellipse's boundary integral (measured: max |LTC - brute force| / albedo 8e-8 for quads, 7.8e-7 for disks; the
    equal-area 12-gon before it 1.1e-3)."""
    rng = np.random.default_rng(7)
    n, p = np.array([0.0, 0.0, 1.0]), np.zeros(3)
    worst = {"quad": 0.0, "disk": 0.0}
    for _ in range(12):
        mu, r = rng.uniform(0.05, 1.0), rng.uniform(0.1, 1.0)
        v = _view(mu)
        centre = rng.normal(size=3) * 1.5 + np.array([0.0, 0.0, 0.6])
        u, w = rng.normal(size=3) * 0.6, rng.normal(size=3) * 0.6
        w -= u * (u @ w) / (u @ u)
        a, b, albedo = (float(x) for x in tables.zeltner_sheen(np.float64(mu), np.float64(r)))
        f_cos = lambda l, vv: albedo * sheen.zeltner_density(l[..., 0], l[..., 1], l[..., 2], a, b)   # noqa: E731
        for kind in ("quad", "disk"):
            if kind == "quad":
                corners = [centre - u - w, centre + u - w, centre + u + w, centre - u + w]
                light = shading.QuadLight(corners, two_sided=1.0)
                truth = reference.brdf_integral_polygon(f_cos, v, np.array(corners), panels=32, two_sided=True).value
            else:
                light = shading.DiskLight(centre, u, w, two_sided=1.0)
                truth = reference.brdf_integral_disk(f_cos, v, centre, u, w, panels=32, two_sided=True).value
            value, _ = shading.zeltner_sheen(tables, light, p, n, v, np.float64(r))
            worst[kind] = max(worst[kind], abs(float(value) - truth) / max(albedo, 1e-6))
    print(f"\n[zeltner area] max |LTC - brute force| / albedo: {worst}")
    assert worst["quad"] < 1e-4 and worst["disk"] < 1e-5, worst


def test_world_form_is_exact_for_l2_radiance_at_nodes(tables):
    rng = np.random.default_rng(4)
    coeffs = rng.normal(size=(9, 3))
    coeffs[0] += 3.0
    local, w = indirect.hemisphere_quadrature(256, 512)
    for mu, r in ((3 / 31, 10 / 31), (0.5, 16 / 31), (1.0, 1.0), (20 / 31, 25 / 31)):
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        t = np.cross(n, rng.normal(size=3))
        t /= np.linalg.norm(t)
        v = mu * n + np.sqrt(max(1.0 - mu * mu, 0.0)) * t
        lobe = world.SH_LTC_ZELTNER(tables, N=n, V=v, **{"Sheen Roughness": np.float64(r)})
        got = world.sh_moments(list(coeffs), lobe) * lobe["Albedo"]
        a, b, albedo = (float(x) for x in tables.zeltner_sheen(np.float64(mu), np.float64(r)))
        t1, t2, nn = polygon.local_frame(n, v)
        lw = local[:, 0, None] * t1 + local[:, 1, None] * t2 + local[:, 2, None] * nn
        d = sheen.zeltner_density(local[:, 0], local[:, 1], local[:, 2], a, b)
        want = albedo * np.einsum("k,kc->c", d * w, indirect.sh_radiance(coeffs, lw))
        np.testing.assert_allclose(got, want, rtol=1e-4, atol=1e-6 * np.abs(want).max())


def test_stored_switch_and_labels():
    assert Features(sheen=True).sheen == "disney_talk" and Features(sheen=False).sheen == "none"
    assert Features.from_dict({"specular": "turquin", "diffuse": "cod", "sheen": 1}).sheen == "disney_talk"
    # the old group name is kept for the old switch (saved files find their groups)
    assert Features("turquin", "cod", sheen=True).label() == "turquin, cod, sheen"
    assert Features("turquin", "cod", sheen="zeltner").label() == "turquin, cod, zeltner sheen"
    assert light_shading.lobe_keys(Features("turquin", "cod", sheen="zeltner"))[-1] == "zeltner"
    with pytest.raises(ValueError):
        Features(sheen="velvet")


def test_principled_layering(tables):
    """Lobes under the Zeltner sheen are weighted by 1 - max(sheen colour) R(mu_v) (Cycles'
    closure_layering_weight); the Disney sheens add."""
    n, v, l = np.array([0.0, 0.0, 1.0]), _view(0.4), np.array([0.3, 0.2, 0.93])
    l /= np.linalg.norm(l)
    surface = {"Albedo": np.array([0.5, 0.4, 0.3]), "Sheen Color": np.array([0.2, 0.8, 0.5])}
    values = dict(lobes.LAMBERT.function("sun")(tables, N=n, V=v, L=l))
    values.update(lobes.ZELTNER.function("sun")(tables, N=n, V=v, L=l, **{"Sheen Roughness": np.float64(0.6)}))
    got = light_shading.combine_lobes(Features("none", "lambert", sheen="zeltner"), surface, values, np.ones(3))
    weight = 1.0 - 0.8 * values["Sheen Albedo"]
    want = surface["Albedo"] * values["Diffuse"] * weight + surface["Sheen Color"] * values["Sheen"]
    np.testing.assert_allclose(got, want, rtol=1e-12)
    assert 0.0 < values["Sheen Albedo"] < 1.0


def _random_lights(rng, count):
    centre = rng.normal(size=(count, 3)) * 1.2 + np.array([0.0, 0.0, 0.3])
    u = rng.normal(size=(count, 3)) * rng.uniform(0.05, 1.0, (count, 1))
    w = rng.normal(size=(count, 3))
    w -= u * (np.sum(u * w, -1) / np.sum(u * u, -1))[:, None]
    w *= rng.uniform(0.05, 1.0, (count, 1)) / np.linalg.norm(w, axis=-1, keepdims=True)
    c = np.stack([rng.uniform(0.2, 1.5, count), rng.uniform(-0.1, 0.1, count), rng.uniform(-0.5, 0.5, count),
                  rng.uniform(0.3, 20.0, count)], axis=-1)              # c0 c3 > c1 c2: a positive determinant
    return centre, u, w, c


def test_clipped_integrals_trace_and_clip_exactly(tables):
    """The exact-horizon integrals: the quad's equals the numpy clipped reference (Sutherland-Hodgman + exact
    edges, ``polygon.ltc_polygon_integral(method="clipped")``); the disk's is its closed form where the
    transformed disk lies above the horizon; both trace to the same values (IR, float32)."""
    from rt_lookdev.core.ir import trace
    from rt_lookdev.core.ir.numpy_backend import evaluate
    from rt_lookdev.core.ltc import disk, matrix

    rng = np.random.default_rng(17)
    centre, u, w, c = _random_lights(rng, 400)
    corners = np.stack([centre - u - w, centre + u - w, centre + u + w, centre - u + w], axis=1)
    for two in (0.0, 1.0):
        args = {f"c{i}": c[:, i] for i in range(4)}
        args.update({f"p{i}": corners[:, i] for i in range(4)}, Center=centre, **{"Two Sided": np.full(len(c), two)})
        got = polygon.LTC_QUAD_INTEGRAL_CLIPPED(tables, **args)["Integral"]
        want = polygon.ltc_polygon_integral(matrix.unpack_inverse(c), corners, bool(two), method="clipped")
        lit = polygon.off_plane(list(np.moveaxis(corners, 1, 0)), centre)
        np.testing.assert_allclose(got, np.where(lit, want, 0.0), rtol=2e-5, atol=2e-6)
        names = {k: ("vector" if np.ndim(v) == 2 else "float") for k, v in args.items()}
        _, out = trace(lambda **kw: polygon.LTC_QUAD_INTEGRAL_CLIPPED(tables, **kw)["Integral"], names)
        np.testing.assert_allclose(evaluate(out, args, np.float32, tables), got, rtol=1e-4, atol=1e-6)

        dargs = {f"c{i}": c[:, i] for i in range(4)}
        dargs.update({"Center": centre, "Axis U": u, "Axis V": w, "Two Sided": np.full(len(c), two)})
        got = disk.LTC_DISK_INTEGRAL_CLIPPED(tables, **dargs)["Integral"]
        closed = disk.LTC_DISK_INTEGRAL(tables, **dargs)["Integral"]
        t = [matrix.transform_packed(tuple(c.T), x) for x in (centre, u, w)]
        above = t[0][:, 2] > np.hypot(t[1][:, 2], t[2][:, 2])
        assert 50 < above.sum() < 350
        np.testing.assert_array_equal(got[above], closed[above])
        names = {k: ("vector" if np.ndim(v) == 2 else "float") for k, v in dargs.items()}
        _, out = trace(lambda **kw: disk.LTC_DISK_INTEGRAL_CLIPPED(tables, **kw)["Integral"], names)
        np.testing.assert_allclose(evaluate(out, dargs, np.float32, tables), got, rtol=1e-4, atol=1e-6)
        assert got.min() >= 0.0 and got.max() <= 1.0


def test_measured_tables_are_kept_not_baked(tmp_path):
    """zeltner_sheen cannot be baked by numpy: the bake never computes it (``lut_bake`` knows only GROUPS),
    ``keep_measured`` copies the shipped files into another LUT folder, and a missing or corrupt copy says how to
    get it back."""
    from rt_lookdev.core import lut_bake
    from rt_lookdev.core.lut import catalog

    assert "zeltner_sheen" not in catalog.GROUPS and catalog.bake_group("zeltner_sheen").measured
    specs = [s for s in catalog.TABLES.values() if s.group == "zeltner_sheen"]
    assert {s.name for s in specs} == {"zeltner_sheen", "zeltner_sheen_sh1", "zeltner_sheen_sh2"}
    missing = catalog.table_status(specs[0], tmp_path)
    assert missing.state == "missing" and "measure_sheen_table.py" in missing.message
    assert catalog.keep_measured(tmp_path, log=lambda line: None) == {"zeltner_sheen": "copied"}
    assert lut_bake.group_is_current("zeltner_sheen", tmp_path)
    assert catalog.keep_measured(tmp_path, log=lambda line: None) == {"zeltner_sheen": "kept"}
    path = tmp_path / specs[0].filename
    data = bytearray(path.read_bytes())
    data[-200] ^= 0xFF                                     # a damaged copy
    path.write_bytes(bytes(data))
    corrupt = catalog.table_status(specs[0], tmp_path)
    assert corrupt.state == "corrupt" and "measured, not baked" in corrupt.message
    assert catalog.keep_measured(tmp_path, log=lambda line: None) == {"zeltner_sheen": "copied"}
