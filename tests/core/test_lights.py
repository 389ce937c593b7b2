"""core/lights.py: Blender light geometry and units, numpy and traced IR alike.

The Cycles side (the units themselves) is checked by renders in tests/blender/test_light_units.py.
"""
from __future__ import annotations

import math

import numpy as np
import pytest

from rt_lookdev.core import lights
from rt_lookdev.core.falloff import MIN_DISTANCE
from rt_lookdev.core.ir import trace
from rt_lookdev.core.ir.expr import FLOAT
from rt_lookdev.core.ir.numpy_backend import evaluate, node_count

N = 257
MAX_NODES = 140


def _unit_quaternions(rng, n):
    q = rng.normal(size=(n, 4))
    return q / np.linalg.norm(q, axis=-1, keepdims=True)


def _matrix(q):
    """Rotation matrix of unit quaternions (w, x, y, z) (..., 4) -> (..., 3, 3) (the textbook form)."""
    w, x, y, z = np.moveaxis(q, -1, 0)
    return np.stack([
        np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], -1),
        np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], -1),
        np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], -1),
    ], -2)


def _random_inputs(fn, rng, n=N):
    """Driver-like values for every input of a NodeFunction."""
    q = _unit_quaternions(rng, n)
    values = {}
    for name, sock in fn.input_sockets.items():
        if name.startswith("Rotation "):
            values[name] = q[:, "WXYZ".index(name[-1])]
        elif name.startswith("Scale "):
            values[name] = rng.uniform(0.2, 3.0, n)
        elif name.startswith("Location "):
            values[name] = rng.uniform(-3, 3, n)
        elif name == "Position":
            values[name] = rng.uniform(-3, 3, (n, 3))
        elif name.startswith("Color "):
            values[name] = rng.uniform(0, 1, n)
        elif name == "Spot Size":
            values[name] = rng.uniform(0.05, np.pi, n)
        elif name == "Spot Blend":
            values[name] = rng.uniform(0, 1, n)
        elif name in ("Cone Inner", "Cone Outer"):
            values[name] = rng.uniform(0.05, np.pi, n)
        elif name == "Range":
            values[name] = rng.uniform(0.0, 8.0, n)
        elif name in ("Size", "Size Y"):
            values[name] = rng.uniform(0.01, 4, n)
        else:                                   # Power, Strength
            values[name] = rng.uniform(0, 2000, n)
    return values


ALL_DATA = lights.NODE_FUNCTIONS + lights.CONTROL_FUNCTIONS


@pytest.mark.parametrize("fn", ALL_DATA, ids=lambda f: f.name)
def test_numpy_and_traced_ir_agree(fn):
    rng = np.random.default_rng(7)
    values = _random_inputs(fn, rng)
    direct = fn(**values)
    body = fn.function
    names = list(body.outputs)
    traced = evaluate(tuple(body.outputs[k] for k in names), values, dtype=np.float64)
    for name, got in zip(names, traced):
        ref = np.asarray(direct[name], np.float64)
        scale = np.maximum(np.abs(ref).max(), 1e-30)
        np.testing.assert_allclose(got, ref, rtol=1e-6, atol=1e-6 * scale, err_msg=f"{fn.name}: {name}")


@pytest.mark.parametrize("fn", ALL_DATA, ids=lambda f: f.name)
def test_call_node_and_interface(fn):
    """A call from another graph gives the body's values; sockets are as documented; <= 140 nodes."""
    kinds = fn.input_kinds
    graph, out = trace(lambda **kw: fn(**kw), kinds)
    assert set(out) == set(fn.output_sockets)
    rng = np.random.default_rng(3)
    values = _random_inputs(fn, rng, 16)
    names = list(out)
    via_call = evaluate(tuple(out[k] for k in names), values, dtype=np.float64)
    direct = fn(**values)
    for name, got in zip(names, via_call):
        np.testing.assert_allclose(got, direct[name], rtol=1e-6, atol=1e-9)
    count = node_count(tuple(fn.function.outputs.values()))
    print(f"{fn.name}: {count} nodes")
    assert count <= MAX_NODES
    for sock in list(fn.input_sockets.values()) + list(fn.output_sockets.values()):
        assert sock.description
    assert all(k == FLOAT for n, k in kinds.items() if n != "Position")


