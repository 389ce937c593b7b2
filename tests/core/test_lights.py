"""core/lights.py: Blender light geometry and units, numpy and traced IR alike.

The Cycles side (the units themselves) is checked by renders in tests/blender/test_light_units.py.
"""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from rt_lookdev.core import lights
from rt_lookdev.core.falloff import MIN_DISTANCE
from rt_lookdev.core.ir import trace
from rt_lookdev.core.ir.expr import FLOAT
from rt_lookdev.core.ir.numpy_backend import evaluate, node_count

N = 257
MAX_NODES = 140
#: A light with spread carries the clamp to the cone and the cone's outputs (core/light_spread.py; each lobe weights
#: its integral by the cone).
MAX_NODES_SPREAD = 700


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
        elif name == "Normal":
            normal = rng.normal(size=(n, 3))
            values[name] = normal / np.linalg.norm(normal, axis=-1, keepdims=True)
        elif name == "Exposure":
            values[name] = rng.uniform(-3, 3, n)
        elif name in ("Normalize", "Soft Falloff"):
            values[name] = (rng.uniform(0, 1, n) < 0.5).astype(np.float64)
        elif name == "Radius":
            values[name] = rng.uniform(0.0, 0.8, n)
        elif name in ("Angle", "Spread"):
            values[name] = rng.uniform(0.0, np.pi, n)
        elif name == "Excluded":
            values[name] = rng.uniform(0, 1, n)
        elif name == "Determinant":
            values[name] = rng.uniform(0.1, 5, n) * rng.choice([-1.0, 1.0], n)
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
    assert count <= (MAX_NODES_SPREAD if "Spread" in fn.input_sockets else MAX_NODES)
    for sock in list(fn.input_sockets.values()) + list(fn.output_sockets.values()):
        assert sock.description
    assert all(k == FLOAT for n, k in kinds.items() if n not in lights.SHADING_POINT_INPUTS)


def test_interfaces_are_the_driver_values():
    loc = [f"Location {a}" for a in "XYZ"]
    rot = [f"Rotation {a}" for a in "WXYZ"]
    scl = [f"Scale {a}" for a in "XYZ"] + ["Determinant"]
    col = [f"Color {c}" for c in "RGB"]
    units = ["Exposure", "Normalize"]
    sphere = ["Radius", "Soft Falloff"]
    disk = ["Center", "Axis U", "Axis V", "Radiance"]
    expect = {
        "RTL Area Light Quad": (loc + rot + scl + ["Power"] + col + ["Size", "Size Y"] + units,
                                ["p0", "p1", "p2", "p3", "Center", "Radiance"]),
        "RTL Area Light Disk": (loc + rot + scl + ["Power"] + col + ["Size", "Size Y"] + units, disk),
        "RTL Point Light": (loc + ["Power"] + col + units + ["Position"], ["L", "Irradiance"]),
        "RTL Spot Light": (loc + rot + scl + ["Power"] + col + ["Spot Size", "Spot Blend"] + units + ["Position"],
                           ["L", "Irradiance"]),
        "RTL Sun Light": (rot + scl + ["Strength"] + col + units, ["L", "Irradiance"]),
        "RTL Quad Spot Fallback Light": (loc + rot + scl + ["Power"] + col + ["Size", "Size Y", "Cone Inner",
                                                                            "Cone Outer"] + units + ["Position"],
                                         ["L", "Irradiance"]),
        "RTL Sphere Light": (loc + ["Power"] + col + sphere + units + ["Position"], disk),
        "RTL Spot Sphere Light": (loc + rot + scl + ["Power"] + col + sphere + ["Spot Size", "Spot Blend"] + units
                                  + ["Position"], disk),
        "RTL Sun Disk Light": (rot + scl + ["Strength"] + col + ["Angle"] + units + ["Position"], disk),
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
         "Color B": 1.0, "Exposure": 0.0, "Normalize": 1.0, "Position": np.zeros(3)}
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
    l, e = lights.sun_light_incidence(*q.T, 1.0, 3.0, color)
    np.testing.assert_allclose(l, _matrix(q)[..., 2], atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(l, axis=-1), 1.0)
    np.testing.assert_allclose(e, 3.0 * color)


@pytest.mark.parametrize("fn", ALL_DATA, ids=lambda f: f.name)
def test_float32_extremes_are_finite(fn):
    """Zero everything, then huge and tiny values: no NaN or Inf in either backend."""
    body = fn.function
    for fill in (0.0, 1e-30, 1e4):
        v = {name: np.float32(fill) for name in fn.input_sockets}
        for name in lights.SHADING_POINT_INPUTS:
            if name in v:
                v[name] = np.full(3, fill, np.float32)
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
            "Cone Inner": math.radians(inner), "Cone Outer": math.radians(outer), "Range": 0.0, "Exposure": 0.0,
            "Normalize": 1.0, "Determinant": 1.0}


def test_the_projector_apex_sits_behind_the_light_so_the_cone_fits_around_it():
    p = _quad_params()
    loc = np.array([0.0, 0.0, 3.0])
    apex, axis = lights.projector_apex(loc, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0, 0.6, math.radians(100.0), "quad")
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


