"""The LTC area-light code traced into the IR equals the direct numpy evaluation.

- the two integral node functions (quad, disk): packed Minv c0..c3, local-frame geometry, sidedness;
  their size (each one node group of <= 140 operations) and interface;
- every shading combination of core/ltc/shading.py traced with Expr p, n, v, roughness, colours and
  light geometry, evaluated by the numpy backend in float64 (1e-6 relative) and float32 (1e-4
  relative, 1e-6 absolute), over quads and disks above, below and across the horizon, in the
  light's plane, degenerate (zero area, collinear, tiny, huge), at mu = 0 and 1 and r = 0 and 1;
- no NaN or Inf anywhere.
"""
import numpy as np
import pytest

from rt_lookdev.core.ir import trace
from rt_lookdev.core.ir.numpy_backend import evaluate, node_count
from rt_lookdev.core.ltc import disk, matrix, polygon, shading
from rt_lookdev.core.lut import lookup

RNG_SEED = 4242
MAX_NODES = 144   # IR operations; the emitted group adds input/output and Separate XYZ nodes (cap 150)
X, Y, Z = np.eye(3)


@pytest.fixture(scope="module")
def tables(lut_dir):
    return lookup.LutSet.from_folder(lut_dir)


# --- configurations ------------------------------------------------------------------------------

def _quad(c, u, v):
    """Corners c +- u +- v; lit side towards -(u x v)."""
    return np.array([c - u - v, c + u - v, c + u + v, c - u + v])


# (centre, semi-axis u, semi-axis v) in the frame N = +Z, shading point at the origin; the lit side
# faces the origin where it can (u x v points away from it)
LIGHTS = {
    "above": (np.array([0.3, -0.2, 1.5]), 0.5 * X, 0.4 * Y),
    "above_tilted": (np.array([-1.0, 0.5, 1.0]), 0.6 * Y, 0.3 * (X + Z) / np.sqrt(2)),
    "straddling": (np.array([1.5, 0.1, 0.1]), 0.5 * Y, 0.6 * Z),
    "below": (np.array([0.2, 0.1, -1.5]), 0.5 * X, -0.5 * Y),
    "in_plane": (np.array([2.0, 0.0, 1.0]), 0.5 * X, 0.5 * Z),
    "on_light": (np.zeros(3), X, Y),
    "zero_area": (np.array([0.3, 0.2, 1.0]), 0.0 * X, 0.0 * Y),
    "collinear": (np.array([0.3, 0.2, 1.0]), X, 0.0 * Y),
    "tiny": (np.array([0.3, 0.2, 1.0]), 1e-4 * X, 1e-4 * Y),
    "huge": (np.array([0.3, 0.2, 1.0]), 1e4 * X, 1e4 * Y),
    "huge_close": (np.array([0.0, 0.0, 1e-3]), 1e3 * X, 1e3 * Y),
    "grazing": (np.array([5.0, 0.0, 1e-6]), X, Y),
}

VIEW_ANGLES = (0.0, 30.0, 60.0, 89.9, 90.0)        # mu = 1 ... 0
ROUGHNESS = (0.0, 0.25, 0.6, 1.0)


def _configurations(seed=RNG_SEED, random_lights=24):
    """Arrays (N, ...) of shading points, normals, views, roughness and light geometry: every named
    light under every view angle and roughness, plus random lights, normals and points."""
    rng = np.random.default_rng(seed)
    rows = []
    for name, (c, u, v) in LIGHTS.items():
        for i, theta in enumerate(VIEW_ANGLES):
            t = np.radians(theta)
            view = np.array([np.sin(t), 0.0, np.cos(t)])
            for r in ROUGHNESS:
                rows.append((np.zeros(3), Z, view, r, c, u, v))
    for _ in range(random_lights):
        n = rng.normal(size=3)
        n /= np.linalg.norm(n)
        view = rng.normal(size=3)
        view -= min(view @ n, 0.0) * 2.0 * n
        view /= np.linalg.norm(view)
        p = rng.normal(size=3)
        d = rng.normal(size=3)
        d /= np.linalg.norm(d)
        c = p + d * rng.uniform(0.5, 3.0)
        u, v = rng.normal(size=3) * rng.uniform(0.1, 1.0), rng.normal(size=3) * rng.uniform(0.1, 1.0)
        rows.append((p, n, view, rng.uniform(0.0, 1.0), c, u, v))
    p, n, view, r, c, u, v = (np.array(x, dtype=np.float64) for x in zip(*rows))
    return {"p": p, "n": n, "v": view, "r": r, "c": c, "u": u, "w": v}


def _close(got, want, dtype):
    got, want = np.asarray(got, np.float64), np.asarray(want, np.float64)
    assert np.all(np.isfinite(got)) and np.all(np.isfinite(want))
    if dtype == np.float64:
        bound = 1e-6 * np.abs(want) + 1e-12
    else:
        bound = 1e-4 * np.abs(want) + 1e-6
    bad = np.abs(got - want) > bound
    assert not bad.any(), (np.flatnonzero(bad)[:10], got[bad][:5], want[bad][:5])


