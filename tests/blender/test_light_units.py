"""Cycles light units: core/lights.py's conversions against small Cycles renders.

A white Diffuse BSDF plane (z = 0, albedo 1, normal +Z) seen by an orthographic camera looking
straight down, one light, no world, direct light only: a pixel is albedo/pi times the irradiance
at its centre (the 0.01-pixel Gaussian filter puts every sample at the centre).  Expected values:
- area lights: L F_z, L from ``core.lights`` and F_z the exact (Lambert / Arvo 1994) vector form
  factor of the light's world corners seen from the pixel's point, computed here independently of
  the repository's LTC code (ellipses: an inscribed 4096-gon, relative error < 1e-6); its sign also
  checks the corner winding (F_z > 0 iff the corners are ordered as the LTC convention says for a
  light facing the point, and Cycles lights that side);
- point, spot, sun: E max(N.l, 0) / pi from ``core.lights`` (``*_incidence``).
The light's transform is read back from Blender as a TRANSFORMS driver delivers it
(``matrix_world.decompose()``: location, unit quaternion, scale).

Tolerances.  Point, spot and sun lights of radius / angle 0 are sampled deterministically (one
light, one direction): the renders agree per pixel to float32 precision (measured: <= 1.1e-5
relative; in a spot's blend ramp <= 5e-5 of the peak, float32 rounding of cos - cos(spot_size/2)
near the cone's edge), and we allow 2e-4.  Area lights are sampled stochastically; the MC noise
of the mean ratio pixel/expected over the 1024 pixels is estimated from the pixel-to-pixel scatter
(pixels are independent): se = std / sqrt(1024).  We assert |mean - 1| <= 5 se + 5e-4 (a floor
for float32 and the sampler's own rounding: at 256 spp the square reads 1.4e-4 high, 3.5 se, so
some of it is likely systematic) and se < 2e-3.  Measured at 256 spp (bpy 5.0.1,
~0.3 s a render on 2 threads): square 1.00014 +- 0.00004, rotated and scaled rectangle 0.99998
+- 0.00001, disk 1.00000 +- 0.00009, rotated and scaled ellipse 1.00005 +- 0.00003 (at 64 spp
the se are 3-4x larger and two seeds differ by about sqrt(2) se, so the estimate holds).

Finally each light NodeFunction, emitted as a node group, renders in Cycles like the numpy
backend (conformance harness of tests/blender/conformance.py; measured max error 2e-6).
The whole file renders 9 + 15 tiny images: a few seconds.
"""
from __future__ import annotations

import math
import tempfile
import time
from pathlib import Path

import numpy as np
import pytest

OpenEXR = pytest.importorskip("OpenEXR")

from rt_lookdev.core import lights  # noqa: E402

pytestmark = pytest.mark.blender

RES = 32
AREA_SAMPLES = 256
DELTA_SAMPLES = 1
Z_MAX = 5.0
AREA_FLOOR = 5e-4
DELTA_RTOL = 2e-4


# --- scene -------------------------------------------------------------------------------------

def _scene(bpy, samples, ortho_scale, center):
    from rt_lookdev.addon import compat
    from rt_lookdev.validation.harness.render_setup import configure_cycles_measurement

    bpy.ops.wm.read_homefile(use_empty=True)
    sc = bpy.context.scene
    configure_cycles_measurement(sc, samples=samples, seed=0, threads=2)
    sc.cycles.max_bounces = 0
    sc.world = None                      # a new world would add its 0.05 grey background
    r = sc.render
    r.resolution_x = r.resolution_y = RES
    r.resolution_percentage = 100
    r.use_compositing = r.use_sequencer = False
    r.dither_intensity = 0.0
    s = r.image_settings
    s.file_format, s.color_depth, s.color_mode = "OPEN_EXR", "32", "RGB"

    half = 50.0
    me = bpy.data.meshes.new("RTL_plane")
    me.from_pydata([(-half, -half, 0), (half, -half, 0), (half, half, 0), (-half, half, 0)], [], [(0, 1, 2, 3)])
    plane = bpy.data.objects.new("RTL_plane", me)
    sc.collection.objects.link(plane)
    mat = compat.new_material("RTL_white")
    nt = mat.node_tree
    nt.nodes.clear()
    bsdf = nt.nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    bsdf.inputs["Roughness"].default_value = 0.0
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    nt.links.new(bsdf.outputs[0], out.inputs["Surface"])
    me.materials.append(mat)

    cam = bpy.data.cameras.new("RTL_cam")
    cam.type, cam.ortho_scale = "ORTHO", ortho_scale
    cam_ob = bpy.data.objects.new("RTL_cam", cam)
    cam_ob.location = (center[0], center[1], 20.0)        # identity rotation: looks down -Z
    sc.collection.objects.link(cam_ob)
    sc.camera = cam_ob
    return sc