# --- Blender's light model (issue 27): mirrors, units, sphere lights, suns with an angle, spread, linking -------

def _decomposed(rng, n, mirror):
    """World matrices M = R diag(s) with the mirror ``mirror`` (scale signs), and what Blender's TRANSFORMS drivers
    deliver for them (measured, core/lights.py "Mirrors"): the columns' lengths as the scale, the rotation of
    sign(det) M, and the determinant (the "Determinant" driver)."""
    q = _unit_quaternions(rng, n)
    s = rng.uniform(0.3, 2.0, (n, 3)) * np.asarray(mirror, float)
    m = _matrix(q) * s[:, None, :]
    det = np.linalg.det(m)
    scale = np.linalg.norm(m, axis=1)
    rot = m / scale[:, None, :] * np.where(det < 0, -1.0, 1.0)[:, None, None]
    assert np.allclose(np.linalg.det(rot), 1.0)
    # the rotation matrix back to a quaternion (w >= 0 is fine: either sign is the same rotation)
    w = 0.5 * np.sqrt(np.maximum(1.0 + rot[:, 0, 0] + rot[:, 1, 1] + rot[:, 2, 2], 1e-12))
    x = (rot[:, 2, 1] - rot[:, 1, 2]) / (4 * w)
    y = (rot[:, 0, 2] - rot[:, 2, 0]) / (4 * w)
    z = (rot[:, 1, 0] - rot[:, 0, 1]) / (4 * w)
    return m, np.stack([w, x, y, z], -1), scale, det


@pytest.mark.parametrize("mirror", [(1, 1, 1), (-1, 1, 1), (1, -1, 1), (1, 1, -1), (-1, -1, -1), (-1, -1, 1)])
def test_mirrored_lights_emit_along_minus_their_matrix_z(mirror):
    """Cycles emits area, spot and sun light along minus the world matrix's third column, whatever its handedness
    (measured; module docstring "Mirrors"): the quad's winding, the disk's axes, the sun's direction and the
    projector's axis follow that column for every mirror of the matrix, as the drivers decompose it."""
    rng = np.random.default_rng(11)
    m, q, scale, det = _decomposed(rng, 40, mirror)
    col2 = m[..., 2] / np.linalg.norm(m[..., 2], axis=-1, keepdims=True)
    rot = (q[:, 0], q[:, 1], q[:, 2], q[:, 3])
    loc = rng.normal(size=(40, 3))
    origin, x, y, z = lights.light_frame(loc, *rot, *scale.T, det)
    np.testing.assert_allclose(np.stack([x, y, z], -1), m, atol=1e-9)              # the world matrix again
    p0, p1, p2, p3, _ = lights.area_light_quad(loc, *rot, *scale.T, 10.0, np.ones(3), 1.0, 0.5, determinant=det)
    # the same corners as the matrix's (a mirror reverses their order), wound about its Z column
    np.testing.assert_allclose(sorted(map(tuple, np.round([p0[0], p1[0], p2[0], p3[0]], 9))),
                               sorted(map(tuple, np.round([loc[0] + sx * m[0, :, 0] / 2 + sy * m[0, :, 1] / 4
                                                           for sx in (-1, 1) for sy in (-1, 1)], 9))), atol=1e-8)
    assert (np.einsum("ni,ni->n", np.cross(p1 - p0, p3 - p0), col2) > 0).all()
    _, u, v, _ = lights.area_light_disk(loc, *rot, *scale.T, 10.0, np.ones(3), 1.0, 1.0, determinant=det)
    assert (np.einsum("ni,ni->n", np.cross(u, v), col2) > 0).all()
    l, _ = lights.sun_light_incidence(*rot, scale[:, 2], 1.0, np.ones(3), determinant=det)
    np.testing.assert_allclose(l, col2, atol=1e-9)
    _, axis = lights.projector_apex(loc, *rot, *scale.T, 1.0, 1.0, 1.0, "quad", det)
    np.testing.assert_allclose(axis, -col2, atol=1e-9)
    # the spot's cone: the cosine to the axis is that of minus the column, in the (mirrored) local frame
    target = loc - 2.0 * col2
    c = lights.spot_cosine(target, loc, *rot, *scale.T, det)
    np.testing.assert_allclose(c, 1.0, atol=1e-9)


def _cap_irradiance(position, centre, sin_half):
    """Irradiance / L of a uniform cone of half-angle asin(sin_half) towards ``centre`` on a surface with normal +Z,
    the cone above the horizon: pi sin^2 cos(theta) (the spherical cap's vector form factor)."""
    d = centre - position
    return np.pi * sin_half ** 2 * d[..., 2] / np.linalg.norm(d, axis=-1)


def _lambert_of(light_out, position):
    """Irradiance / radiance of a DiskLight output on a surface with normal +Z, through the exact disk integral."""
    from rt_lookdev.core.ltc import reference

    out = []
    for k in range(len(position)):
        rel_c = light_out["Center"][k] - position[k]
        x, w = reference.disk_rule(rel_c, light_out["Axis U"][k], light_out["Axis V"][k], np.array([0, 0, 1.0]), 8, 8)
        normal = np.cross(light_out["Axis U"][k], light_out["Axis V"][k])
        normal /= np.linalg.norm(normal)
        r = np.linalg.norm(x, axis=-1)
        out.append(np.sum(w * np.abs(x @ normal) / r ** 3 * np.maximum(x[:, 2], 0) / r))
    return np.array(out)


