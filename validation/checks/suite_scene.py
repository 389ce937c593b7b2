"""A validation case in Blender: its lights, RT Lit spheres and camera ((a) the node render), (b) the numpy
evaluation of the same material at (a)'s passes, and (c) the Cycles closures' truth render."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..harness import closures, scene_render
from .suite_cases import CELL, sphere_centres
from ...core.materials import rt_lit
from ...core.materials.rt_lit_interface import RT_LIT_INPUTS
from ..harness.render_setup import configure_cycles_measurement


# --- scene ------------------------------------------------------------------------------------

def _aim(obj, target):
    import mathutils

    direction = mathutils.Vector(target) - obj.location
    obj.rotation_mode = "QUATERNION"
    obj.rotation_quaternion = direction.to_track_quat("-Z", "Y")


#: Blender light type of each LightSpec kind.
_LIGHT_TYPES = {"quad": "AREA", "disk": "AREA", "point": "POINT", "spot": "SPOT", "sun": "SUN", "sphere": "POINT",
                "spot_sphere": "SPOT", "sun_disk": "SUN"}


def _light_object(bpy, scene, name, spec):
    """A light object as ``spec`` describes it, linked to ``scene`` and aimed at its target."""
    data = bpy.data.lights.new(name, _LIGHT_TYPES[spec.kind])
    data.energy = spec.energy
    data.color = spec.color
    if spec.kind in ("quad", "disk"):
        shape = {"quad": ("SQUARE", "RECTANGLE"), "disk": ("DISK", "ELLIPSE")}[spec.kind]
        data.shape = shape[1] if spec.size_y else shape[0]
        data.size = spec.size
        data.size_y = spec.size_y or spec.size
        data.spread = spec.spread
    elif spec.kind in ("point", "spot", "sphere", "spot_sphere"):
        data.shadow_soft_size = spec.radius if spec.kind in ("sphere", "spot_sphere") else 0.0
        data.use_soft_falloff = spec.soft_falloff
        if spec.kind in ("spot", "spot_sphere"):
            data.spot_size, data.spot_blend = spec.spot_size, spec.spot_blend
    else:
        data.angle = spec.angle if spec.kind == "sun_disk" else 0.0
    for key, value in spec.settings.items():
        setattr(data, key, value)
    if spec.emission is not None:
        data.use_nodes = True
        node = next(n for n in data.node_tree.nodes if n.bl_idname == "ShaderNodeEmission")
        node.inputs["Strength"].default_value = spec.emission[0]
        node.inputs["Color"].default_value = tuple(spec.emission[1]) + (1.0,)
    for key, value in spec.controls.items():
        data[key] = value
    obj = bpy.data.objects.new(name, data)
    obj.location = spec.location
    obj.visible_camera = False
    scene.collection.objects.link(obj)
    _aim(obj, spec.target)
    obj.scale = spec.scale
    return obj


def build_scene(case, cell_px, segments=192, rings=96, lut_dir=None):
    """Reset the file; lights, spheres with RT Lit materials, camera.  Returns (scene, spheres)."""
    from ...addon import compat
    import bpy

    from ...addon import materials

    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    receivers = {}
    for i, spec in enumerate(case.lights):
        obj = _light_object(bpy, scene, f"L{i}_{spec.kind}", spec)
        if spec.excludes:
            receivers[i] = obj.light_linking.receiver_collection = bpy.data.collections.new(f"L{i} receivers")
    materials.sync_scene_lights(scene)

    centres, cols, rows = sphere_centres(case)
    mesh = scene_render.uv_sphere_mesh("RTL_val_sphere", segments, rings)
    spheres = []
    for i, (variant, centre) in enumerate(zip(case.variants, centres)):
        me = mesh.copy()
        mat = compat.new_material(f"RTL_val_{i}")
        materials.assign_rt_lit(mat, variant.features, scene, lut_dir)
        node = mat.node_tree.nodes["RT Lit"]
        for k, v in variant.material().items():
            node.inputs[k].default_value = tuple(v) + (1.0,) if isinstance(v, tuple) else v
        me.materials.append(mat)
        ob = bpy.data.objects.new(f"RTL_val_sphere_{i}", me)
        ob.location = centre
        for attr in ("visible_glossy", "visible_diffuse", "visible_transmission", "visible_volume_scatter",
                     "visible_shadow"):
            setattr(ob, attr, False)
        scene.collection.objects.link(ob)
        spheres.append(ob)
    for i, collection in receivers.items():
        for k in case.lights[i].excludes:
            collection.objects.link(spheres[k])
            collection.collection_objects[len(collection.objects) - 1].light_linking.link_state = "EXCLUDE"
    if receivers:
        materials.sync_scene_lights(scene)          # the excluded spheres' attributes (addon/light_model.py)
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.data.type = "ORTHO"
    cam.data.sensor_fit = "HORIZONTAL"
    cam.data.ortho_scale = CELL * cols
    cam.data.clip_start, cam.data.clip_end = 0.1, 100.0
    cam.location = (0.0, -20.0, 0.0)
    cam.rotation_euler = (math.pi / 2, 0.0, 0.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    scene.world = None
    scene.render.resolution_x = cell_px * cols
    scene.render.resolution_y = cell_px * rows
    return scene, spheres


def sphere_index(case, position, normal):
    """Per pixel: index of the sphere hit (-1 for background)."""
    centres, _, _ = sphere_centres(case)
    hit = np.linalg.norm(normal, axis=-1) > 0.5
    idx = np.full(hit.shape, -1, np.int64)
    for i, c in enumerate(centres):
        idx[hit & (np.linalg.norm(position - np.asarray(c), axis=-1) < 1.05)] = i
    return idx


# --- (b) numpy -------------------------------------------------------------------------------

def scene_light_params(scene, receiver=None):
    """[(kind, driver values)] of the scene's lights; the linking option's "Excluded" for the object ``receiver``."""
    from ...addon import light_model, materials

    return [(kind, light_model.light_parameters(obj, kind, receiver)) for obj, kind in materials.scene_lights(scene)]


def numpy_material(variant):
    """RT_LIT_INPUTS name -> the variant's value (the socket default where the variant sets none)."""
    out = {}
    for name, sock in RT_LIT_INPUTS.items():
        v = variant.material().get(name, sock.default)
        if sock.kind == "float":
            out[name] = float(v)
        elif name == "Normal":
            out[name] = np.zeros(3)
        else:
            out[name] = np.array(list(v)[:3], dtype=np.float64)
    return out


