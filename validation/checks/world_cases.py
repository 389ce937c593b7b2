"""The cases of scripts/validate_world.py: the RT Lit World term under Blender's studio HDRIs.

Everything here is the world counterpart of validation/checks/suite_cases.py (whose metrics, closure
materials and render settings are reused): unit spheres seen by camera rays only (no shadows, no
sphere lights another, so each is convex and unoccluded) and an orthographic camera looking along +Y,
lit by a World whose Background shows an equirectangular image:

    Texture Coordinate (Generated) -> Mapping (Point, Euler XYZ rotation) -> Environment Texture
    (Linear, equirectangular) -> Background (Strength) -> World Output

so the radiance arriving from world direction d is Strength x image(R d) (core/environment/equirect.py
gives Blender's mapping; R = Rz Ry Rx, ``euler_xyz_matrix``).

Per world:

(a) node render: the spheres of the *node block* carry RT Lit materials whose group includes the world
    term (after ``addon.world.sync_world``); Cycles renders 1 sample at pixel centres with Position and
    Normal passes (``engine_parity.render_cycles_passes``);
(b) numpy: ``rt_lit.rt_lit_radiance(..., world=(WorldEnvironment, world_parameters))`` at (a)'s passes;
(c) ground truth:
    - Cycles path tracing of the *truth block*: one sphere per closure (Diffuse BSDF; Glossy BSDF GGX
      and Glossy Multiscatter GGX with white colour, F = 1, per roughness), direct light only (max
      bounces 0: the world is sampled as a light, with MIS), two seeds for the noise;
    - the brute-force integral of the true CoD WWII BRDF (``cod_reference_image``: the image area-
      averaged to a few thousand texels with their solid angles; ``core.indirect.cod_diffuse_reference``
      under the SH-projected environment), for the CoD diffuse and its "magnitude only" baseline.

Why two blocks: the world is at infinity and the camera orthographic, so the radiance of a sphere pixel
depends only on its normal, the view direction and the closure, not on where the sphere sits.  A sphere
is rendered once per closure (truth block) and every node-block variant of that closure is compared with
it cell by cell: both blocks put each sphere in a cell of exactly ``cell_px`` pixels, so a cell of one
block and a cell of the other see identical pixel centres (``cell_alignment`` checks the Normal passes).
"""
from __future__ import annotations

import math
import time
from dataclasses import dataclass
from pathlib import Path
from typing import ClassVar

import numpy as np


from ...core.materials.rt_lit_interface import Features
from ..harness import closures, scene_render
from . import suite_cases
from . import suite_scene
from .node_worlds import NODE_WORLDS
from .suite_cases import Variant
from . import suite_cases as suite
from ...core.conventions import ALPHA_MIN
from ...core.diffuse import cod_multiscatter_diffuse, cod_wrapped_diffuse_cosine
from ...core.environment import equirect
from ...core.microfacet import ggx_brdf
from ..harness import exr_images

CELL = 2.2                          # world units per sphere cell (suite_cases.CELL)
BLOCK_GAP = 60.0                    # the truth block sits this far below the node block (Z)
SPECULAR_ROUGHNESS = (0.1, 0.25, 0.5, 0.75, 1.0)
FURNACE_ROUGHNESS = (0.0, 0.25, 0.5, 0.75, 1.0)