@pytest.mark.parametrize("soft", [1.0, 0.0])
def test_sphere_light_is_the_disk_it_subtends(soft):
    """A point light of radius r: with Soft Falloff a disk of radius r at its centre facing the point (tan a = r/d),
    without it the sphere's visible cap (sin a = r/d); radiance P / (4 pi^2 r^2) (Cycles; measured against Cycles in
    tests/blender/test_light_units.py)."""
    rng = np.random.default_rng(12)
    position = np.concatenate([rng.uniform(-1.5, 1.5, (12, 2)), np.zeros((12, 1))], -1)
    loc, r, power = np.array([0.3, 0.2, 0.7]), 0.25, 100.0
    out = dict(zip(("Center", "Axis U", "Axis V", "Radiance"),
                   lights.sphere_light(position, loc, power, np.ones(3), r, soft)))
    np.testing.assert_allclose(out["Radiance"], power / (4 * np.pi ** 2 * r * r), rtol=1e-12)
    d = np.linalg.norm(loc - position, axis=-1)
    sin_half = r / np.sqrt(d * d + r * r) if soft else r / d
    np.testing.assert_allclose(_lambert_of(out, position), _cap_irradiance(position, loc, sin_half), rtol=1e-6)
    # the disk faces the point: its normal (axis_u x axis_v) points from the point to the light
    n = np.cross(out["Axis U"], out["Axis V"])
    np.testing.assert_allclose(n / np.linalg.norm(n, axis=-1, keepdims=True),
                               (loc - position) / d[:, None], atol=1e-12)
    # inside the sphere and at its centre: finite, the largest disk
    inner = lights.sphere_light(np.array([loc, loc + 0.1]), loc, power, np.ones(3), r, soft)
    assert all(np.isfinite(v).all() for v in inner)


def test_sun_with_an_angle_is_a_cone_of_its_strength():
    """A sun of angle a: the uniform cone of half-angle a/2 with radiance S / (pi sin^2(a/2)), so its irradiance at
    normal incidence is S, and on a tilted surface S cos(theta) while the cone is above the horizon."""
    rng = np.random.default_rng(13)
    q = _unit_quaternions(rng, 20)
    q[:, 1:] *= 0.3                                    # suns above the horizon of +Z
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    angle = np.radians(10.0)
    position = rng.uniform(-5, 5, (20, 3))
    out = dict(zip(("Center", "Axis U", "Axis V", "Radiance"),
                   lights.sun_disk_light(position, *q.T, 1.0, 3.0, np.ones(3), angle)))
    l, _ = lights.sun_light_incidence(*q.T, 1.0, 3.0, np.ones(3))
    np.testing.assert_allclose(out["Radiance"], 3.0 / (np.pi * np.sin(angle / 2) ** 2), rtol=1e-12)
    keep = l[:, 2] > np.sin(angle / 2) + 0.05
    got = _lambert_of({k: v[keep] for k, v in out.items() if k != "Radiance"}, position[keep]) * out["Radiance"][0]
    np.testing.assert_allclose(got, 3.0 * l[keep, 2], rtol=1e-6)


def test_units_exposure_and_normalize():
    """Exposure multiplies by 2^exposure; Normalize off divides by 1 instead of the light's area (Cycles'
    ``Light::area``: the quad, 4 for a radius-0 point, 4 pi r^2 for a sphere, pi sin^2(a/2) for a sun's cone)."""
    one = np.ones(3)
    _, e = lights.point_light_incidence(np.zeros(3), np.array([0, 0, 1.0]), 8.0, one)
    _, e_exp = lights.point_light_incidence(np.zeros(3), np.array([0, 0, 1.0]), 8.0, one, exposure=1.5)
    _, e_off = lights.point_light_incidence(np.zeros(3), np.array([0, 0, 1.0]), 8.0, one, normalize=0.0)
    np.testing.assert_allclose(e_exp, e * 2 ** 1.5, rtol=1e-12)
    np.testing.assert_allclose(e_off, e * 4.0, rtol=1e-12)
    quad = lights.area_light_quad(np.zeros(3), 1.0, 0, 0, 0, 1, 1, 1, 8.0, one, 2.0, 0.5)[-1]
    quad_off = lights.area_light_quad(np.zeros(3), 1.0, 0, 0, 0, 1, 1, 1, 8.0, one, 2.0, 0.5, normalize=0.0)[-1]
    np.testing.assert_allclose(quad_off, quad * 1.0, rtol=1e-12)          # area 2 x 0.5 = 1
    quad_off2 = lights.area_light_quad(np.zeros(3), 1.0, 0, 0, 0, 1, 1, 1, 8.0, one, 2.0, 2.0, normalize=0.0)[-1]
    np.testing.assert_allclose(quad_off2, quad, rtol=1e-12)               # with Normalize off the size does not matter
    r = 0.3
    sphere = lights.sphere_light(np.zeros(3), np.array([0, 0, 2.0]), 8.0, one, r, 1.0)[-1]
    sphere_off = lights.sphere_light(np.zeros(3), np.array([0, 0, 2.0]), 8.0, one, r, 1.0, normalize=0.0)[-1]
    np.testing.assert_allclose(sphere_off, sphere * 4 * np.pi * r * r, rtol=1e-12)
    sun = lights.sun_disk_light(np.zeros(3), 1.0, 0, 0, 0, 1.0, 2.0, one, 0.2)[-1]
    sun_off = lights.sun_disk_light(np.zeros(3), 1.0, 0, 0, 0, 1.0, 2.0, one, 0.2, normalize=0.0)[-1]
    np.testing.assert_allclose(sun_off, sun * np.pi * np.sin(0.1) ** 2, rtol=1e-12)
    # exposure is clamped to Blender's range, so 2^exposure stays finite in float32
    big = lights.exposure_scale(np.float32(1e4))
    assert np.isfinite(big) and big == 2.0 ** 32


