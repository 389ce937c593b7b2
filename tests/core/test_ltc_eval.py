"""LTC evaluation over quads and disks: closed forms against brute-force integration.

- sphere table: Snyder's clipped-cap formula against 1D quadrature, table rows, ltc_code's table;
- polygons: exact clipping == numeric integral of the same LTC; clipless == exact where the
  equivalent cap is unclipped at the table nodes; the vector form factor F.z is exact above the
  transformed horizon; clipless horizon == |F| x table within the table's interpolation error;
- disks: Heitz & Hill closed form == numeric integral; N-gon fallback error falls with N;
- Lambert (identity Minv) against textbook form factors; one-/two-sided lights;
- stress: no NaN/Inf, float32 stays float32, for degenerate configurations.
"""
import numpy as np
import pytest

from rt_lookdev.core.ltc import disk, polygon, reference, sphere_table
from rt_lookdev.core.lut.lookup import lut_coordinate

RNG_SEED = 20240617
X, Y, Z = np.eye(3)


# --- helpers ------------------------------------------------------------------------------------

def quad(c, u, v):
    """Corners of the parallelogram c +- u +- v, lit side towards -(u x v) (module convention)."""
    return np.array([c - u - v, c + u - v, c + u + v, c - u + v])


def random_minv(rng):
    """A random LTC inverse matrix (det > 0), with y-couplings to exercise the general case."""
    c0, c3 = rng.uniform(0.3, 1.3, 2)
    c1, c2 = rng.uniform(-0.3, 0.3, 2)
    return np.array([[c0, 0.0, c2], [0.0, 1.0, 0.0], [c1, 0.0, c3]]) + rng.normal(0.0, 0.1, (3, 3))


def random_light(rng, above=True):
    """Centre and two semi-axis vectors of a light 1-3 units away, facing the origin."""
    d = rng.normal(size=3)
    d /= np.linalg.norm(d)
    if above:
        d[2] = abs(d[2]) + 0.3
        d /= np.linalg.norm(d)
    c = d * rng.uniform(1.0, 3.0)
    n = d + rng.normal(0.0, 0.4, 3)
    n /= np.linalg.norm(n)
    t = np.cross(n, rng.normal(size=3))
    t /= np.linalg.norm(t)
    b = np.cross(n, t)
    if c @ np.cross(t, b) < 0:
        t = -t
    a1, a2 = rng.uniform(0.1, 1.0, 2)
    return c, t * a1, b * a2


def cases(n, above):
    rng = np.random.default_rng(RNG_SEED + n + above)
    return [(random_minv(rng), *random_light(rng, above)) for _ in range(n)]


def transformed_above(minv, points):
    return np.all(points @ np.asarray(minv)[2] > 0.0)


def disk_transformed_above(minv, c, u, v):
    n = np.asarray(minv)[2]
    return n @ c - np.hypot(n @ u, n @ v) > 0.0


def cap_unclipped_at_nodes(f):
    """The table cell around (z, |F|) has only nodes with z >= sqrt(|F|): there the ratio is z."""
    length = np.linalg.norm(f)
    z = f[2] / length
    return z - 2.0 / 63.0 >= np.sqrt(min(length + 1.0 / 63.0, 1.0))


def lambert(l, v):
    return np.maximum(l[..., 2], 0.0) / np.pi


# Howell, "A Catalog of Radiation Heat Transfer Configuration Factors", C-11: differential element
# parallel to an a x b rectangle at height c, its normal through a corner.
def rectangle_corner_form_factor(a, b, c):
    x, y = a / c, b / c
    return (x / np.sqrt(1 + x * x) * np.arctan(y / np.sqrt(1 + x * x))
            + y / np.sqrt(1 + y * y) * np.arctan(x / np.sqrt(1 + y * y))) / (2 * np.pi)


# Howell B-13 family: differential element parallel to a disk of radius r at height h, offset a.
def disk_offset_form_factor(r, h, a):
    zz = h * h + a * a + r * r
    return 0.5 * (1.0 - (h * h + a * a - r * r) / np.sqrt(zz * zz - 4.0 * a * a * r * r))


# --- sphere table -------------------------------------------------------------------------------

