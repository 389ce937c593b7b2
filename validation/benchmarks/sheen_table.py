"""Measuring Cycles' sheen (Zeltner, Burley & Chiang 2022) lobe table from Cycles renders.

Cycles' Sheen BSDF ("Microfiber") and the Principled BSDF's sheen are one LTC lobe per (mu, r): in the
local frame (N = +Z, the view in the XZ plane towards +X) the BRDF times the cosine at a light direction
l = (x, y, z) is

    f cos = albedo * a^2 max(z, 0) / (pi ((a x + b z)^2 + a^2 y^2 + z^2)^2),

the density of the LTC whose inverse matrix is [[a, 0, b], [0, a, 0], [0, 0, 1]] (Heitz et al. 2016,
eq. 1-4; Zeltner et al. 2022, sec. 3: their lobe keeps two free entries), times its albedo.  Cycles reads
(a, b, albedo) bilinearly from a 32 x 32 table over (mu, r), nodes at i/31 (the paper's fit).  We measure
that table instead of copying it: for a delta light (a sun of angle 0) a one-sample, direct-light render
gives f cos exactly, and

    sqrt(z / (f cos)) = k1 (x^2 + y^2) + k2 x z + k3 z^2,   k1 = s|a|, k2 = 2 s sign(a) b, k3 = s (b^2 + 1)/|a|,

with s = sqrt(pi / albedo), is linear in (k1, k2, k3): from three or more light directions a linear least
squares gives them, and s^2 = k1 k3 - k2^2/4, |a| = k1/s, sign(a) b = k2/(2 s), albedo = pi/s^2 (the lobe
only depends on (|a|, sign(a) b), so the table stores a >= 0).

The render.  One orthographic camera looking straight down (view +Z exactly) at a plane covering the
frame, one pixel per cell; a float image read with Closest interpolation gives every pixel its shading
normal (the cell's mu = N.V) and roughness, fed to a Sheen BSDF node.  The material's bump-map correction
is off (Cycles would otherwise soften a shading normal that differs from the geometry's, Conty et al.
2019), the suns are above the plane and above every cell's normal.  Cycles clamps the sheen roughness to
>= 1e-3, so node r = 0 is never read alone: it is measured half-way to node 1 (r = 0.5/31, where Cycles
interpolates both with weight 1/2) and solved from that and node 1 (``solve_node0``).
"""
from __future__ import annotations

import math
import tempfile
import time
from pathlib import Path

import numpy as np
from ...core import lut_bake
from ...core.lut import catalog, exr_io
from ..harness.render_setup import configure_cycles_measurement

#: Cycles' table size and roughness floor (src/kernel/closure/bsdf_sheen.h, bsdf_sheen_setup).
SIZE = 32
ROUGHNESS_MIN = 1e-3

#: Sun directions (towards the light), elevation and azimuth in degrees; the view is +Z and the cells'
#: normals lean towards +X, so every direction is above the plane and above every normal but a few
#: (those are skipped per cell).
SUN_ELEVATIONS = (8.0, 20.0, 35.0, 50.0, 65.0, 80.0)
SUN_AZIMUTHS = (0.0, 40.0, 80.0, 120.0, 160.0)
#: Where node r = 0 is measured: half-way to node 1 (at r = 1e-3 the closure is skipped for most mu, its
#: interpolated albedo being below Cycles' 1e-5 cut-off).
NODE0_ROUGHNESS = 0.5 / (SIZE - 1)
#: Blender renders at least this many pixels per side.
MIN_PIXELS = 4


def sun_directions():
    """(K, 3) unit directions towards the suns."""
    out = []
    for el in SUN_ELEVATIONS:
        for az in SUN_AZIMUTHS:
            e, a = math.radians(el), math.radians(az)
            out.append((math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), math.sin(e)))
    return np.array(out)


def cell_normals(mu):
    """Unit shading normals in the XZ plane with N.V = mu for the view +Z: (sqrt(1 - mu^2), 0, mu)."""
    mu = np.asarray(mu, np.float64)
    return np.stack([np.sqrt(np.maximum(1.0 - mu * mu, 0.0)), np.zeros_like(mu), mu], axis=-1)


