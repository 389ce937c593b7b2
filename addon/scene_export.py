"""Export the open scene's RT Lit lookdev as a scene description (core/export/scene.py) for engines and the
standalone renderer: the camera, the lights RT Lit shades (their driver values), the synced world (SH,
strength, rotation and the prefiltered table), every RT Lit material's switches and input values, and
each mesh object's triangles in world space with the normals Cycles interpolates.

    export_scene(scene, folder, lut_dir=None) -> core.export.scene.SceneDescription
"""
from __future__ import annotations

from pathlib import Path

import bpy
import numpy as np

from ..core.export import scene as description
from ..core.lut import catalog
from ..core.materials import rt_lit
from ..core.materials.rt_lit_interface import RT_LIT_INPUTS, Features
from . import light_model, materials
from . import world_sync
from .common import FEATURES_KEY, RT_LIT_NODE_NAME


class SceneExportError(RuntimeError):
    """The scene cannot be exported as it is; the message says what to change."""


def _camera(scene):
    cam = scene.camera
    if cam is None or cam.type != "CAMERA":
        raise SceneExportError(f"scene {scene.name!r} has no camera: set one (Scene > Camera) to export")
    data = cam.data
    if data.type not in description.CAMERA_TYPES:
        raise SceneExportError(f"camera {cam.name!r} is {data.type}; the export supports "
                               f"{', '.join(description.CAMERA_TYPES)} cameras")
    r = scene.render
    scale = r.resolution_percentage / 100.0
    resolution = (max(1, int(r.resolution_x * scale)), max(1, int(r.resolution_y * scale)))
    if r.pixel_aspect_x != r.pixel_aspect_y:
        raise SceneExportError(f"scene {scene.name!r} has non-square pixels ({r.pixel_aspect_x}:{r.pixel_aspect_y})")
    angle = data.angle_x if data.sensor_fit == "HORIZONTAL" else data.angle_y if data.sensor_fit == "VERTICAL" \
        else data.angle
    return description.Camera([list(row) for row in cam.matrix_world], data.type, float(data.ortho_scale),
                              float(angle), data.sensor_fit, (float(data.shift_x), float(data.shift_y)),
                              float(data.clip_start), float(data.clip_end), resolution)


def _lights(scene):
    found = materials.scene_lights(scene)
    synced = [kind for _, kind in materials.synced_light_kinds()]
    kinds = [kind for _, kind in found]
    if synced != kinds:
        raise SceneExportError(f"the RT Lit groups were built for the lights {synced}, the scene has {kinds}: "
                               "run RT Lookdev > Sync Lights first")
    return [description.SceneLight(obj.name, kind, light_model.light_parameters(obj, kind)) for obj, kind in found]


def _material(mat):
    node = mat.node_tree.nodes.get(RT_LIT_NODE_NAME) if mat.node_tree is not None else None
    ng = node.node_tree if node is not None and node.bl_idname == "ShaderNodeGroup" else None
    if ng is None or FEATURES_KEY not in ng.keys():
        return None
    features = Features.from_dict(ng[FEATURES_KEY])
    values = materials.material_parameters(mat)
    linked = [name for name in RT_LIT_INPUTS if node.inputs[name].is_linked and name != "Normal"]
    return description.SceneMaterial(mat.name, features.as_dict(), values, linked)


def _triangles(obj, depsgraph):
    """World-space triangle corners and corner normals (float64) of the evaluated mesh of ``obj``."""
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        mesh.calc_loop_triangles()
        tris = len(mesh.loop_triangles)
        loops = np.empty(tris * 3, np.int32)
        mesh.loop_triangles.foreach_get("loops", loops)
        corner_vertex = np.empty(len(mesh.loops), np.int32)
        mesh.loops.foreach_get("vertex_index", corner_vertex)
        co = np.empty(len(mesh.vertices) * 3, np.float64)
        mesh.vertices.foreach_get("co", co)
        normals = np.empty(len(mesh.loops) * 3, np.float64)
        if hasattr(mesh, "corner_normals"):              # Blender 4.1+
            mesh.corner_normals.foreach_get("vector", normals)
        else:                                            # pragma: no cover (older than the minimum)
            mesh.loops.foreach_get("normal", normals)
        co, normals = co.reshape(-1, 3), normals.reshape(-1, 3)
        m = np.array(obj.matrix_world, np.float64)
        positions = co[corner_vertex[loops]] @ m[:3, :3].T + m[:3, 3]
        nrm = normals[loops] @ np.linalg.inv(m[:3, :3])          # (M^-T n) as rows
        return positions, nrm
    finally:
        evaluated.to_mesh_clear()