def test_cap_formula_matches_quadrature():
    zs = np.linspace(-1.0, 1.0, 21)
    lens = np.array([1e-3, 0.05, 0.3, 0.6, 0.9, 1.0])
    closed = sphere_table.cap_form_factor(zs[:, None], lens[None, :])
    numeric = np.array([[reference.cap_form_factor_numeric(z, ln) for ln in lens] for z in zs])
    assert np.max(np.abs(closed - numeric)) < 1e-10
    # fully above the horizon the cap's form factor is z |F|; fully below it is 0
    assert np.allclose(sphere_table.cap_form_factor(0.9, 0.5), 0.45, rtol=1e-14)
    assert sphere_table.cap_form_factor(-0.9, 0.5) == 0.0


def test_sphere_table_rows_and_layout():
    n = 64
    table = sphere_table.sphere_horizon_table(n)
    z = 2.0 * np.arange(n) / (n - 1) - 1.0
    assert table.shape == (n, n)
    assert np.array_equal(table[0], np.maximum(z, 0.0))                      # len -> 0: max(z, 0)
    assert np.allclose(table[-1], (z + 1.0) / 2.0, rtol=0, atol=1e-15)       # hemisphere: (z + 1)/2
    assert table.min() >= 0.0 and table.max() <= 1.0
    j, i = 20, 45                                                           # table[j, i]: v = len, u = z
    assert table[j, i] == pytest.approx(sphere_table.cap_form_factor(z[i], j / (n - 1)) / (j / (n - 1)), rel=1e-14)
    # sampled at a node's texel centre, the lookup returns that node exactly
    u, v = lut_coordinate(z[i] * 0.5 + 0.5, n), lut_coordinate(j / (n - 1), n)
    assert sphere_table.clipped_sphere_integral(j / (n - 1), z[i]) == pytest.approx(table[j, i] * j / (n - 1),
                                                                                   rel=1e-12)
    assert 0.0 < u < 1.0 and 0.0 < v < 1.0


def test_sphere_table_interpolation_error():
    """Bilinear table vs exact cap: docs/area_lights.md, "Horizon handling" (max 0.020 abs, 2% of |F|,
    0.77% for |F| < 0.1)."""
    z, length = np.meshgrid(np.linspace(-1, 1, 801), np.linspace(1e-6, 1, 401), indexing="ij")
    err = np.abs(sphere_table.clipped_sphere_integral(length, z) - sphere_table.cap_form_factor(z, length))
    assert err.max() <= 0.020
    assert (err / length).max() <= 0.020
    assert (err / length)[length < 0.1].max() <= 0.008


def test_sphere_table_matches_ltc_code():
    from rt_lookdev.validation.harness import published_ltc as ltc_anchor
    try:
        _, ltc2 = ltc_anchor.load_anchor()
    except FileNotFoundError:
        pytest.skip("anchor table not present")
    # ltc_code computed its table in float and printed 6 significant digits
    assert np.max(np.abs(sphere_table.sphere_horizon_table(64) - ltc2[..., 3])) < 5e-6


# --- edge integral ------------------------------------------------------------------------------

def test_edge_fit_accuracy():
    theta = np.linspace(1e-4, np.pi - 1e-4, 20001)
    x, s = np.cos(theta), np.sin(theta)
    fitted = polygon.edge_factor(x, s * s)
    exact = theta / s / (2 * np.pi)
    # docs/area_lights.md, "Clipless evaluation": 1.4e-6
    assert np.max(np.abs(fitted / exact - 1.0)) < 1.5e-6


def test_edge_vector_nearly_antipodal():
    """sin^2 from the cross product keeps the theta ~ pi edge exact (1 - x^2 would cancel)."""
    eps = 1e-6
    v1, v2 = np.array([1.0, 0.0, 0.0]), np.array([-np.cos(eps), np.sin(eps), 0.0])
    exact = polygon.edge_vector_exact(v1, v2)
    assert np.allclose(polygon.edge_vector(v1, v2), exact, rtol=1e-5, atol=0)


# --- polygons -----------------------------------------------------------------------------------

@pytest.mark.parametrize("above", [True, False])
def test_quad_clipped_is_exact(above):
    for minv, c, u, v in cases(30, above):
        q = quad(c, u, v)
        ref = reference.ltc_integral_polygon(minv, q)
        assert ref.error <= 1e-12 * max(ref.value, 1e-3)
        got = polygon.ltc_quad_integral(minv, q, method="clipped")
        assert abs(got - ref.value) <= 1e-10 * max(ref.value, 1e-3)