def local_directions(normal, light):
    """Light directions in Cycles' sheen frame (T, B, N) for the view +Z: B = normalize(N x V), T = B x N
    (``make_orthonormals_safe_tangent``), which puts V in the XZ plane towards +X.  At N = V (mu = 1)
    the frame is arbitrary; the lobe is then rotationally symmetric (b = 0) and x, y are taken with
    T = +X."""
    view = np.array([0.0, 0.0, 1.0])
    n = np.asarray(normal, np.float64)
    b = np.cross(n, view)
    length = np.linalg.norm(b, axis=-1, keepdims=True)
    fallback = np.broadcast_to([0.0, 1.0, 0.0], b.shape)
    b = np.where(length > 1e-6, b / np.maximum(length, 1e-300), fallback)
    t = np.cross(b, n)
    light = np.asarray(light, np.float64)
    return np.stack([np.sum(light * t, -1), np.sum(light * b, -1), np.sum(light * n, -1)], axis=-1)


def lobe_value(local, a, b, albedo):
    """f cos of the sheen LTC at local directions (..., 3) (module docstring)."""
    x, y, z = local[..., 0], local[..., 1], local[..., 2]
    length2 = (a * x + b * z) ** 2 + (a * y) ** 2 + z * z
    return albedo * a * a * np.maximum(z, 0.0) / (np.pi * np.maximum(length2 * length2, 1e-300))


def fit_cell(local, value, min_z=0.02, min_rel=1e-4):
    """(a, b, albedo, relative rms residual of f cos, directions used) from one cell's samples
    (local directions (K, 3), values (K,)); NaNs when fewer than 3 directions are usable."""
    z = local[:, 2]
    ok = (z > min_z) & (value > min_rel * max(float(np.max(value)), 1e-30))
    if ok.sum() < 3:
        return math.nan, math.nan, math.nan, math.nan, int(ok.sum())
    x, y, z, f = local[ok, 0], local[ok, 1], local[ok, 2], value[ok]
    rhs = np.sqrt(z / f)
    A = np.stack([x * x + y * y, x * z, z * z], axis=-1)
    # relative weights: every equation's error relative to its own size
    w = 1.0 / rhs
    k, *_ = np.linalg.lstsq(A * w[:, None], rhs * w, rcond=None)
    s2 = k[0] * k[2] - 0.25 * k[1] ** 2
    if not s2 > 0:
        return math.nan, math.nan, math.nan, math.nan, int(ok.sum())
    s = math.sqrt(s2)
    a, b, albedo = k[0] / s, 0.5 * k[1] / s, math.pi / s2
    model = lobe_value(local[ok], a, b, albedo)
    residual = float(np.sqrt(np.mean(((model - f) / f) ** 2)))
    return float(a), float(b), float(albedo), residual, int(ok.sum())


def solve_node0(measured, node1, r_measured=None):
    """Node r = 0 from the value measured at ``r_measured`` (default ``NODE0_ROUGHNESS``), which Cycles
    interpolates between nodes 0 and 1 with weight t = r (SIZE - 1) on node 1."""
    t = (NODE0_ROUGHNESS if r_measured is None else r_measured) * (SIZE - 1)
    return (np.asarray(measured) - t * np.asarray(node1)) / (1.0 - t)


# --- Cycles -----------------------------------------------------------------------------------------

