"""Scenes for Cycles measurements: the UV sphere mesh every check renders, a render to a multilayer EXR and its
passes read back."""
from __future__ import annotations

import time

import numpy as np

from . import exr_images


def uv_sphere_mesh(name, segments, rings, radius=1.0):
    """A smooth UV sphere mesh of ``radius`` with exactly radial vertex normals (Blender's default ones are
    angle-weighted face averages, close to radial but not equal near the poles)."""
    import bmesh
    import bpy

    mesh = bpy.data.meshes.new(name)
    bm = bmesh.new()
    bmesh.ops.create_uvsphere(bm, u_segments=segments, v_segments=rings, radius=radius)
    bm.to_mesh(mesh)
    bm.free()
    mesh.shade_smooth()
    mesh.normals_split_custom_set_from_vertices([v.co.normalized() for v in mesh.vertices])
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
