"""A scene description (core/export/scene.py) as a static web page draws it (issue 32, item 3).

    write_web(folder, description)      # folder/draw.json, geometry.bin, programs/, tables/

What ``engines/viewer`` (plain WebGL2, no build step) reads, everything computed here so that the page only uploads
and draws, as the standalone renderer (validation/harness/realtime_render.py) does on OpenGL 4.5:
- ``programs/<i>.vert`` / ``.frag``: the RT Lit material shaders in GLSL ES 3.00 (core/materials/rt_lit_shader.py),
  one program per feature set;
- ``tables/<name>.f32``: each table the shaders sample, RGBA float32, row 0 first (the shaders fetch texels exactly);
- ``geometry.bin``: every object's world-space triangles, interleaved position and normal (float32);
- ``draw.json``: the camera (view and projection, column-major, as uploaded), each object's program, vertex range and
  uniform values (``MaterialShader.uniform_values`` with its lights as the object is drawn), and the controls the
  page offers (the material inputs of each object, each light's power) with their meaning.
"""
from __future__ import annotations

import json

import numpy as np

from ..materials import rt_lit_shader
from ..materials.rt_lit_interface import Features
from .folders import replacing_folder
from .scene import SceneDescriptionError

FORMAT = "rt-lookdev-web"
VERSION = 1
DRAW_FILE = "draw.json"


def _column_major(matrix):
    return [float(v) for v in np.asarray(matrix, np.float64).T.reshape(-1)]


def _rgba(data):
    """A table as (H, W, 4) float32 (fewer channels padded with 0, alpha 1)."""
    a = np.asarray(data, np.float32)
    if a.ndim == 2:
        a = a[..., None]
    if a.shape[2] < 4:
        pad = np.zeros(a.shape[:2] + (4 - a.shape[2],), np.float32)
        pad[..., -1] = 1.0
        a = np.concatenate([a, pad], axis=2)
    return np.ascontiguousarray(a[..., :4])


def _light_control(light, slot):
    """A light's control: the uniform field its power (or a sun's strength) feeds in every program."""
    kind, index = slot
    fields = [f for f, _, parts in rt_lit_shader.light_fields(kind) if f in ("power", "strength")]
    return {"name": light.name, "kind": light.kind,
            "uniform": f"{rt_lit_shader.light_array(kind)}[{index}].{fields[0]}" if fields else None}


def web_bundle(description):
    """(draw: dict, files: {relative path: bytes}) of ``description``."""
    built = description.build_materials()
    tables = description.table_set()
    world = description.world.parameters if description.world is not None else None
    cam = description.camera
    programs, shaders, files, table_info = {}, [], {}, {}
    objects, chunks, first = [], [], 0
    for obj, (positions, normals) in zip(description.objects, description.geometry().values()):
        key = Features.from_dict(description.materials[obj.material].features)
        if key not in programs:
            shader = rt_lit_shader.material_shader(built[obj.material], "glsl300es", precise=False)
            index = programs[key] = len(shaders)
            shaders.append(shader)
            files[f"programs/{index}.vert"] = shader.vertex.encode()
            files[f"programs/{index}.frag"] = shader.fragment.encode()
            for table, (_, h, w) in shader.tables.items():
                if table not in table_info:
                    data = _rgba(tables[table].require_data())
                    if data.shape[:2] != (h, w):
                        raise SceneDescriptionError(f"table {table!r} is {data.shape[:2]}, the shader reads {(h, w)}")
                    files[f"tables/{table}.f32"] = data.astype("<f4").tobytes()
                    table_info[table] = {"file": f"tables/{table}.f32", "width": w, "height": h}
        shader = shaders[programs[key]]
        material = description.materials[obj.material]
        values = shader.uniform_values(material.inputs, obj.light_values(description.lights), world)
        count = len(positions)
        chunks.append(np.concatenate([positions, normals], axis=1).astype("<f4"))
        objects.append({"name": obj.name, "material": obj.material, "program": programs[key], "first": first,
                        "count": count, "uniforms": values})
        first += count
    files["geometry.bin"] = (np.concatenate(chunks).tobytes() if chunks else b"")
    draw = {
        "format": FORMAT, "version": VERSION,
        "resolution": [int(v) for v in cam.resolution],
        "camera": {"view": _column_major(cam.view()), "projection": _column_major(cam.projection()),
                   "position": [float(v) for v in cam.position], "forward": [float(v) for v in cam.forward],
                   "orthographic": cam.type == "ORTHO"},
        "programs": [{"vertex": f"programs/{i}.vert", "fragment": f"programs/{i}.frag",
                      "textures": {texture: table for table, (texture, _, _) in s.tables.items()},
                      "uniforms": [{"name": u.name, "type": u.type, "meaning": u.meaning} for u in s.uniforms]}
                     for i, s in enumerate(shaders)],
        "tables": table_info,
        "objects": objects,
        "lights": [_light_control(light, slot) for light, slot in
                   zip(description.lights, shaders[0].light_slots if shaders else ())],
    }
    return draw, files


def write_web(folder, description, log=None):
    """Write the bundle into ``folder`` (replaced as a whole: an interrupted write leaves the previous one)."""
    draw, files = web_bundle(description)
    with replacing_folder(folder, SceneDescriptionError) as tmp:
        for name, data in files.items():
            path = tmp / name
            path.parent.mkdir(parents=True, exist_ok=True)
            path.write_bytes(data)
        (tmp / DRAW_FILE).write_text(json.dumps(draw))
    if log:
        log(f"web bundle: {len(draw['objects'])} objects, {len(draw['programs'])} programs, "
            f"{len(draw['tables'])} tables into {folder}")
    return draw