def _scene(bpy, cells, distribution="MICROFIBER"):
    """A scene whose pixel (row j from the top, column i) shades cell ``cells[j][i]`` = (mu, r)."""
    from ...addon import compat

    cells = np.asarray(cells, np.float64)
    height, width = cells.shape[:2]
    bpy.ops.wm.read_homefile(use_empty=True)
    sc = bpy.context.scene
    configure_cycles_measurement(sc, samples=1, seed=0, threads=2)
    sc.cycles.max_bounces = 0
    sc.world = None
    r = sc.render
    r.resolution_x, r.resolution_y = width, height
    r.resolution_percentage = 100
    r.use_compositing = r.use_sequencer = False
    r.dither_intensity = 0.0
    s = r.image_settings
    s.file_format, s.color_depth, s.color_mode = "OPEN_EXR", "32", "RGB"

    hw, hh = 0.5 * width, 0.5 * height
    me = bpy.data.meshes.new("RTL_sheen_plane")
    me.from_pydata([(-hw, -hh, 0), (hw, -hh, 0), (hw, hh, 0), (-hw, hh, 0)], [], [(0, 1, 2, 3)])
    plane = bpy.data.objects.new("RTL_sheen_plane", me)
    sc.collection.objects.link(plane)

    # per pixel: the normal (RGB) and the roughness (A), image row 0 = bottom of the frame
    normals = cell_normals(cells[..., 0])
    pixels = np.concatenate([normals, cells[..., 1:2]], axis=-1)[::-1].astype(np.float32)
    img = bpy.data.images.new("RTL_sheen_cells", width, height, alpha=True, float_buffer=True)
    img.colorspace_settings.name = "Non-Color"
    img.alpha_mode = "CHANNEL_PACKED"
    img.pixels.foreach_set(pixels.ravel())
    img.pack()

    mat = compat.new_material("RTL_sheen_measure")
    mat.cycles.use_bump_map_correction = False
    nt = mat.node_tree
    nt.nodes.clear()
    coords = nt.nodes.new("ShaderNodeTexCoord")
    tex = nt.nodes.new("ShaderNodeTexImage")
    tex.image, tex.interpolation, tex.extension = img, "Closest", "EXTEND"
    nt.links.new(coords.outputs["Generated"], tex.inputs["Vector"])
    bsdf = nt.nodes.new("ShaderNodeBsdfSheen")
    bsdf.distribution = distribution
    bsdf.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    nt.links.new(tex.outputs["Color"], bsdf.inputs["Normal"])
    nt.links.new(tex.outputs["Alpha"], bsdf.inputs["Roughness"])
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    nt.links.new(bsdf.outputs[0], out.inputs["Surface"])
    me.materials.append(mat)

    cam = bpy.data.cameras.new("RTL_sheen_cam")
    cam.type, cam.ortho_scale = "ORTHO", float(max(width, height))
    cam_ob = bpy.data.objects.new("RTL_sheen_cam", cam)
    cam_ob.location = (0.0, 0.0, 10.0)                   # identity rotation: looks down -Z
    sc.collection.objects.link(cam_ob)
    sc.camera = cam_ob

    sun = bpy.data.lights.new("RTL_sheen_sun", "SUN")
    sun.angle, sun.energy = 0.0, 1.0
    sun_ob = bpy.data.objects.new("RTL_sheen_sun", sun)
    sun_ob.rotation_mode = "QUATERNION"
    sc.collection.objects.link(sun_ob)
    return sc, sun_ob


def _aim_sun(bpy, sun_ob, direction):
    """Point the sun so that light arrives from ``direction``; returns Blender's direction (float32 matrix)."""
    import mathutils

    sun_ob.rotation_quaternion = mathutils.Vector(direction).to_track_quat("Z", "Y")
    bpy.context.view_layer.update()
    m = np.array(sun_ob.matrix_world, np.float64)
    d = m[:3, 2]
    return d / np.linalg.norm(d)


def _render(bpy, sc, folder):
    import OpenEXR

    sc.render.filepath = str(Path(folder) / "sheen.exr")
    bpy.ops.render.render(write_still=True)
    with OpenEXR.File(sc.render.filepath, separate_channels=True) as f:
        ch = {n: np.array(c.pixels) for p in f.parts for n, c in p.channels.items()}
    return np.stack([ch["R"], ch["G"], ch["B"]], axis=-1).astype(np.float64)


