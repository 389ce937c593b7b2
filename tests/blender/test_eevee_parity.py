"""EEVEE renders an emission-only node tree (Math, Vector Math, a Linear float Image Texture) like
Cycles does, within EEVEE's half-precision film and its slightly inexact Linear filtering.

A plane exactly fills an orthographic camera (one pixel per UV cell of 1/64); ``ramp`` is a 16x16
float Non-Color image sampled Linear/EXTEND at the UV; the emission colour is
R = 0.5 * ramp.R + u^2, G = sqrt(v) * (1 + ramp.G), B = 2 * dot(uv, (1, -1, 0)) * ramp.B (negative
where v > u, where EEVEE writes 0). Skips when EEVEE cannot render (no GPU context / EGL).

Measured on Mesa llvmpipe (2 cores): max relative error 9.5e-4, p99 8.5e-4 (half-float rounding of
EEVEE's film); EEVEE ~1.3 s, Cycles ~0.01 s, the test ~4 s (~14 s with a cold Mesa shader cache).
With the default 2x anisotropic filtering (no ``eevee_texture_filtering()``) the max was 9.9e-3.
"""
from __future__ import annotations


import numpy as np
import pytest

pytest.importorskip("OpenEXR")

from rt_lookdev.validation.harness.engines import compare, eevee_available, render_engines  # noqa: E402

pytestmark = pytest.mark.blender

SIZE = 64
RTOL = 1e-2
FLOOR = 1e-3
RAMP = 16          # ramp image: RAMP x RAMP texels, so one texel spans 4 pixels


def _ramp():
    """A smooth float ramp in [0.2, 1.0]: R along u, G along v, B along both (row 0 = bottom)."""
    t = np.linspace(0.0, 1.0, RAMP, dtype=np.float32)
    u, v = np.meshgrid(t, t)                      # [row = v, col = u]
    rgba = np.ones((RAMP, RAMP, 4), np.float32)
    rgba[..., 0] = 0.2 + 0.8 * u
    rgba[..., 1] = 0.2 + 0.8 * v * v
    rgba[..., 2] = 0.2 + 0.4 * (u + v)
    return rgba


def _build_scene(bpy, scene):
    from rt_lookdev.addon import compat
    img = bpy.data.images.new("RTL_parity_ramp", RAMP, RAMP, alpha=True, float_buffer=True, is_data=True)
    img.alpha_mode = "CHANNEL_PACKED"
    img.colorspace_settings.name = "Non-Color"
    img.use_half_precision = False
    img.pixels.foreach_set(_ramp().ravel())       # img.pixels row 0 = bottom = v 0

    mat = compat.new_material("RTL_parity")
    nt = mat.node_tree
    nt.nodes.clear()
    new, link = nt.nodes.new, nt.links.new
    coord = new("ShaderNodeTexCoord")
    tex = new("ShaderNodeTexImage")
    tex.image, tex.interpolation, tex.extension = img, "Linear", "EXTEND"
    link(coord.outputs["UV"], tex.inputs["Vector"])
    uv = new("ShaderNodeSeparateXYZ")
    link(coord.outputs["UV"], uv.inputs[0])
    ramp = new("ShaderNodeSeparateColor")
    link(tex.outputs["Color"], ramp.inputs[0])

    def math(op, a, b=None):
        n = new("ShaderNodeMath")
        n.operation = op
        for i, x in enumerate((a, b)):
            if x is None:
                continue
            if isinstance(x, (int, float)):
                n.inputs[i].default_value = float(x)
            else:
                link(x, n.inputs[i])
        return n.outputs[0]

    # R = 0.5 * ramp.R + u^2
    r = math("ADD", math("MULTIPLY", ramp.outputs[0], 0.5), math("POWER", uv.outputs[0], 2.0))
    # G = sqrt(v) * (1 + ramp.G)
    g = math("MULTIPLY", math("SQRT", uv.outputs[1]), math("ADD", ramp.outputs[1], 1.0))
    # B = 2 * dot(uv, (1, -1, 0)) * ramp.B  (negative where v > u)
    dot = new("ShaderNodeVectorMath")
    dot.operation = "DOT_PRODUCT"
    link(coord.outputs["UV"], dot.inputs[0])
    dot.inputs[1].default_value = (1.0, -1.0, 0.0)
    scale = new("ShaderNodeVectorMath")
    scale.operation = "SCALE"
    link(tex.outputs["Color"], scale.inputs[0])
    link(dot.outputs["Value"], scale.inputs["Scale"])
    sep_b = new("ShaderNodeSeparateXYZ")
    link(scale.outputs["Vector"], sep_b.inputs[0])
    b = math("MULTIPLY", sep_b.outputs[2], 2.0)

    comb = new("ShaderNodeCombineColor")
    link(r, comb.inputs[0])
    link(g, comb.inputs[1])
    link(b, comb.inputs[2])
    emission = new("ShaderNodeEmission")
    emission.inputs["Strength"].default_value = 1.0
    link(comb.outputs[0], emission.inputs["Color"])
    out = new("ShaderNodeOutputMaterial")
    out.target = "ALL"
    link(emission.outputs[0], out.inputs["Surface"])

    mesh = bpy.data.meshes.new("RTL_parity_plane")
    mesh.from_pydata([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], [], [(0, 1, 2, 3)])
    uv_layer = mesh.uv_layers.new(name="UVMap")
    for loop, (u, v) in zip(mesh.loops, [(0, 0), (1, 0), (1, 1), (0, 1)]):
        uv_layer.data[loop.index].uv = (u, v)
    mesh.materials.append(mat)
    plane = bpy.data.objects.new("RTL_parity_plane", mesh)
    scene.collection.objects.link(plane)

    cam_data = bpy.data.cameras.new("RTL_parity_camera")
    cam_data.type, cam_data.ortho_scale = "ORTHO", 2.0
    cam_data.clip_start, cam_data.clip_end = 0.01, 10.0
    cam = bpy.data.objects.new("RTL_parity_camera", cam_data)
    cam.location = (0.0, 0.0, 1.0)
    scene.collection.objects.link(cam)
    scene.camera = cam

    world = compat.new_world("RTL_parity_world")
    world.color = (0.0, 0.0, 0.0)
    scene.world = world