def test_interfaces_are_the_driver_values():
    loc = [f"Location {a}" for a in "XYZ"]
    rot = [f"Rotation {a}" for a in "WXYZ"]
    scl = [f"Scale {a}" for a in "XYZ"]
    col = [f"Color {c}" for c in "RGB"]
    expect = {
        "RTL Area Light Quad": (loc + rot + scl + ["Power"] + col + ["Size", "Size Y"],
                                ["p0", "p1", "p2", "p3", "Center", "Radiance"]),
        "RTL Area Light Disk": (loc + rot + scl + ["Power"] + col + ["Size", "Size Y"],
                                ["Center", "Axis U", "Axis V", "Radiance"]),
        "RTL Point Light": (loc + ["Power"] + col + ["Position"], ["L", "Irradiance"]),
        "RTL Spot Light": (loc + rot + scl + ["Power"] + col + ["Spot Size", "Spot Blend", "Position"],
                           ["L", "Irradiance"]),
        "RTL Sun Light": (rot + ["Strength"] + col, ["L", "Irradiance"]),
        "RTL Quad Spot Fallback Light": (loc + rot + scl + ["Power"] + col + ["Size", "Size Y", "Cone Inner",
                                                                            "Cone Outer", "Position"],
                                         ["L", "Irradiance"]),
    }
    assert {f.name for f in lights.NODE_FUNCTIONS} == set(expect)
    for f in lights.NODE_FUNCTIONS:
        ins, outs = expect[f.name]
        assert list(f.input_sockets) == ins, f.name
        assert list(f.output_sockets) == outs, f.name


# --- transforms --------------------------------------------------------------------------------

def test_quat_rotate_matches_rotation_matrix():
    rng = np.random.default_rng(1)
    q = _unit_quaternions(rng, 500)
    v = rng.normal(size=(500, 3))
    got = lights.quat_rotate(q[:, 0], q[:, 1], q[:, 2], q[:, 3], v)
    ref = np.einsum("nij,nj->ni", _matrix(q), v)
    np.testing.assert_allclose(got, ref, rtol=0, atol=1e-12)
    # known case: 90 degrees about +Z takes +X to +Y
    c = math.sqrt(0.5)
    np.testing.assert_allclose(lights.quat_rotate(c, 0.0, 0.0, c, np.array([1.0, 0, 0])), [0, 1, 0], atol=1e-15)


def test_light_frame_columns_are_rotation_times_scale():
    rng = np.random.default_rng(2)
    q = _unit_quaternions(rng, 100)
    s = rng.uniform(0.1, 3, (100, 3))
    loc = rng.normal(size=(100, 3))
    origin, x, y, z = lights.light_frame(loc, *q.T, *s.T)
    m = _matrix(q) * s[:, None, :]
    np.testing.assert_allclose(origin, loc)
    for i, axis in enumerate((x, y, z)):
        np.testing.assert_allclose(axis, m[..., i], atol=1e-12)


# --- area lights ---------------------------------------------------------------------------------

def _area_args(rng, n):
    q = _unit_quaternions(rng, n)
    return dict(location=rng.normal(size=(n, 3)), w=q[:, 0], x=q[:, 1], y=q[:, 2], z=q[:, 3],
                scale_x=rng.uniform(0.1, 3, n), scale_y=rng.uniform(0.1, 3, n), scale_z=rng.uniform(0.1, 3, n),
                power=rng.uniform(1, 1000, n), color=rng.uniform(0, 1, (n, 3)),
                size=rng.uniform(0.01, 5, n), size_y=rng.uniform(0.01, 5, n))


def test_quad_corners_area_winding_and_flux():
    rng = np.random.default_rng(4)
    a = _area_args(rng, 200)
    p0, p1, p2, p3, radiance = lights.area_light_quad(**a)
    _, _, _, z = lights.light_frame(a["location"], a["w"], a["x"], a["y"], a["z"],
                                    a["scale_x"], a["scale_y"], a["scale_z"])
    np.testing.assert_allclose(p0 + p2, p1 + p3, atol=1e-12)                  # a parallelogram
    np.testing.assert_allclose((p0 + p1 + p2 + p3) / 4, a["location"], atol=1e-12)
    normal = np.cross(p1 - p0, p3 - p0)                                        # LTC convention
    area = np.linalg.norm(normal, axis=-1)
    np.testing.assert_allclose(area, a["scale_x"] * a["size"] * a["scale_y"] * a["size_y"], rtol=1e-12)
    np.testing.assert_allclose(np.cross(p1 - p0, p2 - p1), normal, atol=1e-12)  # convex, same turn
    assert (np.einsum("ni,ni->n", normal, z) > 0).all()     # away from the lit side (it emits along -Z)
    # the flux pi L A of a Lambertian one-sided emitter is the power (times colour)
    np.testing.assert_allclose(np.pi * radiance * area[:, None], a["power"][:, None] * a["color"], rtol=1e-12)