#: technique -> (RT Lit features, Cycles closure of the truth or None (brute force), description).
TECHNIQUES = {
    "lambert": (Features("none", "lambert"), "DIFFUSE", "Lambert (SH irradiance) vs Cycles Diffuse BSDF"),
    "cod": (Features("none", "cod"), None,
            "CoD WWII diffuse (the talk's SH-LTC lobe) vs the brute-force integral of its BRDF"),
    "cod_wrapped": (Features("none", "cod_wrapped"), None,
                    "multiscattering wrapped diffuse, w = 0.5 (the wrapped lobe about the CoD SH-LTC axis) vs the "
                    "brute-force integral of its BRDF"),
    "ggx": (Features("single", "lambert"), "GGX", "single-scattering split sum, F0 = 1, vs Cycles Glossy GGX"),
    "turquin": (Features("turquin", "lambert"), "MULTI_GGX",
                "Turquin split sum, F0 = 1, vs Cycles Glossy Multiscatter GGX"),
    "fdez_aguera": (Features("fdez_aguera", "lambert"), "MULTI_GGX",
                    "Fdez-Aguera, irradiance form (Fss Ess P + Fms Ems I), F0 = 1, vs Multiscatter GGX"),
    "fdez_aguera_radiance": (Features("fdez_aguera", "lambert", environment_ms="radiance"), "MULTI_GGX",
                             "Fdez-Aguera, the talk's radiance form ((Fss Ess + Fms Ems) P), F0 = 1, "
                             "vs Multiscatter GGX"),
    "kulla_conty": (Features("kulla_conty", "lambert"), "MULTI_GGX",
                    "Kulla-Conty split sum + F_ms (1 - E) I, F0 = 1, vs Multiscatter GGX"),
}
#: Zeltner sheen (issue 17; the variant's roughness is the sheen roughness): its SH lobe vs Cycles' Sheen BSDF.
TECHNIQUES["zeltner"] = (Features("none", "lambert", sheen="zeltner"), "SHEEN",
                         "Zeltner sheen (SH cosine lobe about its LTC's peak, times its albedo) vs Cycles Sheen BSDF "
                         "(Microfiber)")
#: The sheen roughnesses of the zeltner row (full runs only).
SHEEN_ROUGHNESS = (0.2, 0.5, 0.9)
MULTISCATTER = ("turquin", "fdez_aguera", "fdez_aguera_radiance", "kulla_conty")
#: The rough diffuse and CoD against Cycles' Diffuse BSDF with Roughness sigma (closure "ROUGH_DIFFUSE", sigma):
#: the same references as under the lights (suite_cases "oren_nayar" / "cod_cycles"), white.
TECHNIQUES["oren_nayar"] = (Features("none", "oren_nayar"), "ROUGH_DIFFUSE",
                            "rough diffuse (Fujii + EON, SH-LTC + exact SH multiple scattering) vs Cycles Diffuse BSDF "
                            "with Roughness sigma")
TECHNIQUES["cod_cycles"] = (Features("none", "cod"), "ROUGH_DIFFUSE",
                            "CoD WWII diffuse (SH-LTC) with Roughness = sigma vs Cycles Diffuse BSDF with Roughness sigma")
ROUGH_DIFFUSE_ROUGHNESS = (0.5, 1.0)


def rough_diffuse_variants():
    """The rough diffuse and CoD rows (``node_variants(rough_diffuse=True)``)."""
    return [WorldVariant(t, r) for t in ("oren_nayar", "cod_cycles") for r in ROUGH_DIFFUSE_ROUGHNESS]


def technique_material(technique, roughness):
    """RT Lit input values (suite_cases.technique_material): white Lambert / CoD (built without
    specular: ``TECHNIQUES``), or a white metal (F0 = 1, no diffuse) for the specular techniques."""
    if technique in ("oren_nayar", "cod_cycles"):
        return suite.technique_material(technique, roughness, suite.WHITE)
    base = technique if technique in ("lambert", "cod", "cod_wrapped", "zeltner") else "ggx"
    return suite.technique_material(base, roughness)


@dataclass(frozen=True)
class WorldVariant(Variant):
    """A sphere under the world: ``techniques`` are the world's (features, Cycles closure, text)."""
    techniques: ClassVar[dict] = TECHNIQUES

    @property
    def closure(self):
        """(Cycles closure, roughness) of the truth sphere, or None."""
        kind = TECHNIQUES[self.technique][1]
        if kind is None:
            return None
        return (kind, 0.0 if kind == "DIFFUSE" else float(self.roughness))

    @property
    def label(self):
        if self.technique == "lambert":
            return self.technique
        return f"{self.technique} r={self.roughness:g}" + (f" w={self.wrap:g}" if self.technique == "cod_wrapped" else "")

    def material(self):
        return technique_material(self.technique, self.roughness)