def _pixel_points(ortho_scale, center):
    """World positions (RES, RES, 3) of the pixel centres on z = 0, row 0 = top of the image (+Y)."""
    t = (np.arange(RES) + 0.5) / RES * ortho_scale - 0.5 * ortho_scale
    x = center[0] + t[None, :]
    y = center[1] - t[:, None]
    return np.stack(np.broadcast_arrays(x, y, np.zeros_like(x)), axis=-1)


def _light(bpy, sc, kind, location, rotation, scale, **props):
    data = bpy.data.lights.new("RTL_light", kind)
    for k, v in props.items():
        setattr(data, k, v)
    if kind in ("POINT", "SPOT"):
        data.shadow_soft_size = 0.0
    if kind == "SUN":
        data.angle = 0.0
    ob = bpy.data.objects.new("RTL_light", data)
    ob.location = location
    ob.rotation_mode = "QUATERNION"
    ob.rotation_quaternion = rotation
    ob.scale = scale
    ob.visible_camera = False
    sc.collection.objects.link(ob)
    bpy.context.view_layer.update()
    loc, quat, scl = ob.matrix_world.decompose()          # what world-space TRANSFORMS drivers read
    return np.array(loc, float), tuple(float(v) for v in quat), tuple(float(v) for v in scl)


def _render(bpy, sc):
    with tempfile.TemporaryDirectory(prefix="rtl-light-units-") as tmp:
        sc.render.filepath = str(Path(tmp) / "render.exr")
        t0 = time.perf_counter()
        bpy.ops.render.render(write_still=True)
        seconds = time.perf_counter() - t0
        with OpenEXR.File(sc.render.filepath, separate_channels=True) as f:
            ch = {n: np.array(c.pixels) for p in f.parts for n, c in p.channels.items()}
    return np.stack([ch["R"], ch["G"], ch["B"]], axis=-1).astype(np.float64), seconds