# --- the integral node functions ------------------------------------------------------------------

def test_integral_functions_are_small_node_groups():
    for fn in (polygon.LTC_QUAD_INTEGRAL, disk.LTC_DISK_INTEGRAL):
        body = fn.function
        count = node_count(tuple(body.outputs.values()))
        assert 0 < count <= MAX_NODES, (fn.name, count)
        ops = {n.op for n in _nodes(body)}
        # one table lookup: a call of the bilinear "RTL LUT ltc_ggx_mag" function, channel A
        calls = [n for n in _nodes(body) if n.op == "call"]
        assert "lut" not in ops and len(calls) == 1
        assert body.graph.functions[calls[0].attr("function")].name == "RTL LUT ltc_ggx_mag"
        assert {n.attr("name") for n in _nodes(body) if n.op == "output"} == {"A"}
        assert list(fn.output_sockets) == ["Integral"]
        assert all(s.description for s in list(fn.input_sockets.values()) + list(fn.output_sockets.values()))
    assert list(polygon.LTC_QUAD_INTEGRAL.input_sockets) == ["c0", "c1", "c2", "c3", "p0", "p1", "p2", "p3",
                                                              "Center", "Two Sided"]
    assert list(disk.LTC_DISK_INTEGRAL.input_sockets) == ["c0", "c1", "c2", "c3", "Center", "Axis U", "Axis V",
                                                           "Two Sided"]


def _nodes(function):
    from rt_lookdev.core.ir.numpy_backend import topological_order

    return topological_order(tuple(function.outputs.values()))


def _packed_cases(tables, cfg):
    """Packed matrices: table entries at every configuration's (mu, r), the identity, a random mix."""
    mu = np.clip(cfg["v"][:, 2], 0.0, 1.0)
    c, _, _ = tables.ltc("ltc_ggx", mu, cfg["r"])
    rng = np.random.default_rng(RNG_SEED + 1)
    cases = [np.stack(c, axis=-1),
             np.broadcast_to(np.array(shading.IDENTITY), (len(mu), 4)),
             np.stack([rng.uniform(0.01, 1.5, len(mu)), rng.uniform(-0.5, 0.5, len(mu)),
                       rng.uniform(-0.5, 0.5, len(mu)), rng.uniform(1e-4, 1.5, len(mu))], axis=-1)]
    return [np.ascontiguousarray(x) for x in cases]


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_quad_integral_traced_equals_numpy(tables, dtype):
    cfg = _configurations()
    corners = np.stack([_quad(c, u, v) for c, u, v in zip(cfg["c"], cfg["u"], cfg["w"])])
    names = dict({f"c{i}": "float" for i in range(4)}, **{f"p{i}": "vector" for i in range(4)},
                 **{"Center": "vector", "Two Sided": "float"})
    _, out = trace(lambda **kw: polygon.LTC_QUAD_INTEGRAL(tables, **kw)["Integral"], names)
    for packed in _packed_cases(tables, cfg):
        for two in (0.0, 1.0):
            args = {f"c{i}": packed[:, i] for i in range(4)}
            args.update({f"p{i}": corners[:, i] for i in range(4)}, **{"Two Sided": np.full(len(packed), two)})
            args["Center"] = corners.mean(axis=1)
            direct = polygon.LTC_QUAD_INTEGRAL(tables, **args)["Integral"]
            # the array API (3x3 Minv) is the same computation
            via_matrix = polygon.ltc_quad_integral(matrix.unpack_inverse(packed), corners, bool(two),
                                                   sphere_table=tables.sphere_table())
            _close(via_matrix, direct, np.float64)
            _close(evaluate(out, args, dtype, tables), direct, dtype)
            assert direct.min() >= 0.0 and direct.max() <= 1.0 + 1e-6


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_disk_integral_traced_equals_numpy(tables, dtype):
    cfg = _configurations()
    names = dict({f"c{i}": "float" for i in range(4)}, **{"Center": "vector", "Axis U": "vector",
                                                         "Axis V": "vector", "Two Sided": "float"})
    _, out = trace(lambda **kw: disk.LTC_DISK_INTEGRAL(tables, **kw)["Integral"], names)
    for packed in _packed_cases(tables, cfg):
        for two in (0.0, 1.0):
            args = {f"c{i}": packed[:, i] for i in range(4)}
            args.update({"Center": cfg["c"], "Axis U": cfg["u"], "Axis V": cfg["w"],
                         "Two Sided": np.full(len(packed), two)})
            direct = disk.LTC_DISK_INTEGRAL(tables, **args)["Integral"]
            via_matrix = disk.ltc_disk_integral(matrix.unpack_inverse(packed), cfg["c"], cfg["u"], cfg["w"],
                                                bool(two), sphere_table=tables.sphere_table())
            _close(via_matrix, direct, np.float64)
            _close(evaluate(out, args, dtype, tables), direct, dtype)
            assert direct.min() >= 0.0 and direct.max() <= 1.0 + 1e-6


