"""Conformance harness: render a node group's output per pixel with Cycles and read it back.

``render_group_outputs(ng, inputs, output_name)`` packs the input arrays into float images
(3 float inputs per RGB image, one image per vector input), samples them with Closest/EXTEND
image textures at texel centres (a plane exactly filling an orthographic camera, one pixel per
texel, a 0.01-pixel Gaussian filter, 1 sample), feeds the group, routes the output through an
Emission shader (float: Combine Color with R = value; vector: XYZ -> RGB), renders a 32-bit float
single-layer EXR with Cycles CPU and reads it back with OpenEXR.  It renders a scene of its own, so the
file's scenes neither change nor show, and everything it creates is removed again.
"""
from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np

from . import engines, grids
from ...core.ir.numpy_backend import evaluate
from ...core.lut.lookup import LutSet
from .render_setup import blacken_world
from .render_setup import configure_cycles_measurement, configure_eevee_measurement


LAST_RENDER_SECONDS = [0.0]


def _image(bpy, name, rgb):
    """A float, non-colour image whose texel (row j from the top of ``rgb``, col i) = rgb[j, i]."""
    h, w, _ = rgb.shape
    img = bpy.data.images.new(name, w, h, alpha=True, float_buffer=True, is_data=True)
    img.alpha_mode = "CHANNEL_PACKED"
    img.use_half_precision = False      # EEVEE would upload half floats
    rgba = np.ones((h, w, 4), dtype=np.float32)
    rgba[..., :3] = rgb
    img.pixels.foreach_set(np.flipud(rgba).ravel())    # img.pixels row 0 = bottom row
    return img


def _setup_render(scene, w, h, path, engine="CYCLES"):
    if engine == "CYCLES":
        configure_cycles_measurement(scene, samples=1, seed=0)
        scene.cycles.max_bounces = 0
    else:
        configure_eevee_measurement(scene, samples=1, black_world=False)
    from .engines import output_settings

    output_settings(scene, w, h, path)


def _padded_inputs(inputs):
    """(float32 arrays padded to at least 4 x 4 with edge values, (H, W) of the inputs, padded (H, W)):
    Blender renders at least 4x4 pixels, so small inputs are padded and the result cropped."""
    arrays = {k: np.asarray(v, dtype=np.float32) for k, v in inputs.items()}
    shapes = {a.shape[:2] for a in arrays.values()}
    if len(shapes) != 1:
        raise ValueError(f"inputs must share one (H, W) shape, got {shapes}")
    (h0, w0), = shapes
    h, w = max(h0, 4), max(w0, 4)
    if (h, w) != (h0, w0):
        arrays = {k: np.pad(a, [(0, h - h0), (0, w - w0)] + [(0, 0)] * (a.ndim - 2), mode="edge")
                  for k, a in arrays.items()}
    return arrays, (h0, w0), (h, w)


def _link_input_images(bpy, nt, coord, group, arrays, h, w, created):
    """Pack the inputs into images (3 float inputs per RGB image, one image per vector input), sample
    them with Closest/EXTEND image textures at ``coord``'s UV and link them to ``group``'s inputs."""
    def tex(rgb, idx):
        img = _image(bpy, f"RTL_conformance_inputs_{idx}", rgb)
        created["images"].append(img)
        t = nt.nodes.new("ShaderNodeTexImage")
        t.image, t.interpolation, t.extension = img, "Closest", "EXTEND"
        t.location = (0, -300 * idx)
        nt.links.new(coord.outputs["UV"], t.inputs["Vector"])
        return t

    floats = [k for k, a in arrays.items() if a.ndim == 2]
    vectors = [k for k, a in arrays.items() if a.ndim == 3]
    n_img = 0
    for start in range(0, len(floats), 3):
        chunk = floats[start:start + 3]
        rgb = np.zeros((h, w, 3), dtype=np.float32)
        for c, k in enumerate(chunk):
            rgb[..., c] = arrays[k]
        t = tex(rgb, n_img)
        n_img += 1
        sep = nt.nodes.new("ShaderNodeSeparateColor")
        sep.mode = "RGB"
        sep.location = (300, -300 * n_img)
        nt.links.new(t.outputs["Color"], sep.inputs[0])
        for c, k in enumerate(chunk):
            nt.links.new(sep.outputs[c], group.inputs[k])
    for k in vectors:
        t = tex(arrays[k], n_img)
        n_img += 1
        nt.links.new(t.outputs["Color"], group.inputs[k])