def test_disk_axes_area_winding_and_flux():
    rng = np.random.default_rng(5)
    a = _area_args(rng, 200)
    center, u, v, radiance = lights.area_light_disk(**a)
    _, x, y, z = lights.light_frame(a["location"], a["w"], a["x"], a["y"], a["z"],
                                    a["scale_x"], a["scale_y"], a["scale_z"])
    np.testing.assert_allclose(center, a["location"])
    np.testing.assert_allclose(u, x * (0.5 * a["size"])[:, None], atol=1e-12)
    np.testing.assert_allclose(v, y * (0.5 * a["size_y"])[:, None], atol=1e-12)
    normal = np.cross(u, v)
    assert (np.einsum("ni,ni->n", normal, z) > 0).all()
    area = np.pi * np.linalg.norm(normal, axis=-1)
    np.testing.assert_allclose(np.pi * radiance * area[:, None], a["power"][:, None] * a["color"], rtol=1e-12)


@pytest.mark.parametrize("shape", ["SQUARE", "RECTANGLE", "DISK", "ELLIPSE"])
def test_area_light_shapes(shape):
    """SQUARE and DISK use ``size`` for both extents, as Cycles (blender/light.cpp)."""
    out = lights.area_light(shape, np.zeros(3), 1.0, 0.0, 0.0, 0.0, 2.0, 1.0, 1.0, 100.0, np.ones(3), 1.0, 0.5)
    size_y = 1.0 if shape in ("SQUARE", "DISK") else 0.5
    area = 2.0 * size_y * (np.pi / 4 if shape in ("DISK", "ELLIPSE") else 1.0)
    np.testing.assert_allclose(out[-1], 100.0 / (np.pi * area) * np.ones(3), rtol=1e-12)
    with pytest.raises(ValueError):
        lights.area_light("TRIANGLE", np.zeros(3), 1, 0, 0, 0, 1, 1, 1, 1, np.ones(3), 1, 1)


def _degenerate_values(fn):
    v = {name: np.float32(s.default if not isinstance(s.default, tuple) else 0.0)
         for name, s in fn.input_sockets.items()}
    if "Position" in v:
        v["Position"] = np.zeros(3, np.float32)
    return v


@pytest.mark.parametrize("fn", [lights.AREA_LIGHT_QUAD, lights.AREA_LIGHT_DISK], ids=lambda f: f.name)
@pytest.mark.parametrize("zero", ["Size", "Size Y", "Scale X", "Scale Y", "tiny"])
def test_degenerate_area_lights_give_zero_radiance(fn, zero):
    v = _degenerate_values(fn)
    if zero == "tiny":
        v["Size"] = v["Size Y"] = np.float32(1e-12)
    else:
        v[zero] = np.float32(0.0)
    body = fn.function
    for out in (fn(**v), dict(zip(body.outputs, evaluate(tuple(body.outputs.values()), v, np.float32)))):
        for name, value in out.items():
            assert np.isfinite(value).all(), (zero, name)
        np.testing.assert_array_equal(out["Radiance"], 0.0)


# --- point, spot, sun --------------------------------------------------------------------------

def test_point_light_inverse_square_and_guard():
    loc = np.array([0.5, -1.0, 2.0])
    color = np.array([1.0, 0.5, 0.25])
    d = np.array([0.3, 1.0, 4.0])
    p = loc - d[:, None] * np.array([0.0, 0.6, 0.8])
    l, e = lights.point_light_incidence(p, loc, 100.0, color)
    np.testing.assert_allclose(l, np.broadcast_to([0.0, 0.6, 0.8], l.shape), atol=1e-12)
    np.testing.assert_allclose(e, 100.0 / (4 * np.pi) / d[:, None] ** 2 * color, rtol=1e-12)
    # at (and within 1 cm of) the light: finite, clamped to the 1 cm value
    l0, e0 = lights.point_light_incidence(loc, loc, 100.0, color)
    np.testing.assert_array_equal(l0, 0.0)
    np.testing.assert_allclose(e0, 100.0 / (4 * np.pi) / MIN_DISTANCE ** 2 * color)
    g = lights.POINT_LIGHT.function
    v = {"Location X": 0.0, "Location Y": 0.0, "Location Z": 0.0, "Power": 1e6, "Color R": 1.0, "Color G": 1.0,
         "Color B": 1.0, "Position": np.zeros(3)}
    for value in evaluate(tuple(g.outputs.values()), v, np.float32):
        assert np.isfinite(value).all()