def render_lobe(cells, directions, distribution="MICROFIBER"):
    """Cycles' Sheen BSDF, f cos per cell and sun direction: (values (H, W, K), Blender's directions
    (K, 3), seconds).  ``cells`` (H, W, 2) = (mu, r); unit sun strength, so a pixel is f cos."""
    import bpy

    cells = np.asarray(cells, np.float64)
    h, w = cells.shape[:2]
    # Blender renders at least 4 x 4 pixels: pad with copies of the last cell, crop afterwards
    padded = np.pad(cells, ((0, max(MIN_PIXELS - h, 0)), (0, max(MIN_PIXELS - w, 0)), (0, 0)), mode="edge")
    sc, sun_ob = _scene(bpy, padded, distribution)
    values, used = [], []
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="rtl-sheen-") as tmp:
        for d in directions:
            used.append(_aim_sun(bpy, sun_ob, d))
            values.append(_render(bpy, sc, tmp).mean(axis=-1)[:h, :w])
    return np.stack(values, axis=-1), np.array(used), time.perf_counter() - t0


def measure_cells(cells, directions=None):
    """Fit (a, b, albedo) to every cell: dict of (H, W) arrays a, b, albedo, residual, used, and seconds."""
    cells = np.asarray(cells, np.float64)
    directions = sun_directions() if directions is None else directions
    values, used_dirs, seconds = render_lobe(cells, directions)
    normals = cell_normals(cells[..., 0])
    out = {k: np.full(cells.shape[:2], np.nan) for k in ("a", "b", "albedo", "residual")}
    out["used"] = np.zeros(cells.shape[:2], np.int64)
    for j in range(cells.shape[0]):
        for i in range(cells.shape[1]):
            local = local_directions(normals[j, i][None], used_dirs)
            a, b, albedo, res, n = fit_cell(local, values[j, i])
            out["a"][j, i], out["b"][j, i], out["albedo"][j, i], out["residual"][j, i] = a, b, albedo, res
            out["used"][j, i] = n
    out["seconds"] = seconds
    return out


def measure_table():
    """The whole 32 x 32 table as (H = mu nodes, W = r nodes, 3) = (a, b, albedo) (the layout of the
    project's tables: u = r, v = mu), with the r = 0 column solved from r = 1e-3 (``solve_node0``), plus
    the fit report."""
    nodes = np.arange(SIZE) / (SIZE - 1)
    r_cols = nodes.copy()
    r_cols[0] = NODE0_ROUGHNESS
    r, mu = np.meshgrid(r_cols, nodes)
    m = measure_cells(np.stack([mu, r], axis=-1))
    table = np.stack([m["a"], m["b"], m["albedo"]], axis=-1)
    table[:, 0] = solve_node0(table[:, 0], table[:, 1])
    return table, m


def complete(table):
    """The measured table with its unmeasurable cells filled: where Cycles' lobe vanishes at a node (its
    albedo below Cycles' 1e-5 cut-off, so every render is 0) the albedo is stored as 0 and (a, b) as the
    nearest measured node of the same mu row towards higher r (they only shape a lobe whose albedo is
    < 1e-5 there); tiny negative albedos (the r = 0 column's solve, -4e-9) become 0.  Returns (table,
    number of filled cells)."""
    table = np.array(table, np.float64)
    missing = np.isnan(table).any(axis=-1)
    for j, i in zip(*np.nonzero(missing)):
        ok = np.nonzero(~missing[j, i:])[0]
        source = table[j, i + ok[0]] if ok.size else np.array([1.0, 0.0, 0.0])
        table[j, i] = (source[0], source[1], 0.0)
    table[..., 2] = np.maximum(table[..., 2], 0.0)
    return table, int(missing.sum())


#: Points of the moments' quadrature: Gauss-Legendre in u1 (cosine-distributed z_o = sqrt(1 - u1)) times the
#: midpoint rule in phi (measured over the table: 128 x 256 and 256 x 512 agree to 8e-7, 64 x 128 to 3e-5: the
#: low-roughness lobes hug the horizon).
MOMENT_RULE = (128, 256)


