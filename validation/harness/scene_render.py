"""Scenes for Cycles measurements: the UV sphere mesh every check renders, a render to a multilayer EXR and its
passes read back."""
from __future__ import annotations

import time

import numpy as np

from . import exr_images


def uv_sphere_mesh(name, segments, rings, radius=1.0):
    """A smooth UV sphere mesh of ``radius`` with exactly radial vertex normals (Blender's default ones are
    angle-weighted face averages, close to radial but not equal near the poles).

    The normals are a "free" custom normal (the float attribute ``custom_normal`` on the points, Blender 4.5+), not
    ``normals_split_custom_set_from_vertices``: that one stores them encoded in each corner's fan space, off by up to
    4e-4, and differently from one call to the next (four meshes built in a row got four sets of normals, bpy 5.2.3),
    so two runs of a check rendered different normals and their figures differed in the fourth digit."""
    import bmesh
    import bpy

    mesh = bpy.data.meshes.new(name)
    bm = bmesh.new()
    bmesh.ops.create_uvsphere(bm, u_segments=segments, v_segments=rings, radius=radius)
    bm.to_mesh(mesh)
    bm.free()
    mesh.shade_smooth()
    co = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3)
    normals = co / np.linalg.norm(co, axis=1, keepdims=True)
    mesh.attributes.new("custom_normal", "FLOAT_VECTOR", "POINT").data.foreach_set(
        "vector", normals.astype(np.float32).ravel())
    return mesh


def render_exr(scene, path):
    """Render ``scene`` to ``path`` (its output settings as they are); the seconds the render took."""
    import bpy

    scene.render.filepath = str(path)
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    return time.perf_counter() - t0


def read_passes(path):
    """(combined RGB, normal XYZ) float64 arrays (H, W, 3) from a multilayer EXR, all parts."""
    ch = exr_images.read_channels(path)
    return (exr_images.find_pass(ch, "Combined", "RGB").astype(np.float64),
            exr_images.find_pass(ch, "Normal", "XYZ").astype(np.float64))