def _world(scene):
    """(SceneWorld or None, WorldEnvironment or None, the table file to copy or None)."""
    env_record = world_sync.world_environment()
    if env_record is None:
        return None, None, None
    env, record = env_record
    params = world_sync.world_parameters(scene)
    if params is None:
        raise SceneExportError("the RT Lit groups shade a world, but the scene's world is not usable now: "
                               "run RT Lookdev > Sync World")
    values = {k: np.asarray(v).tolist() if np.ndim(v) else float(v) for k, v in params.items()}
    source = env.source if env.source is not None else record["prefiltered"]
    return description.SceneWorld(env.name, f"{env.name}.exr", values), env, source


def _objects(scene):
    """(materials by name, SceneObjects, geometry by key, names of the mesh objects left out)."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    mats, objects, geometry, skipped = {}, [], {}, []
    for obj in sorted(scene.objects, key=lambda o: o.name):
        if obj.type != "MESH" or obj.hide_render:
            continue
        mat = obj.active_material
        entry = _material(mat) if mat is not None else None
        if entry is None:
            skipped.append(obj.name)
            continue
        mats.setdefault(mat.name, entry)
        key = str(len(objects))
        geometry[key] = _triangles(obj, depsgraph)
        excluded = [light.name for light, kind in materials.scene_lights(scene)
                    if not light_model.receives(light, obj)]
        objects.append(description.SceneObject(obj.name, mat.name, key, len(geometry[key][0]) // 3, excluded))
    if not objects:
        raise SceneExportError(f"scene {scene.name!r} has no mesh object with an RT Lit material to export")
    return mats, objects, geometry, skipped


def _lut_files(mats, kinds, env, lut_dir):
    """{table name: file name} and {file name: source path} of the LUTs the materials read."""
    folder = Path(lut_dir) if lut_dir is not None else catalog.default_lut_dir()
    tables, files = {}, {}
    for entry in mats.values():
        for name in rt_lit.build_rt_lit(Features.from_dict(entry.features), kinds, env).table_names():
            if name in catalog.TABLES:
                spec = catalog.TABLES[name]
                tables[name] = spec.filename
                files[spec.filename] = folder / spec.filename
    return tables, files


def export_scene(scene, folder, lut_dir=None, log=None):
    """Write the scene description of ``scene`` into ``folder`` (replacing it atomically); returns the
    ``SceneDescription`` as read back.  Mesh objects without an RT Lit material are left out (named in
    the log); an RT Lit material input that is linked is exported at its unlinked value (listed in the
    material's ``linked``)."""
    # object matrices are evaluated lazily: a camera or light created by a script has an identity
    # matrix_world until its view layer is updated
    (bpy.context.view_layer if bpy.context.scene == scene else scene.view_layers[0]).update()
    camera = _camera(scene)
    lights = _lights(scene)
    world, env, env_file = _world(scene)
    mats, objects, geometry, skipped = _objects(scene)
    tables, table_files = _lut_files(mats, tuple(light.kind for light in lights), env, lut_dir)
    if world is not None:
        tables[world.table] = world.file
        table_files[world.file] = env_file
    desc = description.SceneDescription(camera, lights, world, mats, objects, tables,
                                        source=bpy.data.filepath or "(unsaved)")
    if log and skipped:
        log(f"scene export: left out {len(skipped)} mesh objects without an RT Lit material: {', '.join(skipped)}")
    description.write(folder, desc, geometry, table_files, log=log)
    return description.read(folder)
