"""Indirect diffuse from L2 SH (core/indirect.py).

- the basis is orthonormal (quadrature); Lambert irradiance sum A_l c_lm Y_lm equals the integral;
- the wrapped lobe's closed-form Funk-Hecke factors equal quadrature, reduce to Lambert at w = 0 and
  conserve energy for w in [0, 1];
- the LTC-rotated lobe is the plain cosine lobe when Minv = identity; the axis is the LTC density's
  half-space (the talk's ``mul(float3(0,0,1), mul(Minv, R))``);
- traced (IR + numpy backend, float64) equals direct numpy to 1e-6;
- measured against the brute-force CoD integral over random SH environments and (N, V, r): the
  talk's LTC-rotated lobe (a) beats "scaling by the BRDF magnitude only" (b) on average.
"""
import numpy as np
import pytest

from rt_lookdev.core import indirect as ind
from rt_lookdev.core.diffuse import wrapped_diffuse_cosine
from rt_lookdev.core.ir import trace
from rt_lookdev.core.ir.numpy_backend import evaluate, node_count
from rt_lookdev.core.ltc import matrix, polygon, shading
from rt_lookdev.core.lut import lookup

RNG_SEED = 606


@pytest.fixture(scope="module")
def tables(lut_dir):
    return lookup.LutSet.from_folder(lut_dir)


def _unit(rng, k):
    d = rng.normal(size=(k, 3))
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def _views(rng, n):
    """Random unit views in the upper hemisphere of each normal n (K, 3)."""
    v = rng.normal(size=n.shape)
    v -= 2.0 * np.minimum(np.sum(v * n, axis=-1), 0.0)[:, None] * n
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def _falloff_env(rng):
    """Random coefficients with a realistic band falloff (band l ~ 0.6^l of the DC term, coloured),
    the DC term raised where needed so the radiance is at least 10% of its mean everywhere."""
    dc = rng.uniform(0.3, 3.0) * rng.uniform(0.6, 1.0, 3)
    c = np.empty((9, 3))
    c[0] = dc
    for i in range(1, 9):
        c[i] = rng.normal(size=3) * 0.6 ** ind.BAND[i] * dc
    low = ind.sh_radiance(c, _FLOOR_DIRS).min(axis=0)            # per channel
    c[0] += np.maximum(0.1 * dc * ind.Y00 - low, 0.0) / ind.Y00
    return c


_FLOOR_DIRS = ind.sphere_quadrature(24, 48)[0]


def _lobe_env(rng):
    """3-4 bright exponential lobes (coloured suns / windows) over a dim ambient, projected to L2."""
    k = rng.integers(3, 5)
    dirs = _unit(rng, k)
    sharpness = rng.uniform(2.0, 30.0, k)
    colour = rng.uniform(0.5, 5.0, (k, 3))
    ambient = rng.uniform(0.02, 0.3, 3)

    def radiance(d):
        out = np.broadcast_to(ambient, (len(d), 3)).copy()
        for j in range(k):
            out += colour[j] * np.exp(sharpness[j] * (d @ dirs[j] - 1.0))[:, None]
        return out

    return ind.sh_project(radiance, 48, 96)


# --- basis and Lambert ------------------------------------------------------------------------------

def test_basis_orthonormal():
    dirs, w = ind.sphere_quadrature(24, 48)
    y = ind.sh9_basis_array(dirs)
    gram = np.einsum("ki,k,kj->ij", y, w, y)
    assert np.abs(gram - np.eye(9)).max() < 1e-12


def test_basis_constants():
    # Ramamoorthi & Hanrahan 2001, eq. 3
    assert np.allclose([ind.Y00, ind.Y1, ind.Y2_PRODUCT, ind.Y20, ind.Y22],
                       [0.282095, 0.488603, 1.092548, 0.315392, 0.546274], atol=1e-6)
    assert np.allclose(ind.LAMBERT_ZONAL, [np.pi, 2.0 * np.pi / 3.0, np.pi / 4.0])