@dataclass
class WorldSpec:
    """One world: an equirect image file, its Mapping rotation (Euler XYZ, radians) and strength."""
    name: str
    path: str
    rotation: tuple = (0.0, 0.0, 0.0)
    strength: float = 1.0
    hdri: str = ""                  # studio HDRI name ("" for a synthetic image)
    kind: str = "image"             # "image" (the file), or a world of nodes: NODE_WORLDS

    def describe(self):
        if self.kind != "image":
            return NODE_WORLDS[self.kind][1] + (f", strength {self.strength:g}" if self.strength != 1.0 else "")
        s = f"{self.hdri or Path(self.path).name}"
        if any(self.rotation):
            s += " rotated (" + ", ".join(f"{math.degrees(a):.0f}" for a in self.rotation) + ") deg"
        if self.strength != 1.0:
            s += f", strength {self.strength:g}"
        return s


def node_variants(quick=False, kulla_conty=True, rough_diffuse=False):
    """The node block: Lambert, then one row per technique over the roughness sweep (``rough_diffuse``: then the
    rough-diffuse rows)."""
    rough = (0.25, 0.75) if quick else SPECULAR_ROUGHNESS
    out = [WorldVariant("lambert")]
    techs = ["cod", "ggx", "turquin", "fdez_aguera", "fdez_aguera_radiance"]
    if kulla_conty and not quick:
        techs += ["kulla_conty", "cod_wrapped"]
    for t in techs:
        out += [WorldVariant(t, r) for r in rough]
    if not quick:
        out += [WorldVariant("zeltner", r) for r in SHEEN_ROUGHNESS]
    return out + (rough_diffuse_variants() if rough_diffuse else [])


def furnace_variants(quick=False):
    """Furnace block: F0 = 1 metals of every multiscattering model (and the single-scattering E for
    reference), plus Lambert, over FURNACE_ROUGHNESS."""
    rough = FURNACE_ROUGHNESS
    techs = ["turquin", "fdez_aguera", "fdez_aguera_radiance", "kulla_conty", "ggx"]
    if quick:
        techs = ["turquin", "fdez_aguera", "fdez_aguera_radiance"]
    return [WorldVariant("lambert")] + [WorldVariant(t, r) for t in techs for r in rough]


def truth_closures(variants):
    """The distinct closures the variants need, in order."""
    out = []
    for v in variants:
        c = v.closure
        if c is not None and c not in out:
            out.append(c)
    return out


# --- geometry ---------------------------------------------------------------------------------------

def euler_xyz_matrix(rotation):
    """Blender's Euler XYZ rotation matrix R = Rz(c) Ry(b) Rx(a) (the Mapping node applies R to the
    direction before the Environment Texture)."""
    a, b, c = (float(x) for x in rotation)
    rx = np.array([[1, 0, 0], [0, math.cos(a), -math.sin(a)], [0, math.sin(a), math.cos(a)]])
    ry = np.array([[math.cos(b), 0, math.sin(b)], [0, 1, 0], [-math.sin(b), 0, math.cos(b)]])
    rz = np.array([[math.cos(c), -math.sin(c), 0], [math.sin(c), math.cos(c), 0], [0, 0, 1]])
    return rz @ ry @ rx


def grid(n, columns):
    cols = min(columns, n)
    rows = math.ceil(n / cols)
    return cols, rows


def cell_centres(n, columns, z0=0.0):
    cols, rows = grid(n, columns)
    out = []
    for i in range(n):
        r, c = divmod(i, cols)
        out.append(((c - 0.5 * (cols - 1)) * CELL, 0.0, z0 + (0.5 * (rows - 1) - r) * CELL))
    return out


@dataclass
class Block:
    """A grid of spheres and the camera framing that puts each in a cell of cell_px pixels."""
    name: str
    objects: list
    columns: int
    rows: int
    z0: float
    cell_px: int

    @property
    def resolution(self):
        return (self.cell_px * self.columns, self.cell_px * self.rows)

    def cell(self, image, i):
        """The (cell_px, cell_px, ...) cell of sphere i in an image of this block (row 0 = top)."""
        r, c = divmod(i, self.columns)
        p = self.cell_px
        return image[r * p:(r + 1) * p, c * p:(c + 1) * p]


# --- scene ------------------------------------------------------------------------------------------

def write_constant_equirect(path, value=1.0, width=64, height=32):
    """A constant equirect EXR (the uniform furnace world as an Environment Texture)."""
    return exr_images.write_rgb(path, np.full((height, width, 3), float(value), np.float32))


