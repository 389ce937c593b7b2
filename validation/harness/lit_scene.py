"""A small RT Lit scene for tests: one sphere, one light of every kind, an orthographic camera, and
optionally a studio HDRI world (rotated by a Mapping node) for the World term."""
from __future__ import annotations

import numpy as np
from ...core.materials import rt_lit
from ...core.materials.rt_lit_interface import Features

LIGHTS = (
    # name, type, shape, location, energy, size, size_y, extra
    ("Quad", "AREA", "RECTANGLE", (1.8, -2.2, 1.6), 300.0, 1.4, 0.7, {}),
    ("Ellipse", "AREA", "ELLIPSE", (-2.2, -1.5, 1.0), 200.0, 1.2, 0.6, {}),
    ("Point", "POINT", None, (0.5, -2.5, -1.8), 150.0, None, None, {"shadow_soft_size": 0.0}),
    ("Spot", "SPOT", None, (-1.2, -2.0, -1.6), 400.0, None, None,
     {"shadow_soft_size": 0.0, "spot_size": 0.9, "spot_blend": 0.4}),
    ("Sun", "SUN", None, (0.0, -3.0, 3.0), 1.5, None, None, {"angle": 0.0}),
)


def aim(obj, target=(0.0, 0.0, 0.0)):
    """Point the light's -Z axis at ``target``."""
    import mathutils

    direction = mathutils.Vector(target) - obj.location
    obj.rotation_mode = "QUATERNION"
    obj.rotation_quaternion = direction.to_track_quat("-Z", "Y")


def build(features_by_material, kinds=None, resolution=48, hdri=None, world_strength=0.7, lut_dir=None):
    """Spheres side by side (one per (name, Features)) lit by the LIGHTS (``kinds`` filters them) and,
    with ``hdri``, by that studio HDRI's World term; RT Lit groups read the LUTs of ``lut_dir``."""
    from ...addon import compat
    import bmesh
    import bpy

    from ...addon import materials
    from ...addon import world_sync as rtl_world
    from ...addon.demo_scene import add_hdri_world

    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    scene.world = None
    if hdri:
        add_hdri_world(bpy, scene, hdri, world_strength)
    rtl_world.sync_world(scene)
    for name, ltype, shape, loc, energy, size, size_y, extra in LIGHTS:
        kind = {"RECTANGLE": "quad", "ELLIPSE": "disk"}.get(shape, ltype.lower())
        if kinds is not None and kind not in kinds:
            continue
        data = bpy.data.lights.new(name, ltype)
        data.energy = energy
        if shape:
            data.shape, data.size, data.size_y = shape, size, size_y
        for k, v in extra.items():
            setattr(data, k, v)
        obj = bpy.data.objects.new(name, data)
        obj.location = loc
        scene.collection.objects.link(obj)
        aim(obj)
    materials.sync_scene_lights(scene)
    count = len(features_by_material)
    for i, (name, features) in enumerate(features_by_material):
        mesh = bpy.data.meshes.new(name)
        bm = bmesh.new()
        bmesh.ops.create_uvsphere(bm, u_segments=48, v_segments=24, radius=1.0)
        bm.to_mesh(mesh)
        bm.free()
        for poly in mesh.polygons:
            poly.use_smooth = True
        mat = compat.new_material(name)
        materials.assign_rt_lit(mat, features, scene, lut_dir)
        mesh.materials.append(mat)
        obj = bpy.data.objects.new(name, mesh)
        obj.location = (2.2 * (i - 0.5 * (count - 1)), 0.0, 0.0)
        scene.collection.objects.link(obj)
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 2.2 * count + 0.2
    cam.location = (0.0, -6.0, 0.0)
    cam.rotation_euler = (np.pi / 2, 0.0, 0.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    scene.render.resolution_x = resolution * count
    scene.render.resolution_y = resolution
    return scene


def numpy_radiance(scene, passes, tables):
    """The RT Lit materials evaluated directly in numpy (float64, ``core.materials.rt_lit.rt_lit_radiance``
    with the LUT set ``tables``) at the render's pixels, and the mask of pixels that hit a sphere.  Each
    pixel's material is found by the sphere it lies on."""
    from ...addon import light_model, materials
    from ...addon import world_sync as rtl_world
    from ...addon.common import FEATURES_KEY
    from .engines import camera_incoming

    pos = passes["Position"].astype(np.float64)
    nrm = passes["Normal"].astype(np.float64)
    hit = np.linalg.norm(nrm, axis=-1) > 0.5
    out = np.zeros(pos.shape)
    scene_lights = materials.scene_lights(scene)
    env = rtl_world.world_environment()
    world = None if env is None else (env[0], rtl_world.world_parameters(scene))
    for obj in scene.objects:
        if obj.type != "MESH":
            continue
        mine = hit & (np.linalg.norm(pos - np.array(obj.location), axis=-1) < 1.01)
        if not mine.any():
            continue
        mat = obj.data.materials[0]
        features = Features.from_dict(mat[FEATURES_KEY])
        params = {k: (np.array(v) if isinstance(v, tuple) else v)
                  for k, v in materials.material_parameters(mat).items()}
        geo = {"Position": pos[mine], "Geometry Normal": nrm[mine], "Incoming": camera_incoming(scene, pos[mine])}
        lights = [(kind, light_model.light_parameters(light, kind, obj)) for light, kind in scene_lights]
        out[mine] = rt_lit.rt_lit_radiance(tables, features, params, geo, lights, world)
    return out, hit