def test_spot_attenuation_is_cycles_smoothstep():
    size, blend = np.radians(60.0), 0.4
    cos_half = np.cos(size / 2)
    inner = cos_half + blend * (1 - cos_half)
    c = np.array([cos_half - 0.01, cos_half, 0.5 * (cos_half + inner), inner, 1.0])
    np.testing.assert_allclose(lights.spot_attenuation(c, size, blend), [0, 0, 0.5, 1, 1], atol=1e-12)
    t = 0.25
    np.testing.assert_allclose(lights.spot_attenuation(cos_half + t * (inner - cos_half), size, blend),
                               3 * t * t - 2 * t ** 3, rtol=1e-12)
    # blend 0: a hard edge, finite in float32 too
    hard = lights.spot_attenuation(np.float32([cos_half - 1e-4, cos_half, cos_half + 1e-4]), np.float32(size),
                                   np.float32(0.0))
    np.testing.assert_array_equal(hard, [0, 0, 1])


def test_spot_light_cone_in_local_frame():
    """Identity rotation: the spot points along -Z; inside its cone it is the point light."""
    loc = np.array([0.0, 0.0, 2.0])
    p = np.array([[0.0, 0.0, 0.0], [0.3, 0.0, 0.0], [3.0, 0.0, 0.0], [0.0, 0.0, 4.0]])
    l, e = lights.spot_light_incidence(p, loc, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 50.0, np.ones(3),
                                       np.radians(45.0), 0.1)
    lp, ep = lights.point_light_incidence(p, loc, 50.0, np.ones(3))
    np.testing.assert_allclose(l, lp)
    np.testing.assert_allclose(e[:2], ep[:2])
    np.testing.assert_array_equal(e[2:], 0.0)            # outside the cone, and behind the light
    # a non-uniform scale makes the cone elliptical (Cycles measures the angle in the local frame)
    q = (1.0, 0.0, 0.0, 0.0)
    px = np.array([[0.9, 0.0, 0.0]])
    py = np.array([[0.0, 0.9, 0.0]])
    args = (*q, 2.0, 1.0, 1.0, 50.0, np.ones(3), np.radians(45.0), 0.0)
    assert lights.spot_light_incidence(px, loc, *args)[1].max() > 0      # x/2: inside
    assert lights.spot_light_incidence(py, loc, *args)[1].max() == 0     # y: outside
    # zero scale: finite
    _, e0 = lights.spot_light_incidence(p, loc, *q, 0.0, 0.0, 0.0, 50.0, np.ones(3), 1.0, 0.0)
    assert np.isfinite(e0).all()


def test_sun_direction_is_local_z():
    rng = np.random.default_rng(6)
    q = _unit_quaternions(rng, 50)
    color = rng.uniform(0, 1, (50, 3))
    l, e = lights.sun_light_incidence(*q.T, 3.0, color)
    np.testing.assert_allclose(l, _matrix(q)[..., 2], atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(l, axis=-1), 1.0)
    np.testing.assert_allclose(e, 3.0 * color)


@pytest.mark.parametrize("fn", ALL_DATA, ids=lambda f: f.name)
def test_float32_extremes_are_finite(fn):
    """Zero everything, then huge and tiny values: no NaN or Inf in either backend."""
    body = fn.function
    for fill in (0.0, 1e-30, 1e4):
        v = {name: np.float32(fill) for name in fn.input_sockets}
        if "Position" in v:
            v["Position"] = np.full(3, fill, np.float32)
        for value in evaluate(tuple(body.outputs.values()), v, np.float32):
            assert np.isfinite(value).all(), (fn.name, fill)
        with np.errstate(all="ignore"):
            for value in fn(**v).values():
                assert np.isfinite(value).all(), (fn.name, fill)


# --- the talk's light controls (issue 17, item 4) --------------------------------------------------------------

def test_kinds_carry_their_options_in_one_order():
    assert lights.split_kind("quad+cone+range") == ("quad", ("cone", "range"))
    assert lights.kind_name("quad", ("range", "cone")) == "quad+cone+range"
    assert lights.kind_name("sun", ("range",)) == "sun"                     # options a kind does not take drop
    assert lights.kind_name("quad_spot", ("cone", "range")) == "quad_spot+range"
    for bad in ("quad+range+cone", "sun+range", "point+cone", "quad+range+range", "lamp"):
        with pytest.raises(ValueError):
            lights.split_kind(bad)
    assert lights.light_data("quad") is lights.AREA_LIGHT_QUAD
    assert {"Cone Inner", "Cone Outer", "Range", "Position"} <= set(lights.light_data("quad+cone+range").input_sockets)
    assert lights.driver_sources("quad+range", "SQUARE")["Range"] == ("data", '["rtl_range"]')