def test_transform_packed_is_the_matrix():
    rng = np.random.default_rng(RNG_SEED)
    c = rng.normal(size=(20, 4))
    x = rng.normal(size=(20, 3))
    want = np.einsum("...ij,...j->...i", matrix.unpack_inverse(c), x)
    assert np.allclose(matrix.transform_packed(tuple(c.T), x), want, rtol=1e-14, atol=0)
    g, out = trace(lambda c0, c1, c2, c3, x: matrix.transform_packed((c0, c1, c2, c3), x),
                   {"c0": "float", "c1": "float", "c2": "float", "c3": "float", "x": "vector"})
    got = evaluate(out, dict({f"c{i}": c[:, i] for i in range(4)}, x=x), np.float64)
    assert np.allclose(got, want, rtol=1e-14, atol=0)


# --- shading combinations ------------------------------------------------------------------------

COMBINATIONS = {
    "ggx_specular": lambda t, light, p, n, v, r, k: shading.ggx_specular(t, light, p, n, v, r, k),
    "ggx_turquin": lambda t, light, p, n, v, r, k: shading.ggx_specular_multiscatter(t, light, p, n, v, r, k),
    "ggx_fdez_aguera": lambda t, light, p, n, v, r, k: shading.ggx_specular_multiscatter(t, light, p, n, v, r, k,
                                                                                         "fdez_aguera"),
    "cod_diffuse": lambda t, light, p, n, v, r, k: shading.cod_diffuse(t, light, p, n, v, r, k),
    "ashikhmin_cloth": lambda t, light, p, n, v, r, k: shading.ashikhmin_cloth(t, light, p, n, v, r, k),
    "disney_sheen": lambda t, light, p, n, v, r, k: shading.disney_sheen(t, light, p, n, v, k),
    "lambert": lambda t, light, p, n, v, r, k: shading.lambert(t, light, p, n, v, k),
    "wrapped_diffuse": lambda t, light, p, n, v, r, k: shading.wrapped_diffuse(t, light, p, n, v, k, r),
}


def _light(kind, two_sided, c, u, w):
    if kind == "quad":
        return shading.QuadLight([c - u - w, c + u - w, c + u + w, c - u + w], two_sided)
    return shading.DiskLight(c, u, w, two_sided)


@pytest.mark.parametrize("kind", ["quad", "disk"])
@pytest.mark.parametrize("name", sorted(COMBINATIONS))
def test_shading_traced_equals_numpy(tables, name, kind):
    cfg = _configurations()
    combo = COMBINATIONS[name]
    k = np.linspace(0.02, 1.0, len(cfg["r"]))        # f0 / albedo / colour / wrap

    def shade(p, n, v, r, k, c, u, w, two_sided):
        return combo(tables, _light(kind, two_sided, c, u, w), p, n, v, r, k)

    kinds = {"p": "vector", "n": "vector", "v": "vector", "r": "float", "k": "float", "c": "vector",
             "u": "vector", "w": "vector", "two_sided": "float"}
    graph, out = trace(shade, kinds)
    calls = [graph.functions[n.attr("function")].name for n in graph.nodes.values() if n.op == "call"]
    integrals = [c for c in calls if c.startswith("RTL LTC")]
    # the integral: one nested group; the GGX lobes' band adds a second (catalog.LTC_BANDS)
    assert len(integrals) == (2 if name.startswith("ggx") else 1)
    assert all(c.startswith("RTL LUT ") for c in calls if c not in integrals)   # table lookups
    for two in (0.0, 1.0):
        args = dict(cfg, k=k, two_sided=np.full(len(k), two))
        with np.errstate(over="raise", invalid="raise", divide="raise", under="ignore"):
            direct = shade(**args)
        for dtype in (np.float64, np.float32):
            _close(evaluate(out, args, dtype, tables), direct, dtype)


def test_frame_is_shared_between_lobes(tables):
    """Two lobes at one shading point: one frame, two integral calls (different matrices)."""
    def two_lobes(p, n, v, r, c, u, w):
        light = _light("quad", False, c, u, w)
        return (shading.ggx_specular(tables, light, p, n, v, r, 0.04)
                + shading.cod_diffuse(tables, light, p, n, v, r, 0.8))

    def one_lobe(p, n, v, r, c, u, w):
        return shading.ggx_specular(tables, _light("quad", False, c, u, w), p, n, v, r, 0.04)

    kinds = {"p": "vector", "n": "vector", "v": "vector", "r": "float", "c": "vector", "u": "vector", "w": "vector"}
    g2, out2 = trace(two_lobes, kinds)
    g1, out1 = trace(one_lobe, kinds)
    assert sum(1 for n in g2.nodes.values()
               if n.op == "call" and g2.functions[n.attr("function")].name.startswith("RTL LTC")) == 3   # GGX + band
    # the second lobe adds its table lookups, its call and its shading (measured: 9 operations),
    # not a second frame (26) or a second transform of the corners into it
    frame_ops = node_count(polygon.local_frame(g1.input("n", "vector"), g1.input("v", "vector")))
    assert frame_ops >= 20
    assert node_count(out2) - node_count(out1) <= 12