def _expected(size):
    """numpy value of the node tree at pixel centres (exact bilinear ramp), row 0 = top."""
    c = (np.arange(size) + 0.5) / size
    u, v = np.meshgrid(c, c[::-1])
    ramp = _ramp()[..., :3].astype(np.float64)
    x = np.clip(u * RAMP - 0.5, 0, RAMP - 1)
    y = np.clip(v * RAMP - 0.5, 0, RAMP - 1)
    i0, j0 = np.minimum(np.floor(x).astype(int), RAMP - 2), np.minimum(np.floor(y).astype(int), RAMP - 2)
    fx, fy = (x - i0)[..., None], (y - j0)[..., None]
    t = (ramp[j0, i0] * (1 - fx) * (1 - fy) + ramp[j0, i0 + 1] * fx * (1 - fy)
         + ramp[j0 + 1, i0] * (1 - fx) * fy + ramp[j0 + 1, i0 + 1] * fx * fy)
    return np.stack([0.5 * t[..., 0] + u * u, np.sqrt(v) * (1 + t[..., 1]), 2 * (u - v) * t[..., 2]], -1)


def test_eevee_matches_cycles_on_emission_tree(empty_scene):
    import bpy

    ok, info = eevee_available()
    if not ok:
        pytest.skip(info)
    scene = empty_scene
    _build_scene(bpy, scene)
    res = render_engines(scene, resolution=SIZE)
    cycles, t_cycles = res["CYCLES"]
    eevee, t_eevee = res["BLENDER_EEVEE"]
    assert cycles.shape == eevee.shape == (SIZE, SIZE, 3)
    assert np.all(np.isfinite(eevee))

    # Cycles is the ground truth: check it against the exact tree first (float32, ~1e-6)
    ref = _expected(SIZE)
    c_vs_ref = compare(ref, cycles, positive_floor=FLOOR)
    stats = compare(cycles, eevee, positive_floor=FLOOR)
    e_vs_ref = compare(ref, eevee, positive_floor=FLOOR)
    print(f"\nEEVEE ({info}) {t_eevee:.2f} s, Cycles {t_cycles:.2f} s, {SIZE}x{SIZE}, 1 sample")
    print(f"Cycles vs numpy: max {c_vs_ref['max']:.3g}")
    print(f"EEVEE vs Cycles: {stats}")
    print(f"EEVEE vs numpy:  max {e_vs_ref['max']:.3g}, p99 {e_vs_ref['p99']:.3g}")

    assert float(np.abs(eevee).max()) > 0.1, "EEVEE returned a black image"
    assert c_vs_ref["max"] <= 1e-4, f"Cycles differs from the numpy tree: {c_vs_ref}"
    assert stats["count"] > SIZE * SIZE * 2, stats          # R, G and half of B are compared
    assert stats["max"] <= RTOL, f"EEVEE vs Cycles relative error too large: {stats}"
    # EEVEE writes 0 for negative emission (B where v > u): every negative Cycles value
    assert stats["negative"] > 0 and stats["negative_clamped"] == stats["negative"], stats


@pytest.mark.parametrize("kind,lobe", [("quad", "ggx"), ("quad", "lambert"), ("disk", "cod"), ("point", "ggx")])
def test_rt_lit_lobes_compute_the_same_in_eevee(empty_scene, tables, kind, lobe):
    """Identical inputs (full-float images, Closest) through the same lobe group in both engines:
    EEVEE's film truncates to half floats (relative step 2^-10 = 9.8e-4), nothing else may differ."""
    ok, why = eevee_available()
    if not ok:
        pytest.skip(why)
    from rt_lookdev.validation.harness.conformance import render_group_outputs
    from rt_lookdev.validation.harness.grids import area_lobe_inputs as _area_inputs
    from rt_lookdev.validation.harness.grids import punctual_lobe_inputs as _punctual_inputs

    from rt_lookdev.addon.node_emit import ensure_function_group
    from rt_lookdev.core.materials import lobes

    fn = lobes.LOBES[lobe].function(kind)
    vals = _punctual_inputs() if kind == "point" else _area_inputs(kind)
    vals = {k: vals[k] for k in fn.input_sockets}
    ng = ensure_function_group(fn, tables)
    for out in fn.output_sockets:
        cycles = render_group_outputs(ng, vals, out)
        eevee = render_group_outputs(ng, vals, out, engine="BLENDER_EEVEE")
        # half floats: values above 65504 (a point light on a mirror, r = 0) saturate in EEVEE
        big = (cycles > 1e-3) & (cycles < 65504.0)
        rel = np.abs(eevee[big] - cycles[big]) / cycles[big]
        print(f"{fn.name}.{out}: {big.sum()} values, EEVEE vs Cycles median {np.median(rel):.2e}, "
              f"max {rel.max():.2e}")
        assert big.sum() > 20 and rel.max() <= 1.5e-3