def sh_moments(table, rule=MOMENT_RULE):
    """Moments of each cell's normalised sheen LTC D (local frame: N = +Z, V towards +X), for the world term's
    exact L2 SH integral (core/materials/world_shading.py): ((H, W, 3) E[x], E[z], E[x z]; (H, W, 3) E[x^2],
    E[y^2], E[z^2]) (E[y] = E[x y] = E[y z] = 0 by symmetry).  A direction of D is M w_o / |M w_o| with w_o
    cosine-distributed and M = Minv^-1 ~ [[1, 0, -b], [0, 1, 0], [0, 0, a]] (Heitz et al. 2016, sec. 3), so
    E[g] = E_cos[g(M w_o / |M w_o|)], integrated by a product rule in (u1, phi) (Malley's mapping)."""
    x, wx = np.polynomial.legendre.leggauss(rule[0])
    u1, w1 = 0.5 * (x + 1.0), 0.5 * wx
    phi = (np.arange(rule[1]) + 0.5) * 2.0 * np.pi / rule[1]
    rr, zo = np.sqrt(u1)[:, None], np.sqrt(1.0 - u1)[:, None]
    xo, yo, zo = (rr * np.cos(phi)).ravel(), (rr * np.sin(phi)).ravel(), np.broadcast_to(zo, (rule[0], rule[1])).ravel()
    weight = np.broadcast_to(w1[:, None] / rule[1], (rule[0], rule[1])).ravel()
    table = np.asarray(table, np.float64)
    first, second = np.zeros(table.shape[:-1] + (3,)), np.zeros(table.shape[:-1] + (3,))
    for j in np.ndindex(table.shape[:-2]) if table.ndim > 2 else [()]:      # one row of cells at a time
        a, b = table[j][..., 0:1], table[j][..., 1:2]
        dx, dy, dz = xo - b * zo, yo + 0.0 * a, a * zo
        inv_length = 1.0 / np.sqrt(dx * dx + dy * dy + dz * dz)
        dx, dy, dz = dx * inv_length, dy * inv_length, dz * inv_length
        mean = lambda g: np.sum(g * weight, axis=-1)            # noqa: E731
        first[j] = np.stack([mean(dx), mean(dz), mean(dx * dz)], axis=-1)
        second[j] = np.stack([mean(dx * dx), mean(dy * dy), mean(dz * dz)], axis=-1)
    return first, second


def write_measured(lut_dir, table=None, report=None):
    """Measure (unless ``table`` is given: (a, b, albedo) of the 32 x 32 nodes) and write the measured group's
    tables into ``lut_dir`` with their provenance: ``zeltner_sheen.exr`` and the moments derived from it
    (``sh_moments``: ``zeltner_sheen_sh1.exr``, ``zeltner_sheen_sh2.exr``); returns (path, report)."""
    import bpy

    if table is None:
        table, report = measure_table()
    table, filled = complete(table)
    first, second = sh_moments(table)
    group = catalog.bake_group("zeltner_sheen")
    digest = catalog.inputs_hash("zeltner_sheen")
    ones = np.ones(table.shape[:2] + (1,))
    items = []
    for name, data in (("zeltner_sheen", table), ("zeltner_sheen_sh1", first), ("zeltner_sheen_sh2", second)):
        spec = catalog.TABLES[name]
        meta = lut_bake._metadata(spec, group, digest)
        meta.update({"generator": "rt_lookdev.validation.benchmarks.sheen_table", "sampler": "sun renders (angle 0), 1 sample",
                     "samples": int(len(sun_directions())), "blender_version": bpy.app.version_string,
                     "filled_cells": filled,
                     "provenance": f"measured from Cycles (Blender {bpy.app.version_string}) Sheen BSDF Microfiber "
                                   "renders; Zeltner, Burley and Chiang 2022's lobe"
                                   + ("" if name == "zeltner_sheen" else "; moments of its LTCs (sh_moments)")})
        items.append((Path(lut_dir) / spec.filename,
                      np.concatenate([data, ones], axis=-1).astype(np.float32), meta))
    exr_io.write_tables(items)
    return items[0][0], dict(report or {}, filled=filled)