def setup_world(scene, spec):
    """scene.world = Generated -> Mapping (Point, spec.rotation) -> Environment Texture (spec.path,
    Linear) -> Background (spec.strength) -> World Output; a world of nodes (``NODE_WORLDS``) for
    ``spec.kind`` other than "image"."""
    from ...addon import compat
    import bpy

    world = compat.new_world(f"RTL_val_world_{spec.name}")
    if spec.kind != "image":
        background = world.node_tree.nodes["Background"]
        background.inputs["Strength"].default_value = float(spec.strength)
        NODE_WORLDS[spec.kind][0](world.node_tree, background)
        scene.world = world
        return world
    nt = world.node_tree
    nt.nodes.clear()
    coords = nt.nodes.new("ShaderNodeTexCoord")
    mapping = nt.nodes.new("ShaderNodeMapping")
    mapping.vector_type = "POINT"
    mapping.inputs["Rotation"].default_value = tuple(float(a) for a in spec.rotation)
    env = nt.nodes.new("ShaderNodeTexEnvironment")
    env.image = bpy.data.images.load(str(spec.path), check_existing=True)
    env.interpolation = "Linear"
    env.projection = "EQUIRECTANGULAR"
    bg = nt.nodes.new("ShaderNodeBackground")
    bg.inputs["Strength"].default_value = float(spec.strength)
    out = nt.nodes.new("ShaderNodeOutputWorld")
    nt.links.new(coords.outputs["Generated"], mapping.inputs["Vector"])
    nt.links.new(mapping.outputs["Vector"], env.inputs["Vector"])
    nt.links.new(env.outputs["Color"], bg.inputs["Color"])
    nt.links.new(bg.outputs["Background"], out.inputs["Surface"])
    for i, node in enumerate((coords, mapping, env, bg, out)):
        node.location = (i * 250.0, 0.0)
    scene.world = world
    return world


def _sphere(mesh, name, location, material):
    import bpy

    me = mesh.copy()
    me.materials.append(material)
    ob = bpy.data.objects.new(name, me)
    ob.location = location
    for attr in ("visible_glossy", "visible_diffuse", "visible_transmission", "visible_volume_scatter",
                 "visible_shadow"):
        setattr(ob, attr, False)
    bpy.context.scene.collection.objects.link(ob)
    return ob


def closure_material(closure, name):
    """Cycles closure material of a truth sphere: ("DIFFUSE", 0) white Diffuse BSDF (roughness 0 =
    Lambert), ("GGX" | "MULTI_GGX", r) white Glossy BSDF (F = 1)."""
    kind, r = closure
    technique = {"DIFFUSE": "lambert", "GGX": "ggx", "MULTI_GGX": "turquin", "ROUGH_DIFFUSE": "oren_nayar", "SHEEN": "zeltner"}[kind]
    color = suite_cases.WHITE if kind == "ROUGH_DIFFUSE" else None        # white, as the node block's variants
    return closures.closure_material(Variant(technique, r, color), name)