def _quat(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    return (math.cos(angle / 2), *(math.sin(angle / 2) * axis))


# --- exact form factor ---------------------------------------------------------------------------

def _form_factor_z(points, corners):
    """Signed z of the vector form factor F = 1/(2 pi) sum_i theta_i unit(v_i x v_(i+1)) of the
    polygon ``corners`` (K, 3) seen from each of ``points`` (..., 3) (Arvo 1994, exact edges)."""
    v = corners[None, :, :] - points.reshape(-1, 1, 3)
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    w = np.roll(v, -1, axis=1)
    c = np.cross(v, w)
    s = np.linalg.norm(c, axis=-1)
    theta = np.arctan2(s, np.sum(v * w, axis=-1))
    fz = np.sum(theta * c[..., 2] / s, axis=-1) / (2 * np.pi)
    return fz.reshape(points.shape[:-1])


def _ellipse_polygon(center, axis_u, axis_v, n=4096):
    t = 2 * np.pi * np.arange(n) / n
    return center + np.cos(t)[:, None] * axis_u + np.sin(t)[:, None] * axis_v


# --- checks ----------------------------------------------------------------------------------------

REPORT = {}


def _judge_area(name, img, expected, seconds):
    gray = img.mean(axis=-1)
    ratio = gray / expected
    mean, se = float(ratio.mean()), float(ratio.std(ddof=1) / math.sqrt(ratio.size))
    REPORT[name] = dict(mean_ratio=mean, se=se, seconds=seconds)
    print(f"\n[light units] {name}: mean(pixel / expected) = {mean:.5f} +- {se:.5f} (se), "
          f"{ratio.size} px, {AREA_SAMPLES} spp, render {seconds:.2f} s")
    assert abs(mean - 1.0) <= Z_MAX * se + AREA_FLOOR, (name, mean, se)
    assert se < 2e-3, (name, se)          # the bound is only meaningful if the noise is small


def _judge_delta(name, got, expected, seconds, peak=None):
    """Per-value agreement (pixels x channels): relative, or relative to ``peak`` (the ramp of a spot
    tends to 0 at the cone's edge, where float32 rounding of cos - cos(spot_size/2) dominates)."""
    got, expected = np.ravel(got), np.ravel(expected)
    peak = None if peak is None else np.ravel(peak)
    assert got.shape == expected.shape and (expected > 0).all()
    rel = np.abs(got - expected) / (expected if peak is None else peak)
    REPORT[name] = dict(max_rel=float(rel.max()), mean_rel=float(rel.mean()), seconds=seconds)
    print(f"\n[light units] {name}: max |pixel - expected| / {'expected' if peak is None else 'peak'} = "
          f"{rel.max():.2e} over {rel.size // 3} px, render {seconds:.2f} s")
    assert rel.max() <= DELTA_RTOL, (name, float(rel.max()))


AREA_CASES = {
    # name: shape, size, size_y, location, rotation (axis, angle), scale, camera (scale, centre)
    "square": ("SQUARE", 1.0, 3.0, (0.0, 0.0, 1.0), ((1, 0, 0), 0.0), (1, 1, 1), (0.6, (0.1, 0.0))),
    "rectangle_rotated_scaled": ("RECTANGLE", 0.8, 0.4, (0.2, -0.1, 1.2), ((1, 2, 0.5), 0.5), (1.5, 0.7, 2.0),
                                 (0.8, (0.2, -0.1))),
    "disk": ("DISK", 1.2, 0.3, (0.0, 0.0, 0.8), ((0, 0, 1), 0.3), (1, 1, 1), (0.8, (0.2, 0.1))),
    "ellipse_rotated_scaled": ("ELLIPSE", 1.0, 0.5, (-0.1, 0.2, 1.0), ((0.3, -1, 0.2), 0.4), (1.3, 0.9, 1.0),
                               (0.8, (-0.1, 0.2))),
}


@pytest.mark.parametrize("name", list(AREA_CASES))
def test_area_light_radiance(bpy_module, name):
    bpy = bpy_module
    shape, size, size_y, location, (axis, angle), scale, (ortho, center) = AREA_CASES[name]
    sc = _scene(bpy, AREA_SAMPLES, ortho, center)
    power, color = 150.0, np.array([1.0, 0.5, 0.25])
    loc, q, s = _light(bpy, sc, "AREA", location, _quat(axis, angle), scale,
                       energy=power, color=tuple(color), shape=shape, size=size, size_y=size_y)
    img, seconds = _render(bpy, sc)
    out = lights.area_light(shape, loc, *q, *s, power, color, size, size_y)
    if shape in ("SQUARE", "RECTANGLE"):
        corners, radiance = np.array(out[:4]), out[4]
    else:
        corners, radiance = _ellipse_polygon(*out[:3]), out[3]
    points = _pixel_points(ortho, center)
    fz = _form_factor_z(points, corners)
    assert (fz > 0).all(), "the corners are not wound as the LTC convention says for the lit side"
    expected = fz[..., None] * radiance          # albedo 1: pixel = (1/pi) L (pi F_z)
    # colour: Cycles multiplies the power by the colour channel by channel
    np.testing.assert_allclose(img / img.mean(axis=-1, keepdims=True),
                               np.broadcast_to(color / color.mean(), img.shape), rtol=1e-5)
    _judge_area(name, img, expected.mean(axis=-1), seconds)


def test_point_light_intensity(bpy_module):
    bpy = bpy_module
    ortho, center = 2.0, (0.3, -0.2)
    sc = _scene(bpy, DELTA_SAMPLES, ortho, center)
    power, color = 80.0, np.array([0.2, 1.0, 0.6])
    loc, q, s = _light(bpy, sc, "POINT", (0.1, 0.2, 0.7), (1, 0, 0, 0), (3.0, 1.0, 0.5),
                       energy=power, color=tuple(color))
    img, seconds = _render(bpy, sc)
    p = _pixel_points(ortho, center)
    l, e = lights.point_light_incidence(p, loc, power, color)
    expected = e * np.maximum(l[..., 2], 0.0)[..., None] / np.pi
    _judge_delta("point", img, expected, seconds)


SPOT_CASES = {
    # name: location, rotation, scale, spot_size, spot_blend, camera
    "spot_blend": ((0.0, 0.0, 1.0), ((1, 0, 0), 0.0), (1, 1, 1), math.radians(60), 0.5, (1.6, (0.0, 0.0))),
    "spot_tilted_hard": ((0.2, 0.0, 1.5), ((0, 1, 0), 0.35), (1, 1, 1), math.radians(40), 0.0, (1.6, (-0.2, 0.0))),
    "spot_scaled": ((0.0, 0.0, 1.0), ((0, 0, 1), 0.6), (2.0, 0.7, 1.3), math.radians(50), 0.6, (1.2, (0.0, 0.0))),
}


@pytest.mark.parametrize("name", list(SPOT_CASES))
def test_spot_light_cone(bpy_module, name):
    """Inside the cone the intensity is the point light's P/(4 pi); the blend ramp and the cone in
    the light's local (scaled) frame are Cycles' spot_light_attenuation."""
    bpy = bpy_module
    location, (axis, angle), scale, spot_size, spot_blend, (ortho, center) = SPOT_CASES[name]
    sc = _scene(bpy, DELTA_SAMPLES, ortho, center)
    power, color = 60.0, np.array([1.0, 0.8, 0.3])
    loc, q, s = _light(bpy, sc, "SPOT", location, _quat(axis, angle), scale, energy=power,
                       color=tuple(color), spot_size=spot_size, spot_blend=spot_blend)
    img, seconds = _render(bpy, sc)
    p = _pixel_points(ortho, center)
    l, e = lights.spot_light_incidence(p, loc, *q, *s, power, color, spot_size, spot_blend)
    expected = e * np.maximum(l[..., 2], 0.0)[..., None] / np.pi
    c = lights.spot_cosine(p, loc, *q, *s)
    cos_half = math.cos(spot_size / 2)
    inner = cos_half + spot_blend * (1 - cos_half)
    full = c > inner + 1e-4
    ramp = (c > cos_half + 1e-4) & (c < inner - 1e-4)
    dark = c < cos_half - 1e-4
    assert full.sum() >= 50 and dark.sum() >= 50 and (spot_blend == 0 or ramp.sum() >= 50), \
        (full.sum(), ramp.sum(), dark.sum())
    # inside the cone: exactly the point light (no renormalisation by the cone's solid angle)
    l_pt, e_pt = lights.point_light_incidence(p, loc, power, color)
    np.testing.assert_allclose(expected[full], (e_pt * l_pt[..., 2:] / np.pi)[full], rtol=1e-12)
    _judge_delta(name + " (inside)", img[full], expected[full], seconds)
    if spot_blend > 0:
        _judge_delta(name + " (blend)", img[ramp], expected[ramp], seconds,
                     peak=np.broadcast_to(expected.max(axis=(0, 1)), expected[ramp].shape))
    assert np.abs(img[dark]).max() == 0.0


def test_sun_irradiance(bpy_module):
    bpy = bpy_module
    ortho, center = 1.0, (0.0, 0.0)
    sc = _scene(bpy, DELTA_SAMPLES, ortho, center)
    strength, color = 3.5, np.array([0.9, 0.4, 1.0])
    loc, q, s = _light(bpy, sc, "SUN", (5.0, -3.0, 2.0), _quat((1, 1, 0), 0.6), (2.0, 1.0, 1.0),
                       energy=strength, color=tuple(color))
    img, seconds = _render(bpy, sc)
    l, e = lights.sun_light_incidence(*q, s[2], strength, color)
    assert l[2] > 0.5
    expected = np.broadcast_to(e * l[2] / np.pi, img.shape)
    _judge_delta("sun", img, expected, seconds)


# --- the node groups ---------------------------------------------------------------------------------

NODE_SIZE = 16


def _node_inputs(fn, rng):
    """Driver-like per-pixel values for every input of a light NodeFunction (float32, (H, W[, 3]))."""
    n = NODE_SIZE * NODE_SIZE
    q = rng.normal(size=(n, 4))
    q /= np.linalg.norm(q, axis=-1, keepdims=True)
    ranges = {"Location": (-3, 3), "Scale": (0.2, 3), "Color": (0, 1), "Power": (1, 2000), "Strength": (0, 10),
              "Size": (0.01, 4), "Spot Size": (0.1, 3.1), "Spot Blend": (0, 1), "Cone": (0.1, 3.1), "Range": (0.0, 8.0),
              "Exposure": (-2, 2), "Radius": (0.01, 0.6), "Angle": (0.01, 1.0), "Spread": (0.3, 3.1),
              "Excluded": (0, 1)}
    values = {}
    for name in fn.input_sockets:
        if name.startswith("Rotation "):
            v = q[:, "WXYZ".index(name[-1])]
        elif name == "Position":
            v = rng.uniform(-3, 3, (n, 3))
        elif name == "Normal":
            v = rng.normal(size=(n, 3))
            v /= np.linalg.norm(v, axis=-1, keepdims=True)
        elif name in ("Normalize", "Soft Falloff"):
            v = (rng.uniform(0, 1, n) < 0.5).astype(np.float64)
        elif name == "Determinant":
            v = rng.uniform(0.2, 3, n) * rng.choice([-1.0, 1.0], n)
        else:
            key = name if name in ranges else name.rsplit(" ", 1)[0]
            v = rng.uniform(*ranges[key], n)
        values[name] = v.reshape((NODE_SIZE, NODE_SIZE) + v.shape[1:]).astype(np.float32)
    return values


def _vector_wrapper(bpy, inner):
    """A group instancing ``inner`` with every output as a Vector socket (colour -> vector is exact
    per channel; the conformance harness reads back float and vector outputs only)."""
    ng = bpy.data.node_groups.new(inner.name + " (vectors)", "ShaderNodeTree")
    node = ng.nodes.new("ShaderNodeGroup")
    node.node_tree = inner
    gin, gout = ng.nodes.new("NodeGroupInput"), ng.nodes.new("NodeGroupOutput")
    for item in inner.interface.items_tree:
        if getattr(item, "item_type", None) != "SOCKET":
            continue
        if item.in_out == "INPUT":
            ng.interface.new_socket(item.name, in_out="INPUT", socket_type=item.socket_type)
            ng.links.new(gin.outputs[item.name], node.inputs[item.name])
        else:
            kind = "NodeSocketFloat" if item.socket_type == "NodeSocketFloat" else "NodeSocketVector"
            ng.interface.new_socket(item.name, in_out="OUTPUT", socket_type=kind)
            ng.links.new(node.outputs[item.name], gout.inputs[item.name])
    return ng


@pytest.mark.parametrize("fn", lights.NODE_FUNCTIONS + lights.CONTROL_FUNCTIONS, ids=lambda f: f.name)
def test_node_group_renders_like_numpy(empty_scene, bpy_module, fn):
    """Each light function, emitted as its node group, gives the numpy backend's values in Cycles."""
    from rt_lookdev.validation.harness.conformance import render_group_outputs

    from rt_lookdev.addon.node_emit import ensure_function_group
    from rt_lookdev.core.ir.numpy_backend import evaluate

    ng = _vector_wrapper(bpy_module, ensure_function_group(fn))
    values = _node_inputs(fn, np.random.default_rng(11))
    body = fn.function
    refs = dict(zip(body.outputs, evaluate(tuple(body.outputs.values()), values)))
    for name, ref in refs.items():
        got = render_group_outputs(ng, values, name)
        ref = np.broadcast_to(ref, got.shape)
        err = np.abs(got - ref)
        bound = 1e-4 * np.abs(ref) + 1e-5 * np.abs(ref).max()
        print(f"\n[light units] node group {fn.name} / {name}: max |cycles - numpy| = {err.max():.2e} "
              f"(max |value| {np.abs(ref).max():.3g})")
        assert np.isfinite(got).all()
        assert (err <= bound).all(), (name, float((err - bound).max()))