def test_lambert_irradiance_matches_quadrature():
    rng = np.random.default_rng(RNG_SEED)
    coeffs = np.stack([_falloff_env(rng) for _ in range(8)] + [rng.normal(size=(9, 3)) for _ in range(4)])
    n = _unit(rng, len(coeffs))
    got = ind.sh_irradiance(ind.coefficient_list(coeffs), n)
    # hemisphere about n: the integrand is a polynomial there, so Gauss-Legendre is exact
    local, w = ind.hemisphere_quadrature(16, 32)
    t1, t2, nn = polygon.local_frame(n, _unit(rng, len(n)))
    world = local[:, 0, None] * t1[:, None] + local[:, 1, None] * t2[:, None] + local[:, 2, None] * nn[:, None]
    want = np.einsum("bk,bkc->bc", (local[:, 2] * w)[None], ind.sh_radiance(coeffs, world))
    assert np.abs(got - want).max() < 1e-11 * np.abs(want).max()
    assert np.allclose(ind.sh_cosine_lobe_eval(ind.coefficient_list(coeffs), 2.5 * n), got / np.pi, rtol=1e-12)


def test_projection_roundtrip():
    rng = np.random.default_rng(RNG_SEED + 1)
    c = rng.normal(size=(9, 3))
    assert np.allclose(ind.sh_project(lambda d: ind.sh_radiance(c, d), 16, 32), c, atol=1e-12)


# --- wrapped lobe -----------------------------------------------------------------------------------

@pytest.mark.parametrize("wrap", [0.0, 0.2, 0.5, 0.8, 1.0])
def test_wrapped_lobe_zonal_matches_quadrature(wrap):
    # Funk-Hecke by quadrature of the kernel itself (core.diffuse.wrapped_diffuse_cosine) on [-w, 1]
    x, wx = np.polynomial.legendre.leggauss(32)
    t = -wrap + (1.0 + wrap) * 0.5 * (x + 1.0)
    wt = (1.0 + wrap) * 0.5 * wx
    k = wrapped_diffuse_cosine(t, wrap)
    legendre = (np.ones_like(t), t, 0.5 * (3.0 * t * t - 1.0))
    want = [2.0 * np.pi * np.sum(wt * k * p) for p in legendre]
    got = ind.wrapped_lobe_zonal(wrap)
    assert np.allclose(got, want, rtol=1e-12, atol=1e-14)
    assert abs(got[0] - 1.0) < 1e-12           # energy: a uniform environment gives 1


def test_wrapped_lobe_energy_and_lambert_limit():
    rng = np.random.default_rng(RNG_SEED + 2)
    coeffs = ind.coefficient_list(np.stack([_falloff_env(rng) for _ in range(6)]))
    n = _unit(rng, 6)
    albedo = rng.uniform(0.1, 1.0, (6, 3))
    assert np.allclose(ind.sh_wrapped_diffuse(coeffs, n, albedo, 0.0), ind.sh_lambert(coeffs, n, albedo), rtol=1e-14)
    white = [np.ones(3)] + [np.zeros(3)] * 8
    for w in np.linspace(0.0, 1.0, 11):
        # a uniform environment L = 1 (c00 = 1 / Y00) gives 1 for every wrap
        uniform = [white[0] / ind.Y00] + white[1:]
        assert np.allclose(ind.sh_wrapped_lobe_eval(uniform, n, w), 1.0, rtol=1e-12)
        # and the wrapped result integrated over all normals equals Lambert's (both conserve energy)
        dirs, wq = ind.sphere_quadrature(12, 24)
        wrapped = ind.sh_wrapped_lobe_eval(coeffs, dirs[:, None, :], w)
        lam = ind.sh_cosine_lobe_eval(coeffs, dirs[:, None, :])
        assert np.allclose(np.einsum("k,kbc->bc", wq, wrapped), np.einsum("k,kbc->bc", wq, lam), rtol=1e-12)


# --- the LTC-rotated lobe --------------------------------------------------------------------------

def test_identity_ltc_gives_plain_cosine_lobe():
    rng = np.random.default_rng(RNG_SEED + 3)
    n = _unit(rng, 20)
    v = _views(rng, n)
    frame = polygon.local_frame(n, v)
    c = tuple(np.full(20, x) for x in shading.IDENTITY)
    for mode in ("talk", "peak"):
        axis = ind.ltc_lobe_axis(c, frame, mode)
        assert np.allclose(axis, n, atol=1e-15)
    coeffs = ind.coefficient_list(np.stack([_falloff_env(rng) for _ in range(20)]))
    assert np.allclose(ind.sh_cosine_lobe_eval(coeffs, ind.ltc_lobe_axis(c, frame)),
                       ind.sh_cosine_lobe_eval(coeffs, n), rtol=1e-14)