def new_scene():
    import bpy

    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.data.type = "ORTHO"
    cam.data.sensor_fit = "HORIZONTAL"
    cam.data.clip_start, cam.data.clip_end = 0.1, 100.0
    cam.rotation_euler = (math.pi / 2, 0.0, 0.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    return scene


def sphere_mesh(segments=192, rings=96):
    import bpy

    existing = bpy.data.meshes.get("RTL_valw_sphere")
    return existing or scene_render.uv_sphere_mesh("RTL_valw_sphere", segments, rings)


def add_node_block(scene, variants, cell_px, columns, z0=0.0, lut_dir=None, mesh=None, name="node"):
    """RT Lit spheres (one per variant) in a grid centred at (0, 0, z0)."""
    from ...addon import compat, materials

    mesh = mesh or sphere_mesh()
    objects = []
    for i, (variant, centre) in enumerate(zip(variants, cell_centres(len(variants), columns, z0))):
        mat = compat.new_material(f"RTL_valw_{name}_{i}")
        materials.assign_rt_lit(mat, variant.features, scene, lut_dir)
        node = mat.node_tree.nodes["RT Lit"]
        for k, v in variant.material().items():
            node.inputs[k].default_value = tuple(v) + (1.0,) if isinstance(v, tuple) else v
        objects.append(_sphere(mesh, f"RTL_valw_{name}_{i}", centre, mat))
    cols, rows = grid(len(variants), columns)
    return Block(name, objects, cols, rows, z0, cell_px)


def add_truth_block(scene, closures, cell_px, columns, z0=-BLOCK_GAP, mesh=None, name="truth"):
    """Closure spheres (one per distinct closure) in a grid centred at (0, 0, z0)."""
    mesh = mesh or sphere_mesh()
    objects = []
    for i, (closure, centre) in enumerate(zip(closures, cell_centres(len(closures), columns, z0))):
        objects.append(_sphere(mesh, f"RTL_valw_{name}_{i}", centre, closure_material(closure, f"RTL_valw_{name}_{i}")))
    cols, rows = grid(len(closures), columns)
    return Block(name, objects, cols, rows, z0, cell_px)


def frame(scene, block, blocks):
    """Point the camera at ``block`` (others hidden from the render) and set the resolution."""
    for b in blocks:
        for ob in b.objects:
            ob.hide_render = b is not block
    cam = scene.camera
    cam.data.ortho_scale = CELL * block.columns
    cam.location = (0.0, -20.0, block.z0)
    scene.render.resolution_x, scene.render.resolution_y = block.resolution
    scene.render.resolution_percentage = 100
    return block.resolution


def block_index(block, normal):
    """Per pixel of a block image: the sphere index (cell) where the Normal pass is non-zero, else -1."""
    h, w = normal.shape[:2]
    p = block.cell_px
    idx = np.arange(h)[:, None] // p * block.columns + np.arange(w)[None, :] // p
    idx = np.where(np.linalg.norm(normal, axis=-1) > 0.5, idx, -1)
    idx[idx >= len(block.objects)] = -1
    return idx


# --- renders ----------------------------------------------------------------------------------------

def render_node(scene, block, blocks, folder):
    """(a): the RT Lit block rendered, 1 sample at pixel centres, with passes."""
    from ..harness.engines import render_cycles_passes

    res = frame(scene, block, blocks)
    return render_cycles_passes(scene, res, path=folder)


def render_truth(scene, block, blocks, samples, seeds, folder, threads=2):
    """(c): the closure block rendered with Cycles path tracing, direct light only, once per seed.
    Returns ([rgb per seed], [seconds per seed], normal)."""
    frame(scene, block, blocks)
    images, seconds, normal = [], [], None
    for seed in seeds:
        suite_scene.configure_truth_render(scene, samples, seed, threads)
        path = Path(folder) / f"truth_seed{seed}.exr"
        seconds.append(scene_render.render_exr(scene, path))
        rgb, nrm = scene_render.read_passes(path)
        images.append(rgb)
        normal = nrm
    return images, seconds, normal


# --- (b) numpy ----------------------------------------------------------------------------------------

def world_params_numpy(params):
    """world_parameters(scene) values as numpy (tuples -> arrays)."""
    return {k: (np.asarray(v, np.float64) if isinstance(v, (tuple, list, np.ndarray)) else float(v))
            for k, v in params.items()}


# --- brute-force references --------------------------------------------------------------------------

def image_quadrature(image, size=(128, 64)):
    """Texel directions (T, 3) (image frame), solid-angle weights (T,) and radiance (T, 3) of an equirect
    image area-averaged (equirect.downsample, solid-angle weighted) to ``size`` = (W, H)."""
    image = np.asarray(image, np.float32)
    w, h = size
    f = image.shape[1] // w
    if f < 1 or image.shape[1] % w or image.shape[0] // f != h:
        raise ValueError(f"cannot area-average {image.shape[1]}x{image.shape[0]} to {w}x{h}")
    small = equirect.downsample(image, f) if f > 1 else image
    dirs = equirect.texel_directions(h, w).reshape(-1, 3)
    wts = equirect.texel_solid_angles(h, w).reshape(-1)
    return dirs, wts, np.asarray(small, np.float64).reshape(-1, 3)


def lambert_reference_image(quad, n, chunk=512):
    """Lambert (albedo 1) radiance int L(l) max(n.l, 0) dl / pi over the image's texels; n (K, 3) in the
    image frame -> (K, 3)."""
    dirs, wts, rad = quad
    weighted = rad * wts[:, None]
    out = np.empty((len(n), 3))
    for s in range(0, len(n), chunk):
        out[s:s + chunk] = np.maximum(n[s:s + chunk] @ dirs.T, 0.0) @ weighted / math.pi
    return out


def cod_reference_image(quad, n, v, roughness, chunk=64, wrap=None):
    """Brute force of the true CoD WWII BRDF (albedo 1) over the image's texels:
    int L(l) f_CoD(l, v) (n.l) dl, n and v (K, 3) unit in the image frame, roughness (K,) -> (K, 3).
    With ``wrap`` (a float): the multiscattering wrapped diffuse instead (``core.diffuse.cod_wrapped_diffuse_cosine``,
    whose support reaches below the horizon)."""
    dirs, wts, rad = quad
    n = np.asarray(n, np.float64)
    v = np.asarray(v, np.float64)
    r = np.broadcast_to(np.asarray(roughness, np.float64), (len(n),))
    out = np.empty((len(n), 3))
    for s in range(0, len(n), chunk):
        nn, vv, rr = n[s:s + chunk], v[s:s + chunk], r[s:s + chunk]
        mu_l = nn @ dirs.T                                                     # (k, T)
        mu_v = np.clip(np.sum(nn * vv, axis=-1), 0.0, 1.0)[:, None]
        h = dirs[None, :, :] + vv[:, None, :]
        h /= np.maximum(np.linalg.norm(h, axis=-1, keepdims=True), 1e-300)
        n_dot_h = np.einsum("kti,ki->kt", h, nn)
        l_dot_h = np.einsum("kti,ti->kt", h, dirs)
        alpha = np.maximum(rr * rr, ALPHA_MIN)[:, None]
        if wrap is not None:
            f_cos = cod_wrapped_diffuse_cosine(1.0, nn[:, None, :], vv[:, None, :], dirs[None, :, :], alpha, wrap)
            out[s:s + chunk] = (f_cos * wts[None, :]) @ rad
            continue
        f = cod_multiscatter_diffuse(1.0, mu_l, mu_v, n_dot_h, l_dot_h, alpha)
        out[s:s + chunk] = (f * np.maximum(mu_l, 0.0) * wts[None, :]) @ rad
    return out


# --- the world sync (addon/world.py) --------------------------------------------------------------------

def sync_world(scene, cache_dir, lut_dir=None):
    """Bake (cached in ``cache_dir``) and sync the scene's world for RT Lit (``addon.world``): returns
    (WorldEnvironment, world_parameters(scene), EnvironmentBake, the image array Cycles renders at the
    Background's strength 1 (``world_array``: the image's pixels, a constant, or Cycles' render of the world;
    scene linear, top row first))."""
    from ...addon import materials
    from ...addon import world_sync as addon_world

    setup = addon_world.world_setup(scene.world)
    if not setup.usable:
        raise RuntimeError(f"the validation world is not usable by RT Lit: {setup.reason}")
    job = addon_world.bake_job(scene, cache_dir)
    bake = job()
    record = addon_world.sync_world(scene, cache_dir, bake=bake)
    if record is None:
        raise RuntimeError("sync_world built no 'RTL World' group")
    materials.rebuild_rt_lit_groups(scene, lut_dir)
    found = addon_world.world_environment()
    if found is None:
        raise RuntimeError("no 'RTL World' group with a bake record after sync_world")
    image = job.array
    if image.shape[0] < 2:                                # a constant world: one texel, the studies want a grid
        image = np.broadcast_to(image, (512, 1024, 3)).copy()
    return found[0], addon_world.world_parameters(scene), bake, image


def world_source():
    """Where the synced World term's image came from ("image", "constant", "render": ``WorldSetup.source``)."""
    from ...addon import world_sync as addon_world

    found = addon_world.world_environment()
    return None if found is None else found[1].get("source")


def measure_bake(scene, cache_dir):
    """Bake time of the scene's world as RT Lookdev > Sync World bakes it (``addon.world.bake_world``:
    the image's pixels through ``core.environment.prefilter.bake_environment_image``), forced, then a
    cached re-run: {"forced" | "cached": {"states", "seconds" (the bake's own), "wall" (the call)}}."""
    from ...addon import world_sync as addon_world

    out = {}
    for key, force in (("forced", True), ("cached", False)):
        t0 = time.perf_counter()
        bake = addon_world.bake_world(scene, cache_dir, force=force)
        out[key] = {"states": dict(bake.states), "seconds": dict(bake.seconds), "wall": time.perf_counter() - t0}
    return out


# --- comparisons ------------------------------------------------------------------------------------------

def cell_alignment(block_a, normal_a, i, block_c, normal_c, j):
    """Mask of the pixels where sphere i of block a and sphere j of block c both have a normal and the
    normals agree (max |difference| < 1e-4), and the largest difference over the common pixels."""
    na, nc = block_a.cell(normal_a, i), block_c.cell(normal_c, j)
    hit = (np.linalg.norm(na, axis=-1) > 0.5) & (np.linalg.norm(nc, axis=-1) > 0.5)
    diff = np.abs(na - nc).max(axis=-1)
    return hit & (diff < 1e-4), float(diff[hit].max()) if hit.any() else 0.0


def max_fraction(c, mask, floor_frac):
    """The floor ``floor_frac`` x median(c) over the mask's values, as a fraction of their max (what
    suite_metrics.truth_metrics and metrics.rel_values take).  Under an environment the max is a
    sun's highlight, hundreds of times the typical value, so a max-relative floor would keep only the
    highlight; the median-relative floor keeps every value but the nearly black ones."""
    cv = np.asarray(c, np.float64)[mask].ravel()
    cv = cv[np.isfinite(cv) & (cv > 0)]
    if not cv.size:
        return floor_frac
    return float(floor_frac * np.median(cv) / cv.max())


def rel_stats(x, ref, floor_frac=0.0):
    """mean / median / p90 / max of |x - ref| / ref over values (rows x channels) with ref above
    floor_frac x median(ref) (``max_fraction``); also the mean signed error (bias)."""
    x = np.asarray(x, np.float64).ravel()
    ref = np.asarray(ref, np.float64).ravel()
    pos = ref[np.isfinite(ref) & (ref > 0)]
    floor = floor_frac * np.median(pos) if pos.size else 0.0
    sel = np.isfinite(ref) & (ref > floor) & (ref > 0)
    rel = np.abs(x[sel] - ref[sel]) / ref[sel]
    if not rel.size:
        return None
    return {"values": int(rel.size), "mean": float(rel.mean()), "median": float(np.median(rel)),
            "p90": float(np.percentile(rel, 90)), "max": float(rel.max()),
            "bias": float(np.mean((x[sel] - ref[sel]) / ref[sel]))}


def ggx_reference_image(quad, n, v, roughness, chunk=16):
    """Brute force of the single-scattering GGX BRDF (F = 1, height-correlated Smith: Cycles' Glossy GGX)
    over the image's texels: int L(l) f_ss(l, v) (n.l) dl, n and v (K, 3) unit in the image frame.
    Point-sampling texel centres: meaningful where the lobe spans several texels (alpha >~ 4 x texel)."""
    dirs, wts, rad = quad
    alpha = max(float(roughness) ** 2, ALPHA_MIN)
    out = np.empty((len(n), 3))
    for s in range(0, len(n), chunk):
        nn, vv = n[s:s + chunk], v[s:s + chunk]
        mu_l = nn @ dirs.T
        mu_v = np.clip(np.sum(nn * vv, axis=-1), 0.0, 1.0)[:, None]
        h = dirs[None, :, :] + vv[:, None, :]
        h /= np.maximum(np.linalg.norm(h, axis=-1, keepdims=True), 1e-300)
        n_dot_h = np.einsum("kti,ki->kt", h, nn)
        v_dot_h = np.einsum("kti,ki->kt", h, vv)
        f = ggx_brdf(mu_l, mu_v, n_dot_h, v_dot_h, alpha)
        out[s:s + chunk] = (f * np.maximum(mu_l, 0.0) * wts[None, :]) @ rad
    return out