def test_linking_option_removes_the_light_from_excluded_objects():
    p = dict(_quad_params(), Excluded=1.0)
    np.testing.assert_array_equal(lights.control_factor("quad+linking", np.zeros((2, 3)), p), 0.0)
    p["Excluded"] = 0.0
    np.testing.assert_array_equal(lights.control_factor("quad+linking", np.zeros((2, 3)), p), 1.0)


def _spread_weight(points, position, spread):
    """Cycles' spread weight of the directions from ``position`` to ``points`` on a light facing -Z (the formula
    of core/light_spread.py, written out)."""
    d = points - position
    w = d / np.linalg.norm(d, axis=-1, keepdims=True)
    h = spread / 2
    tan_a = np.sqrt(np.maximum(1 - w[:, 2] ** 2, 0)) / w[:, 2]
    return np.maximum(1 - tan_a / np.tan(h), 0) * np.tan(h) / (np.tan(h) - h)


def _spread_truth(position, rect, height, spread, density, n=400):
    """Exact integral over a quad light (z = height, emitting down, ``rect`` ((u0, u1), (v0, v1))) of ``density``
    (a function of unit directions (K, 3)) times Cycles' spread weight per solid angle: an n x n midpoint rule."""
    (u0, u1), (v0, v1) = rect
    s = (np.arange(n) + 0.5) / n
    uu, vv = np.meshgrid(u0 + (u1 - u0) * s, v0 + (v1 - v0) * s)
    q = np.stack([uu.ravel(), vv.ravel(), np.full(n * n, height)], -1)
    d = q - position
    r2 = np.sum(d * d, -1)
    w = d / np.sqrt(r2)[:, None]
    da = (u1 - u0) * (v1 - v0) / (n * n)
    return float(np.sum(_spread_weight(q, position, spread) * density(w) * w[:, 2] / r2) * da)


def _spread_case(rng):
    """A seeded quad light facing -Z at z = height with spread, a receiver below it: (position, normal, centre,
    half_u, half_v, spread)."""
    su, sv = rng.uniform(0.4, 2.0, 2)
    height = rng.uniform(0.8, 2.5)
    position = np.array([rng.uniform(-1.2, 1.2), rng.uniform(-1.2, 1.2), 0.0])
    normal = rng.normal(size=3)
    normal[2] = abs(normal[2]) + 0.8
    normal /= np.linalg.norm(normal)
    spread = np.radians(rng.uniform(30, 160))
    half_u, half_v = np.array([su / 2, 0, 0]), np.array([0, sv / 2, 0])     # eu x ev = +Z: it lights below
    return position, normal, np.array([0, 0, height]), half_u, half_v, spread


def _view_near_mirror(rng, normal, target):
    """A seeded view direction near the mirror of ``target`` (towards a point of the light) about ``normal``, or None
    where it grazes the surface."""
    target = target / np.linalg.norm(target)
    view = 2 * (normal @ target) * normal - target + rng.normal(scale=0.15, size=3)
    view /= np.linalg.norm(view)
    return None if view @ normal < 0.05 else view


def _spread_light(position, centre, half_u, half_v, spread, exact_horizon=True):
    """The QuadLight RT Lit shades for a light with spread (core/lights.py ``spread_geometry``) and its hits."""
    from rt_lookdev.core.ltc import shading

    c, eu, ev, cone, hits = lights.light_spread.spread_quad(position, centre, half_u, half_v, spread)
    corners = [c - eu - ev, c + eu - ev, c + eu + ev, c - eu + ev]
    return shading.QuadLight(corners, center_point=c, exact_horizon=exact_horizon, spread=cone), hits