def _quad_params(height=3.0, outer=100.0, inner=90.0, size=1.0, size_y=0.6):
    return {"Location X": 0.0, "Location Y": 0.0, "Location Z": height, "Rotation W": 1.0, "Rotation X": 0.0,
            "Rotation Y": 0.0, "Rotation Z": 0.0, "Scale X": 1.0, "Scale Y": 1.0, "Scale Z": 1.0, "Power": 100.0,
            "Color R": 1.0, "Color G": 1.0, "Color B": 1.0, "Size": size, "Size Y": size_y,
            "Cone Inner": math.radians(inner), "Cone Outer": math.radians(outer), "Range": 0.0}


def test_the_projector_apex_sits_behind_the_light_so_the_cone_fits_around_it():
    p = _quad_params()
    loc = np.array([0.0, 0.0, 3.0])
    apex, axis = lights.projector_apex(loc, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 0.6, math.radians(100.0), "quad")
    np.testing.assert_allclose(axis, [0.0, 0.0, -1.0], atol=1e-12)            # a light emits along its -Z
    diagonal = math.hypot(1.0, 0.6)
    assert apex[2] - 3.0 == pytest.approx(0.5 * diagonal / math.tan(math.radians(50.0)))
    # the quad's corners lie on the outer cone: the cone fits around the light
    corner = np.array([0.5, 0.3, 3.0])
    cos_corner = np.dot(_unit(corner - apex), axis)
    assert cos_corner == pytest.approx(math.cos(math.radians(50.0)))
    factor = lights.control_factor("quad+cone", np.array([[0.0, 0.0, 0.0], [0.0, 5.0, 2.9]]), p)
    np.testing.assert_allclose(factor, [1.0, 0.0])                             # on the axis / outside the cone


def _unit(v):
    return v / np.linalg.norm(v)


def test_range_window_reaches_zero_at_the_range():
    p = dict(_quad_params(), Range=4.0)
    pos = np.array([[0.0, 0.0, 3.0 - d] for d in (0.0, 2.0, 3.99, 4.0, 6.0)])
    f = lights.control_factor("quad+range", pos, p)
    np.testing.assert_allclose(f, [1.0, (1 - (2 / 4) ** 4) ** 2, (1 - (3.99 / 4) ** 4) ** 2, 0.0, 0.0], atol=1e-12)


def test_the_fallback_is_the_quads_far_field():
    """The quad-to-spot fallback is a point at the quad's centre of the quad's Lambertian intensity P cos / pi: far
    away (100 light sizes) its irradiance is the quad's exact form factor, cone falloff included identically."""
    from rt_lookdev.core.ltc import polygon

    rng = np.random.default_rng(5)
    p = _quad_params(outer=150.0, inner=140.0)
    dirs = rng.normal(size=(64, 3))
    dirs[:, 2] = -np.abs(dirs[:, 2]) - 0.6
    pos = np.array([0.0, 0.0, 3.0]) + 100.0 * dirs / np.linalg.norm(dirs, axis=-1, keepdims=True)
    spot = lights.light_data("quad_spot")(**{k: v for k, v in p.items() if k != "Range"}, Position=pos)
    quad = lights.AREA_LIGHT_QUAD(**{k: v for k, v in p.items() if k in lights.AREA_LIGHT_QUAD.input_sockets})
    corners = np.stack([quad[f"p{i}"] for i in range(4)])
    cone = lights.control_factor("quad+cone", pos, p)
    for k in range(len(pos)):
        normal = spot["L"][k]                                  # a surface facing the light's centre
        rel = corners - pos[k]
        frame = polygon.local_frame(normal, _unit(normal + np.array([0.3, -0.2, 0.1])))
        local = np.stack([polygon.frame_coordinates(frame, q) for q in rel])
        form_factor = polygon.ltc_polygon_integral(np.eye(3), local, two_sided=True, method="clipped")
        irradiance_quad = np.pi * form_factor * quad["Radiance"][0] * cone[k]
        assert spot["Irradiance"][k][0] == pytest.approx(irradiance_quad, rel=2e-3, abs=1e-12)