def material_values(material):
    """Inputs of the RT Lit function from a material's RT Lit node (``materials.material_parameters``)."""
    from ...addon import materials

    return {k: (np.array(v) if isinstance(v, tuple) else v) for k, v in materials.material_parameters(material).items()}


def numpy_radiance(scene, variants, objects, passes, index, tables, world=None, dtype=np.float32):
    """(b): each sphere's RT Lit material, the core function the node groups are emitted from
    (``core.materials.rt_lit.build_rt_lit`` for its features, the scene's lights and the world), evaluated
    by the numpy backend at the render's Position / Normal passes with the material node's values, the
    lights' driver values and the world's parameters; float32 with Cycles' node semantics (float64 on
    request).  ``objects[i]`` carries variant i's material; ``world``: None or (WorldEnvironment, params)."""
    from ..harness.engines import camera_incoming

    pos = passes["Position"].astype(np.float64)
    nrm = passes["Normal"].astype(np.float64)
    out = np.zeros(pos.shape)
    lights = scene_light_params(scene)
    env, world_params = world if world is not None else (None, {})
    for i, variant in enumerate(variants):
        mine = index == i
        if not mine.any():
            continue
        material = rt_lit.build_rt_lit(variant.features, tuple(kind for kind, _ in lights), env)
        lights = scene_light_params(scene, objects[i])
        values = material_values(objects[i].data.materials[0])
        values.update({"Position": pos[mine], "Geometry Normal": nrm[mine],
                       "Incoming": camera_incoming(scene, pos[mine])})
        for names, (_, params) in zip(material.light_inputs, lights):
            values.update({names[p]: params[p] for p in names})
        values.update({material.world_inputs[p]: v for p, v in world_params.items()})
        out[mine] = material.evaluate(values, tables, dtype)["Radiance"]
    return out


def conditioning(fn, passes, b=None):
    """(b) = fn(passes, float32) (computed unless given) and, per value, how far float32 rounding moves
    it: the float64 evaluation moved by one float32 ulp of position and normal (random signs), and
    float32 vs float64 at both positions (its internal rounding)."""
    b = fn(passes, np.float32) if b is None else b
    b64 = fn(passes, np.float64)
    moved = dict(passes)
    signs = np.random.default_rng(17)
    for key in ("Position", "Normal"):
        x = passes[key].astype(np.float32)
        moved[key] = np.nextafter(x, np.where(signs.random(x.shape) < 0.5, -np.inf, np.inf).astype(np.float32))
    b64_moved = fn(moved, np.float64)
    b32_moved = fn(moved, np.float32)
    return b, np.maximum.reduce([np.abs(b - b64), np.abs(b64_moved - b64), np.abs(b32_moved - b64_moved)])


# --- (c) Cycles ground truth -----------------------------------------------------------------

def configure_truth_render(scene, samples, seed, threads=2):
    from ...addon import compat

    configure_cycles_measurement(scene, samples, seed, threads)
    c = scene.cycles
    c.max_bounces = 0                 # direct light only: spheres are convex and see nothing else
    c.blur_glossy = 0.0
    c.caustics_reflective = True
    c.caustics_refractive = True
    vl = scene.view_layers[0]
    vl.use_pass_combined = True
    vl.use_pass_normal = True
    vl.use_pass_position = False
    s = scene.render.image_settings
    compat.set_exr_output(s, multilayer=True)
    s.exr_codec = "ZIP"


def render_truth(case, scene, spheres, samples, seeds, folder, threads=2):
    """(c) for the Cycles-closure variants: one render per seed.  Returns ([rgb per seed], seconds
    per seed, normal) or None when no variant uses Cycles."""
    todo = [i for i, v in enumerate(case.variants) if v.truth == "cycles"]
    if not todo:
        return None
    saved = []
    for i, ob in enumerate(spheres):
        saved.append((ob.data.materials[0], ob.hide_render))
        if i in todo:
            ob.data.materials[0] = closures.closure_material(case.variants[i], f"RTL_truth_{i}")
        else:
            ob.hide_render = True
    images, seconds, normal = [], [], None
    try:
        for seed in seeds:
            configure_truth_render(scene, samples, seed, threads)
            path = Path(folder) / f"truth_seed{seed}.exr"
            seconds.append(scene_render.render_exr(scene, path))
            rgb, nrm = scene_render.read_passes(path)
            images.append(rgb)
            normal = nrm
    finally:
        for ob, (mat, hidden) in zip(spheres, saved):
            ob.data.materials[0] = mat
            ob.hide_render = hidden
    return images, seconds, normal