def test_spread_on_a_lambert_receiver(energy_tables):
    """The spread's clamp and Lambert-weighted average (core/light_spread.py) against the exact integral of the
    spread weight for a Lambert receiver: 40 seeded quads, receivers and spreads 30-160 deg; median <= 1%,
    every case <= 8% (the docstring's figures are from a larger run); spread 180 deg changes nothing."""
    from rt_lookdev.core.ltc import shading

    rng = np.random.default_rng(14)
    errors = []
    for _ in range(40):
        position, normal, centre, half_u, half_v, spread = _spread_case(rng)
        light, hits = _spread_light(position, centre, half_u, half_v, spread)
        form = shading.lambert(energy_tables, light, position, normal, normal, 1.0) * hits
        rect = ((-half_u[0], half_u[0]), (-half_v[1], half_v[1]))
        truth = _spread_truth(position, rect, centre[2], spread, lambda w: np.maximum(w @ normal, 0) / np.pi)
        if truth > 1e-3:
            errors.append(abs(form / truth - 1))
        full = lights.light_spread.spread_quad(position, centre, half_u, half_v, np.pi)
        np.testing.assert_allclose(full[0], centre)
        np.testing.assert_allclose(full[4], 1.0)
        full_light, _ = _spread_light(position, centre, half_u, half_v, np.pi)
        plain = shading.QuadLight(full_light.corners, center_point=centre, exact_horizon=True)
        np.testing.assert_allclose(shading.lambert(energy_tables, full_light, position, normal, normal, 1.0),
                                   shading.lambert(energy_tables, plain, position, normal, normal, 1.0), rtol=1e-12)
    errors = np.array(errors)
    print(f"spread, Lambert: median {np.median(errors):.3%}, max {errors.max():.3%} over {len(errors)}")
    assert np.median(errors) <= 0.01 and errors.max() <= 0.08


@pytest.mark.parametrize("roughness, spread_deg, cases, median_limit, p90_limit", [
    (0.4, None, 40, 0.005, 0.03),
    (0.1, 60.0, 80, 0.01, 0.2),
])
def test_spread_weights_each_lobe_under_its_own_kernel(energy_tables, roughness, spread_deg, cases, median_limit,
                                                       p90_limit):
    """Issue 27: a glossy lobe sees the spread's weight near its reflection, not where Lambert's cosine puts it.
    The GGX LTC over ``cases`` seeded quads with spread (30-160 deg, or ``spread_deg``), views near the mirror direction of
    a point of the light, against the dense integral of the same LTC times the weight (so the figure is the spread's
    handling alone).  r = 0.4: median <= 0.5%, p90 <= 3% (measured 0.02% / 0.8%; 5 x 5 plain: 0.06% / 1.7%; weighting by Lambert's kernel,
    as before issue 27: 7% / 53%).  r = 0.1 at 60 deg, a lobe narrower than the plain 5 x 5 rule's spacing: median
    <= 1%, p90 <= 20% (measured 0.34% / 9.7% with the rule warped towards the lobe's peak; the plain 5 x 5 rule: 5.4% / 54%)."""
    from rt_lookdev.core.ltc import matrix, polygon

    rng = np.random.default_rng(27)
    errors = []
    for _ in range(cases):
        position, normal, centre, half_u, half_v, spread = _spread_case(rng)
        if spread_deg is not None:
            spread = np.radians(spread_deg)
        view = _view_near_mirror(rng, normal, centre + rng.uniform(-1, 1) * half_u + rng.uniform(-1, 1) * half_v
                                 - position)
        if view is None:
            continue
        light, hits = _spread_light(position, centre, half_u, half_v, spread)
        frame = polygon.local_frame(normal, view)
        packed, _, _ = energy_tables.ltc("ltc_ggx", np.array(view @ normal), np.array(roughness))
        c = np.array([float(x) for x in packed])
        value = light.integral(energy_tables, tuple(c), frame, position) * hits
        basis = np.stack(frame)
        rect = ((-half_u[0], half_u[0]), (-half_v[1], half_v[1]))
        truth = _spread_truth(position, rect, centre[2], spread,
                              lambda w: matrix.density_packed(c[None], w @ basis.T)[0], n=700)
        if truth > 1e-3:
            errors.append(abs(value / truth - 1))
    errors = np.array(errors)
    print(f"spread, GGX r {roughness}: median {np.median(errors):.3%}, p90 {np.percentile(errors, 90):.3%} "
          f"over {len(errors)}")
    assert len(errors) >= 20
    assert np.median(errors) <= median_limit and np.percentile(errors, 90) <= p90_limit


def _disk_spread_truth(position, radius, height, spread, density, radial=200, angular=400):
    """Exact integral over a disk light (centre (0, 0, height), emitting down) of ``density`` times Cycles' spread
    weight per solid angle: a polar midpoint rule."""
    r = (np.arange(radial) + 0.5) / radial * radius
    rr, aa = np.meshgrid(r, (np.arange(angular) + 0.5) / angular * 2 * np.pi)
    q = np.stack([(rr * np.cos(aa)).ravel(), (rr * np.sin(aa)).ravel(), np.full(rr.size, height)], -1)
    d = q - position
    r2 = np.sum(d * d, -1)
    w = d / np.sqrt(r2)[:, None]
    area = rr.ravel() * (radius / radial) * (2 * np.pi / angular)
    return float(np.sum(_spread_weight(q, position, spread) * density(w) * w[:, 2] / r2 * area))