def _link_emission_output(nt, out_socket, is_vector):
    """Route ``out_socket`` through an Emission shader to the material output (float: Combine Color
    with R = value; vector: XYZ -> RGB)."""
    emission = nt.nodes.new("ShaderNodeEmission")
    emission.inputs["Strength"].default_value = 1.0
    emission.location = (1000, 0)
    if is_vector:
        nt.links.new(out_socket, emission.inputs["Color"])
    else:
        comb = nt.nodes.new("ShaderNodeCombineColor")
        comb.mode = "RGB"
        comb.location = (800, 0)
        comb.inputs[1].default_value = 0.0
        comb.inputs[2].default_value = 0.0
        nt.links.new(out_socket, comb.inputs[0])
        nt.links.new(comb.outputs[0], emission.inputs["Color"])
    mout = nt.nodes.new("ShaderNodeOutputMaterial")
    mout.location = (1200, 0)
    mout.target = "ALL"
    nt.links.new(emission.outputs[0], mout.inputs["Surface"])


def _finite_mask(nt, out_socket, is_vector):
    """A float socket: 1 where ``out_socket`` is finite (every component), else 0.  Math Compare with
    epsilon 0 of a value with itself is |x - x| <= 0: false for NaN, and for +-Inf (Inf - Inf = NaN)."""
    values = [out_socket]
    if is_vector:
        sep = nt.nodes.new("ShaderNodeSeparateXYZ")
        nt.links.new(out_socket, sep.inputs[0])
        values = list(sep.outputs)
    mask = None
    for value in values:
        cmp = nt.nodes.new("ShaderNodeMath")
        cmp.operation = "COMPARE"
        nt.links.new(value, cmp.inputs[0])
        nt.links.new(value, cmp.inputs[1])
        cmp.inputs[2].default_value = 0.0
        if mask is None:
            mask = cmp.outputs[0]
        else:
            mul = nt.nodes.new("ShaderNodeMath")
            mul.operation = "MULTIPLY"
            nt.links.new(mask, mul.inputs[0])
            nt.links.new(cmp.outputs[0], mul.inputs[1])
            mask = mul.outputs[0]
    return mask


def _build_material(bpy, ng, arrays, h, w, output_name, created, finite_mask=False):
    """The temporary material: input images -> group ``ng`` -> emission.  Returns (material, whether
    the output is read back as RGB: vector and colour outputs).  ``finite_mask``: emit
    ``_finite_mask`` of the output instead (a float)."""
    from ...addon import compat
    mat = compat.new_material("RTL_conformance")
    created["materials"].append(mat)
    nt = mat.node_tree
    nt.nodes.clear()
    coord = nt.nodes.new("ShaderNodeTexCoord")
    group = nt.nodes.new("ShaderNodeGroup")
    group.node_tree = ng
    group.location = (600, 0)
    _link_input_images(bpy, nt, coord, group, arrays, h, w, created)
    out_socket = group.outputs[output_name]
    is_vector = out_socket.type in ("VECTOR", "RGBA")      # colours read back as RGB
    if finite_mask:
        out_socket, is_vector = _finite_mask(nt, out_socket, is_vector), False
    _link_emission_output(nt, out_socket, is_vector)
    return mat, is_vector


def _build_plane_and_camera(bpy, scene, mat, h, w, created):
    """A plane carrying ``mat`` exactly filling an orthographic camera (one pixel per texel), made
    the scene's camera."""
    sx, sy = (w / max(w, h), h / max(w, h))        # half extents; ortho_scale = 2 covers max side
    mesh = bpy.data.meshes.new("RTL_conformance_plane")
    created["meshes"].append(mesh)
    mesh.from_pydata([(-sx, -sy, 0), (sx, -sy, 0), (sx, sy, 0), (-sx, sy, 0)], [], [(0, 1, 2, 3)])
    uv = mesh.uv_layers.new(name="UVMap")
    for loop, (u, v) in zip(mesh.loops, [(0, 0), (1, 0), (1, 1), (0, 1)]):
        uv.data[loop.index].uv = (u, v)
    mesh.materials.append(mat)
    mesh.update()
    plane = bpy.data.objects.new("RTL_conformance_plane", mesh)
    created["objects"].append(plane)
    scene.collection.objects.link(plane)

    cam_data = bpy.data.cameras.new("RTL_conformance_camera")
    created["cameras"].append(cam_data)
    cam_data.type = "ORTHO"
    cam_data.ortho_scale = 2.0
    cam_data.sensor_fit = "AUTO"
    cam_data.clip_start, cam_data.clip_end = 0.01, 10.0
    cam = bpy.data.objects.new("RTL_conformance_camera", cam_data)
    created["objects"].append(cam)
    cam.location = (0.0, 0.0, 1.0)
    scene.collection.objects.link(cam)
    scene.camera = cam


def _build_black_world(bpy, scene, created):
    """A black world (colour and any Background node at 0), made the scene's world."""
    from ...addon import compat

    world = compat.new_world("RTL_conformance_world")
    created["worlds"].append(world)
    scene.world = blacken_world(world)