def test_quad_clipless_above_horizon():
    n_table_exact = 0
    for minv, c, u, v in cases(48, True):
        q = quad(c, u, v)
        if not transformed_above(minv, q):
            continue
        ref = reference.ltc_integral_polygon(minv, q).value
        f = polygon.ltc_polygon_vector_form_factor(minv, q)
        assert abs(f[2] - ref) <= 1e-5 * ref                       # the fitted edges: exact to 1e-5
        got = polygon.ltc_quad_integral(minv, q)
        if cap_unclipped_at_nodes(f):
            n_table_exact += 1
            assert abs(got - f[2]) <= 1e-12 * f[2]                 # the table returns z there
        else:  # the equivalent cap dips below the horizon: clipping drops its negative-cosine part
            assert got >= f[2] * (1 - 1e-12)
    assert n_table_exact >= 10


def test_quad_clipless_horizon_is_the_tabulated_cap():
    """Straddling lights: clipless = |F| x table(z, |F|), i.e. the exact clipped cap with the same
    F up to the table's interpolation error; the cap itself is the approximation (reported)."""
    rng = np.random.default_rng(RNG_SEED)
    checked = 0
    while checked < 12:
        minv, (c, u, v) = random_minv(rng), random_light(rng, above=False)
        q = quad(c, u, v)
        t = q @ minv[2]
        if not (t.max() > 0 > t.min()) or (q[0] @ polygon.light_normal(q[None])[0]) < 0:
            continue
        f = polygon.ltc_polygon_vector_form_factor(minv, q)
        length = np.linalg.norm(f)
        cap = sphere_table.cap_form_factor(f[2] / length, length)
        assert abs(polygon.ltc_quad_integral(minv, q) - cap) <= 0.02 * length
        checked += 1


def test_lambert_rectangle_form_factor():
    """Identity Minv is Lambert: clipped, clipless and the brute-force reference all give Howell C-11."""
    a, b, h = 0.7, 1.3, 0.9
    corners = np.array([[0, 0, h], [a, 0, h], [a, b, h], [0, b, h]], dtype=np.float64)
    exact = rectangle_corner_form_factor(a, b, h)
    brute = reference.brdf_integral_polygon(lambert, Z, corners)
    assert abs(brute.value - exact) <= 1e-12 and brute.error <= 1e-12
    assert polygon.ltc_quad_integral(np.eye(3), corners, method="clipped") == pytest.approx(exact, rel=1e-12)
    # unclipped cap at the nodes: the clipless path is exact up to the edge fit
    assert polygon.ltc_quad_integral(np.eye(3), corners) == pytest.approx(exact, rel=3e-6)
    # a centred rectangle is four corner rectangles
    centred = quad(np.array([0.0, 0.0, h]), a * X, b * Y)
    assert polygon.ltc_quad_integral(np.eye(3), centred, method="clipped") == pytest.approx(
        4 * exact, rel=1e-12)


def test_lambert_quad_half_below_horizon():
    """Identity Minv: the clipped path is the Lambert form factor of the part above the horizon."""
    q = quad(np.array([1.5, 0.2, 0.1]), 0.8 * Y, 0.6 * Z)         # vertical, faces the origin
    assert q[0] @ polygon.light_normal(q[None])[0] > 0
    brute = reference.brdf_integral_polygon(lambert, Z, q)
    upper = reference.brdf_integral_polygon(lambert, Z, reference.clip_polygon(q, Z))
    assert brute.value == pytest.approx(upper.value, rel=1e-12)
    clipped = polygon.ltc_quad_integral(np.eye(3), q, method="clipped")
    assert clipped == pytest.approx(brute.value, rel=1e-10)
    f = polygon.ltc_polygon_vector_form_factor(np.eye(3), q)
    length = np.linalg.norm(f)
    clipless = polygon.ltc_quad_integral(np.eye(3), q)
    assert abs(clipless - sphere_table.cap_form_factor(f[2] / length, length)) <= 0.02 * length
    assert clipless > f[2]  # the cap's part below the horizon is dropped, not subtracted


@pytest.mark.parametrize("method", ["clipless", "clipped"])
def test_quad_one_and_two_sided(method):
    for minv, c, u, v in cases(6, True):
        front = quad(c, u, v)
        back = front[::-1]                                   # same light, lit side away from the origin
        one = polygon.ltc_quad_integral(minv, front, method=method)
        assert one > 0.0
        assert polygon.ltc_quad_integral(minv, back, method=method) == 0.0
        assert polygon.ltc_quad_integral(minv, back, two_sided=True, method=method) == pytest.approx(one, rel=1e-12)
        assert polygon.ltc_quad_integral(minv, front, two_sided=True, method=method) == pytest.approx(one, rel=1e-12)