def test_spread_disk_culls_only_lights_the_cone_misses():
    """Regression: ``spread_disk`` culled a light when the cone's foot was farther than R from the circle of the
    light's area, so a thin ellipse (1 m x 1 mm) lost its light along its length (hits 0 with the foot on the light
    itself).  It culls where the foot is surely farther than R from the ellipse now: (distance in its unit-circle
    coordinates - 1) x the smaller semi-axis; for a round disk the same test as before."""
    spread_disk = lights.light_spread.spread_disk
    centre, axis_u, axis_v = np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0]), np.array([0.0, 1e-3, 0.0])
    for foot_x, reach, lit in ((0.5, 0.1, 1.0), (0.99, 0.05, 1.0), (0.3, 0.001, 1.0)):
        spread = 2 * math.atan(reach)                                 # R = tan(spread / 2) at 1 m
        hits = spread_disk(np.array([foot_x, 0.0, 0.0]), centre, axis_u, axis_v, spread)[4]
        assert float(hits) == lit, (foot_x, reach)
    # beside the ellipse's width, out of reach: culled; a round disk as before (d > a + R)
    hits = spread_disk(np.array([0.0, 0.05, 0.0]), centre, axis_u, axis_v, 2 * math.atan(0.01))[4]
    assert float(hits) == 0.0
    disk_v = np.array([0.0, 1.0, 0.0])
    for d, reach, lit in ((1.5, 0.6, 1.0), (1.5, 0.4, 0.0)):
        assert float(spread_disk(np.array([d, 0.0, 0.0]), centre, axis_u, disk_v, 2 * math.atan(reach))[4]) == lit


@pytest.mark.parametrize("lobe, median_limit, p90_limit", [("lambert", 0.01, 0.05), ("ggx r 0.1", 0.03, 0.25)])
def test_spread_on_a_disk(energy_tables, lobe, median_limit, p90_limit):
    """Issue 27: a disk light with spread 90 deg (radius 0.3-1 m at 0.6-2 m, 30 seeded receivers viewing near the
    mirror direction of a point of the light), its LTC integral times the spread's average under the lobe's kernel
    against the dense integral of the same LTC times the weight.  Lambert: median <= 1%, p90 <= 5% (measured 0.36% /
    2.7% with the polar rule about the foot over the disk's true overlap with the cone; averaged over the overlap's
    fitted ellipse, before: 1.4% / 8.3%); GGX r = 0.1: median <= 3%, p90 <= 25% (measured 1.2% / 15% with the warped
    rule for narrow lobes; the polar rule alone, before: 13% / 53%)."""
    from rt_lookdev.core.ltc import matrix, polygon, shading

    rng = np.random.default_rng(5)
    spread = np.radians(90.0)
    errors = []
    while len(errors) < 30:
        radius, height = rng.uniform(0.3, 1.0), rng.uniform(0.6, 2.0)
        position = np.array([rng.uniform(-1.2, 1.2), rng.uniform(-1.2, 1.2), 0.0])
        normal = rng.normal(size=3)
        normal[2] = abs(normal[2]) + 0.8
        normal /= np.linalg.norm(normal)
        centre, axis_u, axis_v = np.array([0, 0, height]), np.array([radius, 0, 0]), np.array([0, radius, 0])
        view = _view_near_mirror(rng, normal, centre + rng.uniform(-0.7, 0.7) * axis_u
                                 + rng.uniform(-0.7, 0.7) * axis_v - position)
        if view is None:
            continue
        c_, u_, v_, cone, hits = lights.light_spread.spread_disk(position, centre, axis_u, axis_v, spread)
        light = shading.DiskLight(c_, u_, v_, exact_horizon=True, spread=cone)
        frame = polygon.local_frame(normal, view)
        if lobe == "lambert":
            c = np.array([1.0, 0.0, 0.0, 1.0])       # Minv = I: the clamped cosine
        else:
            packed, _, _ = energy_tables.ltc("ltc_ggx", np.array(view @ normal), np.array(0.1))
            c = np.array([float(x) for x in packed])
        value = float(light.integral(energy_tables, tuple(c), frame, position) * hits)
        basis = np.stack(frame)
        truth = _disk_spread_truth(position, radius, height, spread,
                                   lambda w: matrix.density_packed(c[None], w @ basis.T)[0])
        if truth > 1e-3:
            errors.append(abs(value / truth - 1))
    errors = np.array(errors)
    print(f"spread on a disk, {lobe}: median {np.median(errors):.3%}, p90 {np.percentile(errors, 90):.3%}")
    assert np.median(errors) <= median_limit and np.percentile(errors, 90) <= p90_limit


def _ellipse_spread_truth(position, normal, centre, axis_u, axis_v, spread, radial=160, angular=320):
    """The clamped cosine over pi times Cycles' spread weight, integrated densely over an ellipse light facing -Z (the
    polar grid of the unit disk carried onto the ellipse)."""
    r = (np.arange(radial) + 0.5) / radial
    rr, aa = np.meshgrid(r, (np.arange(angular) + 0.5) / angular * 2 * np.pi)
    x, y = (rr * np.cos(aa)).ravel(), (rr * np.sin(aa)).ravel()
    q = centre + x[:, None] * axis_u + y[:, None] * axis_v
    d = q - position
    r2 = np.sum(d * d, -1)
    w = d / np.sqrt(r2)[:, None]
    area = rr.ravel() / radial * (2 * np.pi / angular) * np.linalg.norm(axis_u) * np.linalg.norm(axis_v)
    return float(np.sum(_spread_weight(q, position, spread) * np.maximum(w @ normal, 0) / np.pi * w[:, 2] / r2
                        * area))