def _render(bpy, scene, w, h, path, engine):
    """Render the scene to the float EXR ``path``; its time goes to ``LAST_RENDER_SECONDS``."""
    _setup_render(scene, w, h, path, engine)
    t0 = time.perf_counter()
    if engine == "CYCLES":
        bpy.ops.render.render(write_still=True, scene=scene.name)
    else:
        from .render_setup import eevee_texture_filtering

        with eevee_texture_filtering():
            bpy.ops.render.render(write_still=True, scene=scene.name)
    LAST_RENDER_SECONDS[0] = time.perf_counter() - t0


def _read_back(path, h0, w0, is_vector):
    """The rendered values, cropped to the inputs' (H, W): RGB, or the R channel of a float output."""
    rgb = engines.read_exr_rgb(path)
    rgb = rgb[:h0, :w0]
    return rgb.copy() if is_vector else rgb[..., 0].copy()


def _cleanup(bpy, created):
    """Remove every datablock in ``created`` (the render's own scene last)."""
    for obj in created.get("objects", []):
        bpy.data.objects.remove(obj, do_unlink=True)
    for key in ("meshes", "cameras", "materials", "images", "worlds", "scenes"):
        coll = getattr(bpy.data, key)
        for item in created.get(key, []):
            coll.remove(item)


def render_group_outputs(ng, inputs, output_name, engine="CYCLES", finite_mask=False):
    """Cycles' (or EEVEE's: ``engine="BLENDER_EEVEE"``) value of ``ng``'s output ``output_name``
    per pixel for per-pixel ``inputs``.  EEVEE stores half floats and writes 0 for negative values.
    ``finite_mask``: instead of the value, 1 where the renderer computed it finite and 0 where NaN or
    Inf (which it would write as 0), as float32 (H, W).

    ``inputs``: group input name -> float32 array (H, W) (float sockets) or (H, W, 3) (vector).
    Returns float32 (H, W) or (H, W, 3) in the orientation of the inputs.
    """
    import bpy

    arrays, (h0, w0), (h, w) = _padded_inputs(inputs)
    # a scene of its own: nothing of the current file's scenes (objects in front of the plane, render
    # settings of another measurement) reaches the pixels, and nothing of them is changed
    scene = bpy.data.scenes.new("RTL_conformance")
    created = {"images": [], "materials": [], "meshes": [], "objects": [], "cameras": [], "worlds": [],
               "scenes": [scene]}
    tmp = tempfile.TemporaryDirectory(prefix="rtl-conformance-")
    try:
        mat, is_vector = _build_material(bpy, ng, arrays, h, w, output_name, created, finite_mask)
        _build_plane_and_camera(bpy, scene, mat, h, w, created)
        _build_black_world(bpy, scene, created)
        path = Path(tmp.name) / "out.exr"
        _render(bpy, scene, w, h, path, engine)
        return _read_back(path, h0, w0, is_vector)
    finally:
        _cleanup(bpy, created)
        tmp.cleanup()


# --- a node function against the numpy backend --------------------------------------------------------

RTOL = 1e-4
ATOL = 1e-6
NEAR_ZERO = grids.NEAR_ZERO


def compare(got, ref):
    """(max relative error where |ref| >= NEAR_ZERO, max absolute error elsewhere)."""
    return grids.max_deviation(got, ref, NEAR_ZERO)


def check_function(function, values, tables=None, rtol=RTOL, atol=ATOL):
    """Emit ``function`` (a NodeFunction), render each output for ``values`` (input name ->
    (H, W) or (H, W, 3) float32) and compare with its traced graph in numpy (float32), both reading
    ``tables`` (a table set; default the shipped LUTs).
    Returns {output: (max rel, max abs near zero, seconds)}; asserts finiteness and tolerances."""
    from ...addon.node_emit import ensure_function_group

    tables = tables if tables is not None else LutSet.from_folder()
    fn = function.function
    ng = ensure_function_group(function, tables)
    vals = {k: np.asarray(v, np.float32) for k, v in values.items()}
    refs = evaluate(tuple(fn.outputs.values()), vals, tables=tables)
    report, failures = {}, []
    for (name, expr), ref in zip(fn.outputs.items(), refs):
        if expr.is_const:
            continue
        ref = np.broadcast_to(ref, next(iter(vals.values())).shape[:2] + ref.shape[2:])
        got = render_group_outputs(ng, vals, name)
        assert np.all(np.isfinite(ref)), f"{function.name}.{name}: numpy reference not finite"
        assert np.all(np.isfinite(got)), f"{function.name}.{name}: non-finite pixels"
        rel, absolute = compare(got, ref)
        report[name] = (rel, absolute, LAST_RENDER_SECONDS[0])
        print(f"{function.name}.{name}: max rel {rel:.3g}, max abs near 0 {absolute:.3g}")
        if rel > rtol or absolute > atol:
            failures.append(f"{function.name}.{name}: rel {rel:.3g} abs {absolute:.3g}")
    assert not failures, "\n".join(failures)
    return report