def test_local_frame_and_transform():
    rng = np.random.default_rng(RNG_SEED)
    n = rng.normal(size=(50, 3))
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    v = rng.normal(size=(50, 3))
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    v[:5] = n[:5]                                   # mu = 1: fallback tangent
    v[5:10] = -n[5:10]
    v[10:15] = np.cross(n[10:15], rng.normal(size=(5, 3)))  # mu = 0
    v[10:15] /= np.linalg.norm(v[10:15], axis=-1, keepdims=True)
    t1, t2, nn = polygon.local_frame(n, v)
    basis = np.stack([t1, t2, nn], axis=-2)
    assert np.allclose(basis @ np.swapaxes(basis, -1, -2), np.eye(3), atol=1e-12)
    assert np.allclose(np.linalg.det(basis), 1.0)
    p = rng.normal(size=(50, 3))
    local, mu = polygon.to_local((p + v)[:, None, :], p, n, v)
    assert np.allclose(local[:, 0, 1], 0.0, atol=1e-12) and np.all(local[:, 0, 0] >= -1e-12)
    assert np.allclose(local[:, 0, 2], mu) and np.allclose(np.hypot(local[:, 0, 0], mu), 1.0)


# --- disks --------------------------------------------------------------------------------------

def test_disk_closed_form_is_exact():
    n_exact = 0
    for minv, c, u, v in cases(48, True):
        if not disk_transformed_above(minv, c, u, v):
            continue
        ref = reference.ltc_integral_disk(minv, c, u, v)
        assert ref.error <= 1e-12 * ref.value
        f = disk.ltc_disk_vector_form_factor(minv, c, u, v)
        assert abs(f[2] - ref.value) <= 1e-10 * ref.value
        if cap_unclipped_at_nodes(f):
            n_exact += 1
            assert abs(disk.ltc_disk_integral(minv, c, u, v) - ref.value) <= 1e-10 * ref.value
    assert n_exact >= 10


def test_disk_horizon_is_the_tabulated_cap():
    for minv, c, u, v in cases(48, False):
        if disk_transformed_above(minv, c, u, v) or np.cross(u, v) @ c < 0:
            continue
        f = disk.ltc_disk_vector_form_factor(minv, c, u, v)
        length = np.linalg.norm(f)
        cap = sphere_table.cap_form_factor(f[2] / length, length) if length > 0 else 0.0
        assert abs(disk.ltc_disk_integral(minv, c, u, v) - cap) <= 0.02 * length


def test_lambert_disk_form_factor():
    """Identity Minv: closed form and brute-force reference against Howell's offset-disk factor."""
    for r, h, a in [(1.0, 1.0, 0.0), (0.5, 2.0, 0.7), (2.0, 0.3, 1.5), (1e-3, 1.0, 0.2)]:
        c = np.array([a, 0.0, h])
        exact = disk_offset_form_factor(r, h, a)
        got = disk.ltc_disk_integral(np.eye(3), c, r * X, r * Y)
        assert got == pytest.approx(exact, rel=1e-11)
        brute = reference.brdf_integral_disk(lambert, Z, c, r * X, r * Y)
        assert brute.value == pytest.approx(exact, rel=1e-11)


def test_disk_one_and_two_sided():
    for minv, c, u, v in cases(6, True):
        one = disk.ltc_disk_integral(minv, c, u, v)
        assert one > 0.0
        assert disk.ltc_disk_integral(minv, c, v, u) == 0.0           # swapped axes: normal flipped
        assert disk.ltc_disk_integral(minv, c, v, u, two_sided=True) == pytest.approx(one, rel=1e-12)


def test_disk_polygon_fallback_converges():
    """Equal-area regular N-gon: same area as the disk, LTC error falls ~N^-2 or faster."""
    c, u, v = np.array([0.2, 0.1, 1.5]), 0.6 * X + 0.1 * Y, 0.4 * Y
    poly = disk.disk_polygon(c, u, v, 8)
    area = 0.5 * np.linalg.norm(polygon.light_normal(poly[None])[0])
    assert area == pytest.approx(np.pi * np.linalg.norm(np.cross(u, v)), rel=1e-12)
    errors = []
    for n in (6, 12, 24, 48):
        err = []
        for minv, cc, uu, vv in cases(8, True):
            if not disk_transformed_above(minv, cc, uu, vv):
                continue
            exact = disk.ltc_disk_vector_form_factor(minv, cc, uu, vv)[2]
            err.append(abs(disk.ltc_disk_integral_polygon(minv, cc, uu, vv, n=n, method="clipped") - exact) / exact)
        errors.append(max(err))
    assert all(later < earlier / 3.0 for earlier, later in zip(errors, errors[1:]))