def test_lambert_under_a_disk_with_spread_is_exact_along_its_rays(energy_tables):
    """Issue 27: Lambert's lobe under a disk or ellipse light with spread (``shading.lambert`` ->
    ``light_spread.LAMBERT_DISK``: the radial integral in closed form on 16 rays about the cone's foot) against the
    dense integral of the clamped cosine times Cycles' weight, horizon included: 60 seeded receivers (feet inside and
    outside the light, normals tilted up to about 70 deg, spreads 20-170 deg, half of them ellipses), median <= 0.02%,
    p90 <= 0.2% (measured 0.001% / 0.037%, max 0.16%; the average under the kernel by DISK_RULE before it: 0.95% /
    3.5% at 40 deg, docs/benchmarks/spread.md).  Behind the one-sided light: 0.  The traced IR in float32 stays within
    1e-4 of it (measured 3e-6: the angular moments are written not to cancel at small angles)."""
    from rt_lookdev.core.ltc import shading

    rng = np.random.default_rng(33)
    errors, ir_errors = [], []
    body = lights.light_spread.LAMBERT_DISK.function
    while len(errors) < 60:
        a, b, height = rng.uniform(0.3, 1.0), rng.uniform(0.3, 1.0), rng.uniform(0.5, 2.5)
        if rng.random() < 0.5:
            b = a                                                     # Blender's Disk; else an Ellipse
        centre, axis_u, axis_v = np.array([0, 0, height]), np.array([a, 0, 0]), np.array([0, b, 0])
        position = np.array([rng.uniform(-1.5, 1.5), rng.uniform(-1.5, 1.5), 0.0])
        normal = rng.normal(size=3)
        normal[2] = abs(normal[2]) + 0.4
        normal /= np.linalg.norm(normal)
        spread = np.radians(rng.uniform(20, 170))
        c_, u_, v_, cone, hits = lights.light_spread.spread_disk(position, centre, axis_u, axis_v, spread)
        light = shading.DiskLight(c_, u_, v_, spread=cone)
        value = float(shading.lambert(energy_tables, light, position, normal, normal, 1.0)) * float(hits)
        truth = _ellipse_spread_truth(position, normal, centre, axis_u, axis_v, spread)
        if truth < 1e-3:
            continue
        errors.append(abs(value / truth - 1))
        captured = {}
        real = lights.light_spread.LAMBERT_DISK
        lights.light_spread.LAMBERT_DISK = lambda **kw: captured.update(kw) or real(**kw)
        try:
            direct = float(lights.light_spread.lambert_disk_form_factor(cone, position, normal))
        finally:
            lights.light_spread.LAMBERT_DISK = real
        (traced,) = evaluate((body.outputs["Form Factor"],), captured, np.float32)
        ir_errors.append(abs(float(traced) / direct - 1))
        # the same light seen from behind its emitting side
        behind = shading.DiskLight(c_, u_, v_, spread=replace(cone, disk=(centre, axis_v, axis_u)))
        assert float(shading.lambert(energy_tables, behind, position, normal, normal, 1.0)) == 0.0
    errors = np.array(errors)
    print(f"Lambert under a disk with spread: median {np.median(errors):.3%}, p90 {np.percentile(errors, 90):.3%}, "
          f"max {errors.max():.3%}; float32 IR max {max(ir_errors):.1e}")
    assert np.median(errors) <= 2e-4 and np.percentile(errors, 90) <= 2e-3
    assert max(ir_errors) <= 1e-4


def _foot_polar_truth(normal, height, foot, half_u, half_v, reach, panels=1024, radial=24):
    """The clamped cosine over pi times Cycles' spread weight (its kernel's formula, of the distance rho from the
    cone's foot: 1 - rho / R) over an ellipse light of semi-axes ``half_u`` x ``half_v`` along X and Y in the plane
    z = ``height`` above the origin, emitting down, in polar coordinates about the foot ((0, 0, height); ``foot`` the
    foot's offset from the ellipse's centre): Gauss-Legendre panels in the angle, and along each ray's chord (the
    ellipse's quadratic, cut at R and split where it crosses the receiver's horizon) Gauss-Legendre in rho: dense
    where the light is thin and close, where a grid over the light misses its near part.  The defaults agree with
    4096 panels x 48 points to 1.8e-5 relative on the thin-ellipse cases below."""
    x, w = np.polynomial.legendre.leggauss(8)
    edges = np.linspace(0.0, 2 * np.pi, panels + 1)
    half = (edges[1] - edges[0]) / 2
    phi = (edges[:-1, None] + half * (x + 1)).ravel()
    d_phi = np.tile(w * half, panels)
    du, dv = np.cos(phi), np.sin(phi)
    # |foot + rho d| = 1 in the ellipse's unit-circle coordinates
    qa = (du / half_u) ** 2 + (dv / half_v) ** 2
    qb = 2 * (foot[0] * du / half_u ** 2 + foot[1] * dv / half_v ** 2)
    qc = (foot[0] / half_u) ** 2 + (foot[1] / half_v) ** 2 - 1
    disc = np.maximum(qb * qb - 4 * qa * qc, 0.0)
    near = np.clip((-qb - np.sqrt(disc)) / (2 * qa), 0.0, reach)
    far = np.clip((-qb + np.sqrt(disc)) / (2 * qa), near, reach)
    slope = du * normal[0] + dv * normal[1]                # the receiver's cosine is (rho slope + height n_z) / |q|
    with np.errstate(divide="ignore", invalid="ignore"):
        cut = np.where(slope != 0, -height * normal[2] / slope, np.inf)
    pieces = [(near, np.clip(cut, near, far)), (np.clip(cut, near, far), far)]
    xr, wr = np.polynomial.legendre.leggauss(radial)
    total = 0.0
    for lo, hi in pieces:
        rho = lo[:, None] + (hi - lo)[:, None] * (xr + 1) / 2
        dist2 = rho * rho + height * height
        cos_receiver = np.maximum(rho * slope[:, None] + height * normal[2], 0.0) / np.sqrt(dist2)
        cos_light = height / np.sqrt(dist2)
        weight = np.maximum(1 - rho / reach, 0.0)
        f = weight * cos_receiver * cos_light / dist2 * rho / np.pi
        total += np.sum(f * wr * ((hi - lo) / 2)[:, None] * d_phi[:, None])
    return float(total)