def test_lobe_axis_is_the_ltc_half_space(tables):
    """The talk's axis a = R^T Minv^T e_z: a.w > 0 exactly where the LTC density is positive, and
    a.w = (Minv R w).z for every direction."""
    rng = np.random.default_rng(RNG_SEED + 4)
    n = _unit(rng, 50)
    v = _views(rng, n)
    r = rng.uniform(0.0, 1.0, 50)
    c, _, _ = tables.ltc(ind.COD_TABLE, np.clip(np.sum(n * v, -1), 0, 1), r)
    frame = polygon.local_frame(n, v)
    axis = ind.ltc_lobe_axis(c, frame)
    rot = np.stack(frame, axis=-2)                      # rows T1, T2, N
    minv = matrix.unpack_inverse(np.stack(c, axis=-1))
    w = _unit(rng, 50)
    z = np.einsum("bij,bjk,bk->bi", minv, rot, w)[:, 2]
    assert np.allclose(np.sum(axis * w, -1), z, atol=1e-12)
    # the talk's HLSL expression, literally: row vector (0, 0, 1) times (Minv R)
    talk = np.einsum("j,bjk->bk", np.array([0.0, 0.0, 1.0]), np.einsum("bij,bjk->bik", minv, rot))
    assert np.allclose(talk, axis, atol=1e-12)
    # "peak": the image M e_z of the cosine's peak
    peak = np.einsum("bji,bj->bi", rot, np.linalg.inv(minv)[:, :, 2])
    peak /= np.linalg.norm(peak, axis=-1, keepdims=True)
    got = ind.ltc_lobe_axis(c, frame, "peak")
    assert np.allclose(got / np.linalg.norm(got, axis=-1, keepdims=True), peak, atol=1e-12)


def test_reference_quadrature_converged():
    rng = np.random.default_rng(RNG_SEED + 5)
    coeffs = np.stack([_lobe_env(rng) for _ in range(4)])
    n = _unit(rng, 4)
    v = _views(rng, n)
    r = np.array([0.0, 0.3, 0.7, 1.0])
    coarse = ind.cod_diffuse_reference(coeffs, n, v, r, 48, 96)
    fine = ind.cod_diffuse_reference(coeffs, n, v, r, 128, 256)
    assert np.abs(coarse / fine - 1.0).max() < 1e-5


def test_reference_uniform_environment_is_table_magnitude(tables):
    """In a uniform white environment both methods give the magnitude, and the reference the BRDF's
    directional albedo: they agree to the table's accuracy."""
    rng = np.random.default_rng(RNG_SEED + 6)
    n = _unit(rng, 30)
    v = _views(rng, n)
    r = rng.uniform(0.0, 1.0, 30)
    uniform = np.zeros((30, 9, 3))
    uniform[:, 0] = 1.0 / ind.Y00
    ref = ind.cod_diffuse_reference(uniform, n, v, r)
    got = ind.sh_cod_diffuse(tables, ind.coefficient_list(uniform), n, v, r, np.ones(3))
    assert np.abs(got / ref - 1.0).max() < 0.02


# --- traced = numpy -------------------------------------------------------------------------------

def _trace_inputs():
    names = {f"c{i}": "vector" for i in range(9)}
    names.update(n="vector", v="vector", r="float", albedo="vector", wrap="float")
    return names


def _trace_values(rng, k=64):
    n = _unit(rng, k)
    v = _views(rng, n)
    v[0] = n[0]                                           # mu = 1: frame fallback
    v[1] = np.cross(n[1], _unit(rng, 1)[0])
    v[1] /= np.linalg.norm(v[1])                          # mu = 0
    r = rng.uniform(0.0, 1.0, k)
    r[:4] = (0.0, 1.0, 0.0, 1.0)
    coeffs = np.stack([_falloff_env(rng) for _ in range(k)])
    values = {f"c{i}": coeffs[:, i] for i in range(9)}
    values.update(n=n, v=v, r=r, albedo=rng.uniform(0.0, 1.0, (k, 3)), wrap=rng.uniform(0.0, 1.0, k))
    return values