# --- GGX matrices of the published table (comparison only) -------------------------------------

def test_published_ggx_matrices():
    from rt_lookdev.validation.harness import published_ltc as ltc_anchor
    try:
        ltc1, _ = ltc_anchor.load_anchor()
    except FileNotFoundError:
        pytest.skip("anchor table not present")
    from rt_lookdev.core.ltc import matrix
    rng = np.random.default_rng(RNG_SEED)
    for t, a in [(10, 40), (32, 32), (50, 63), (20, 25)]:
        minv = matrix.unpack_inverse(ltc1[t, a])
        c, u, v = random_light(rng, above=True)
        q = quad(c, u, v)
        ref = reference.ltc_integral_polygon(minv, q, panels=16)
        assert ref.error <= 1e-9 * max(ref.value, 1e-3)
        assert polygon.ltc_quad_integral(minv, q, method="clipped") == pytest.approx(ref.value, rel=1e-8)
        if disk_transformed_above(minv, c, u, v):
            dref = reference.ltc_integral_disk(minv, c, u, v, panels=16)
            assert disk.ltc_disk_vector_form_factor(minv, c, u, v)[2] == pytest.approx(dref.value, rel=1e-8)


# --- stress: no NaN/Inf, dtype kept -------------------------------------------------------------

STRESS_QUADS = {
    "in_light_plane": quad(np.array([3.0, 0.0, 1.0]), X, 0.5 * Z),
    "on_light": quad(np.zeros(3), X, Y),
    "on_light_vertical": quad(np.array([0.0, 0.0, 0.5]), X, Z),
    "on_edge": quad(X, X, Y),
    "corner_at_origin": quad(X + Y, X, Y),
    "below": quad(np.array([0.0, 0.0, -2.0]), X, Y),
    "partly_below": quad(np.array([2.0, 0.0, 0.0]), Y, Z),
    "tiny": quad(np.array([0.3, 0.2, 1.0]), 1e-4 * X, 1e-4 * Y),
    "tiny_far": quad(np.array([0.3, 0.2, 1e4]), 1e-4 * X, 1e-4 * Y),
    "huge": quad(np.array([0.3, 0.2, 1.0]), 1e4 * X, 1e4 * Y),
    "huge_vertical": quad(np.array([3e3, 0.2, 1e4]), 1e4 * X, 1e4 * Z),
    "zero_area": quad(np.array([0.3, 0.2, 1.0]), 0 * X, 0 * Y),
    "collinear": quad(np.array([0.3, 0.2, 1.0]), X, 0 * Y),
    "grazing": quad(np.array([5.0, 0.0, 1e-6]), X, Y),
    "big_disk_over_receiver": quad(np.array([0.0, 0.0, 1e-3]), 1e3 * X, 1e3 * Y),
    "disk_over_receiver": quad(np.array([0.0, 0.0, 1.0]), 3.0 * X, 3.0 * Y),
}