def test_lambert_under_a_thin_ellipse_with_spread_seen_close(energy_tables):
    """Regression (issue 27, found by the robustness property test, seed 65536): a 0.19 m x 0.24 mm ellipse light
    0.6 mm from the point.  The rays of ``LAMBERT_DISK`` were spread evenly in the ellipse's own unit-circle angle,
    which puts all but a few of them along its long axis: 0.913 against the truth's 0.154 in float64, 1.39 in float32
    (the robustness bound broken).  They are spread in the angle of an importance ellipse now (the light's semi-axes
    cut to the cone's reach, each as the radial integral grows with a ray's length).  Against a dense integral about
    the foot: that case within 0.5%, and 40 seeded ellipses 1:10 to 1:1000 seen from 0.1x to 10x their width, feet
    inside and outside, median <= 0.5%, p90 <= 3% (measured 0.16% / 1.4%, max 9.5% with the foot just outside; the
    kernel-averaged rule before: median 100%, ``spread_disk`` culling such lights by their equal-area circle);
    float32 within 1e-4 of float64."""
    body = lights.light_spread.LAMBERT_DISK.function

    def rule(dtype, cases):
        """The rule at every case at once (the IR evaluates arrays)."""
        def rows(f):
            return np.array([f(*case) for case in cases], np.float64)

        kw = {"Position": rows(lambda *c: np.zeros(3)), "Normal": rows(lambda n, *c: n),
              "Foot": rows(lambda n, t, *c: [0.0, 0.0, t]),
              "Disk Center": rows(lambda n, t, g, *c: [-g[0], -g[1], t]),
              "Disk Axis U": rows(lambda n, t, g, a, *c: [a, 0.0, 0.0]),
              "Disk Axis V": rows(lambda n, t, g, a, b, r: [0.0, b, 0.0]),
              "Cone Radius": rows(lambda *c: c[-1]), "Cone Scale": rows(lambda *c: 1.0),
              "Two Sided": rows(lambda *c: 0.0)}
        (value,) = evaluate((body.outputs["Form Factor"],), {k: v.astype(dtype) for k, v in kw.items()}, dtype)
        return np.asarray(value, np.float64)

    rng = np.random.default_rng(27)
    seen = np.radians(46.4)                                           # the robustness case's receiver, N.axis 0.689
    cases = [(np.array([np.sin(seen), 0.0, np.cos(seen)]), 6.13e-4, (-1.36e-3, 2.62e-6), 0.095, 1.19e-4, 3.57e-3)]
    while len(cases) < 41:
        half_v = 10 ** rng.uniform(-3, -1)
        height = half_v * 10 ** rng.uniform(-1, 1)
        reach = height * math.tan(np.radians(rng.uniform(10, 170)) / 2)
        foot = rng.uniform(-1.3, 1.3, 2) * (1.0, half_v)
        normal = rng.normal(size=3)
        normal[2] = abs(normal[2]) + 0.3
        case = (normal / np.linalg.norm(normal), height, foot, 1.0, half_v, reach)
        if _foot_polar_truth(*case) > 1e-3 * reach * reach / (reach * reach + height * height):
            cases.append(case)                                        # not a sliver of the cone's reach
    truth = np.array([_foot_polar_truth(*case) for case in cases])
    value = rule(np.float64, cases)
    errors = np.abs(value / truth - 1)
    f32 = np.abs(rule(np.float32, cases) / value - 1)
    assert errors[0] <= 5e-3, (errors[0], "the robustness case")
    print(f"thin ellipses: median {np.median(errors):.3%}, p90 {np.percentile(errors, 90):.3%}, "
          f"max {errors.max():.3%}; float32 max {f32.max():.1e}")
    assert np.median(errors) <= 5e-3 and np.percentile(errors, 90) <= 3e-2
    assert f32.max() <= 1e-4