FUNCTIONS = {
    "irradiance": lambda t, a: ind.sh_irradiance(a["c"], a["n"]),
    "lambert": lambda t, a: ind.sh_lambert(a["c"], a["n"], a["albedo"]),
    "wrapped": lambda t, a: ind.sh_wrapped_diffuse(a["c"], a["n"], a["albedo"], a["wrap"]),
    "cod_talk": lambda t, a: ind.sh_cod_diffuse(t, a["c"], a["n"], a["v"], a["r"], a["albedo"]),
    "cod_peak": lambda t, a: ind.sh_cod_diffuse(t, a["c"], a["n"], a["v"], a["r"], a["albedo"], axis="peak"),
    "cod_magnitude_only": lambda t, a: ind.sh_cod_diffuse_magnitude_only(t, a["c"], a["n"], a["v"], a["r"],
                                                                         a["albedo"]),
    "cod_wrapped": lambda t, a: ind.sh_cod_wrapped_diffuse(t, a["c"], a["n"], a["v"], a["r"], a["albedo"],
                                                           a["wrap"]),
}


def _call(name, tables, kw):
    args = {"c": [kw[f"c{i}"] for i in range(9)], "n": kw["n"], "v": kw["v"], "r": kw["r"],
            "albedo": kw["albedo"], "wrap": kw["wrap"]}
    return FUNCTIONS[name](tables, args)


@pytest.mark.parametrize("name", sorted(FUNCTIONS))
def test_traced_equals_numpy(tables, name):
    rng = np.random.default_rng(RNG_SEED + 7)
    values = _trace_values(rng)
    want = np.asarray(_call(name, tables, values), dtype=np.float64)
    graph, out = trace(lambda **kw: _call(name, tables, kw), _trace_inputs())
    got = evaluate(out, values, dtype=np.float64, tables=tables)
    assert np.all(np.isfinite(want)) and np.all(np.isfinite(got))
    assert np.all(np.abs(got - want) <= 1e-6 * np.abs(want) + 1e-12), np.abs(got - want).max()
    assert node_count(out) < 150
    got32 = evaluate(out, values, dtype=np.float32, tables=tables)
    assert np.all(np.isfinite(got32))
    assert np.all(np.abs(got32 - want) <= 1e-4 * np.abs(want) + 1e-5)


# --- the measurement ---------------------------------------------------------------------------------

def _relative_errors(tables, coeffs, n, v, r):
    ref = ind.cod_diffuse_reference(coeffs, n, v, r, 48, 96)
    c = ind.coefficient_list(coeffs)
    white = np.ones(3)
    methods = {"ltc_talk": ind.sh_cod_diffuse(tables, c, n, v, r, white),
               "ltc_peak": ind.sh_cod_diffuse(tables, c, n, v, r, white, axis="peak"),
               "magnitude_only": ind.sh_cod_diffuse_magnitude_only(tables, c, n, v, r, white)}
    return {k: np.abs(x / ref - 1.0) for k, x in methods.items()}


@pytest.mark.parametrize("family", ["falloff", "lobes"])
def test_ltc_rotated_lobe_beats_magnitude_only(tables, family):
    rng = np.random.default_rng(RNG_SEED + (8 if family == "falloff" else 9))
    k = 240
    make = _falloff_env if family == "falloff" else _lobe_env
    coeffs = np.stack([make(rng) for _ in range(k)])
    n = _unit(rng, k)
    v = _views(rng, n)
    r = rng.uniform(0.0, 1.0, k)
    err = _relative_errors(tables, coeffs, n, v, r)
    for name, e in err.items():
        print(f"[{family}] {name:15s} mean {e.mean():.4f}  median {np.median(e):.4f}  "
              f"p90 {np.quantile(e, 0.9):.4f}  max {e.max():.4f}")
    assert err["ltc_talk"].mean() < err["magnitude_only"].mean()
    assert err["ltc_peak"].mean() < err["magnitude_only"].mean()