STRESS_MATRICES = {
    "lambert (r = 1)": np.eye(3),
    "mirror at mu = 1 (r = 0)": np.diag([1.0, 1.0, 2e-5]),
    "c0 = c3 = 2e-5": np.diag([2e-5, 1.0, 2e-5]),
    "singular": np.zeros((3, 3)),
    "grazing table cell (t = 63)": np.array([[2.4e-8, 0.0, 0.59], [0.0, 1.0, 0.0], [-0.3, 0.0, 8e-11]]),
}


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
@pytest.mark.parametrize("name", sorted(STRESS_MATRICES))
def test_stress_finite(name, dtype):
    q = np.stack(list(STRESS_QUADS.values())).astype(dtype)
    c, u, v = q.mean(axis=1), (q[:, 1] - q[:, 0]) / 2, (q[:, 3] - q[:, 0]) / 2
    minv = STRESS_MATRICES[name].astype(dtype)
    with np.errstate(over="raise", invalid="raise", divide="raise", under="ignore"):
        results = [polygon.ltc_quad_integral(minv, q, two, method=m) for m in ("clipless", "clipped")
                   for two in (False, True)]
        results += [disk.ltc_disk_integral(minv, c, u, v, two) for two in (False, True)]
        results += [disk.ltc_disk_integral_polygon(minv, c, u, v, n=8, two_sided=two) for two in (False, True)]
    for r in results:
        assert r.dtype == dtype and r.shape == (len(STRESS_QUADS),)
        assert np.all(np.isfinite(r)) and r.min() >= 0.0 and r.max() <= 1.0 + 1e-5


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_stress_frames(dtype):
    """mu = 0 and mu = 1 frames, lights in world space through ``to_local``."""
    n = np.array([[0, 0, 1], [0, 0, 1], [0, 1, 0], [0, 0, -1]], dtype=dtype)
    v = np.array([[0, 0, 1], [1, 0, 0], [0, 1, 0], [0, 1, 0]], dtype=dtype)
    p = np.zeros((4, 3), dtype=dtype)
    corners = np.broadcast_to(quad(np.array([0.2, 0.1, 1.0]), X, Y).astype(dtype), (4, 4, 3))
    with np.errstate(over="raise", invalid="raise", divide="raise", under="ignore"):
        local, mu = polygon.to_local(corners, p, n, v)
        out = polygon.ltc_quad_integral(np.diag([1.0, 1.0, 0.3]).astype(dtype), local, two_sided=True)
    assert local.dtype == dtype and out.dtype == dtype and np.all(np.isfinite(out))
    assert np.allclose(mu, [1, 0, 1, 0])


@pytest.mark.parametrize("dtype", [np.float64, np.float32])
def test_large_disk_centred_over_receiver(dtype):
    """ltc_code#9 / Blender #67060: a circular cone (double root) must not give NaN or a black spot."""
    radius = np.array([1.0, 10.0, 1e3, 1e4], dtype=dtype)
    h = np.array([1.0, 1e-3, 1.0, 1e-2], dtype=dtype)
    c = np.stack([np.zeros_like(h), np.zeros_like(h), h], axis=-1)
    u = radius[:, None] * X.astype(dtype)
    v = radius[:, None] * Y.astype(dtype)
    exact = radius.astype(np.float64) ** 2 / (radius.astype(np.float64) ** 2 + h.astype(np.float64) ** 2)
    with np.errstate(over="raise", invalid="raise", divide="raise", under="ignore"):
        for minv in (np.eye(3), np.diag([1.0, 1.0, 2e-5]), np.diag([0.4, 0.4, 1.0])):
            got = disk.ltc_disk_integral(minv.astype(dtype), c, u, v)
            assert got.dtype == dtype and np.all(np.isfinite(got))
            if minv[2, 2] == 1.0 and minv[0, 0] == 1.0:
                assert np.allclose(got, exact, rtol=1e-12 if dtype == np.float64 else 1e-6, atol=0)
            assert np.all(got > 0.0)


def test_float32_small_lights_agree_with_float64():
    """Small lights in float32: the cancellation-free vector form factor keeps the error ~1e-7/size
    (the plain sum of edge vectors is ~1e-7/size^2: 175% at 1e-3 scale); the disk is scale free."""
    cs = cases(60, True) + cases(60, False)
    minv = np.stack([x[0] for x in cs])
    c, u, v = (np.stack([x[i] for x in cs]) for i in (1, 2, 3))
    for scale in (1e-2, 1e-3):
        smallest_angle = 0.1 * scale / 3.0          # semi-axes >= 0.1 scale, distance <= 3
        bound = 1e-6 / smallest_angle               # ~10 float32 epsilons / angular size
        q = np.stack([quad(*args) for args in zip(c, u * scale, v * scale)])
        for method in ("clipless", "clipped"):
            f64 = polygon.ltc_quad_integral(minv, q, method=method)
            f32 = polygon.ltc_quad_integral(minv.astype(np.float32), q.astype(np.float32), method=method)
            lit = f64 > 1e-3 * f64.max()
            assert np.max(np.abs(f32[lit] - f64[lit]) / f64[lit]) <= bound
        d64 = disk.ltc_disk_integral(minv, c, u * scale, v * scale)
        d32 = disk.ltc_disk_integral(*(a.astype(np.float32) for a in (minv, c, u * scale, v * scale)))
        lit = d64 > 1e-3 * d64.max()
        assert np.max(np.abs(d32[lit] - d64[lit]) / d64[lit]) <= 2e-5
