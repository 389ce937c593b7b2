"""Build the demo lookdev scene: spheres across roughness, metal, cloth, wrap and sheen, lit by a
quad (rectangle) and a disk area light and a studio HDRI world (rotated by a Mapping node), every
material converted from Principled to RT Lit.

    python scripts/build_demo_scene.py [--out out/demo/lookdev_demo.blend] [--lut-dir DIR]
                                       [--hdri forest|none] [--world-strength 0.5]
    blender --background --python scripts/build_demo_scene.py -- [same options]

The HDRI is one of those inside Blender (``datafiles/studiolights/world``); its bake is cached
(addon/world_sync.py).  The world is invisible to Cycles' camera rays and has no importance map (the
materials are emission only), so the background is black.

The scene is emission-only (the RT Lit materials compute the lighting), so a 1-sample render
is the material's exact per-pixel value; ``configure_demo_render`` sets that up for Cycles.
"""
from __future__ import annotations

import argparse
from pathlib import Path


REPO = Path(__file__).resolve().parents[1]
DEFAULT_OUT = REPO / "out" / "demo" / "lookdev_demo.blend"

ROUGHNESS = (0.05, 0.25, 0.5, 0.75, 1.0)
SPACING = 1.0
RADIUS = 0.42

#: (row label, Principled inputs, RT Lit features) per row; roughness sweeps along the row.
ROWS = (
    ("dielectric", {"Base Color": (0.8, 0.25, 0.1, 1.0), "Metallic": 0.0},
     {"specular": "turquin", "diffuse": "cod"}),
    ("metal", {"Base Color": (1.0, 0.78, 0.34, 1.0), "Metallic": 1.0},
     {"specular": "kulla_conty", "diffuse": "lambert"}),
)

#: The third row: one sphere per variant at roughness 0.5.
VARIANTS = (
    ("cloth", {"Base Color": (0.1, 0.2, 0.6, 1.0), "Roughness": 0.6},
     {"specular": "single", "diffuse": "cod", "cloth": True}, {"Cloth Weight": 1.0,
                                                              "Cloth Color": (0.9, 0.7, 0.8, 1.0)}),
    ("wrap", {"Base Color": (0.85, 0.55, 0.45, 1.0), "Roughness": 0.5},
     {"specular": "turquin", "diffuse": "wrapped"}, {"Wrap": 0.5}),
    ("sheen", {"Base Color": (0.3, 0.05, 0.05, 1.0), "Roughness": 0.7, "Sheen Weight": 1.0,
               "Sheen Tint": (1.0, 1.0, 1.0, 1.0)},
     {"specular": "turquin", "diffuse": "cod", "sheen": True}, {}),
    ("fdez", {"Base Color": (0.95, 0.64, 0.54, 1.0), "Metallic": 1.0, "Roughness": 0.4},
     {"specular": "fdez_aguera", "diffuse": "lambert"}, {}),
    ("single", {"Base Color": (0.5, 0.5, 0.5, 1.0), "Roughness": 0.3},
     {"specular": "single", "diffuse": "lambert"}, {}),
)


DEFAULT_HDRI = "forest"
WORLD_ROTATION_Z = 1.2          # radians, the Mapping node's Z rotation


def add_hdri_world(bpy, scene, hdri, strength, rotation_z=WORLD_ROTATION_Z):
    """The lookdev scene's HDRI world (``lookdev_scene.add_hdri_world``), neither importance-sampled nor
    seen by the camera: the RT Lit materials are emission only, so Cycles needs no importance map of the
    world (building it cost ~0.8 s per demo render, measured), and the background is black, as EEVEE's
    measurement world (scripts/demo_report.py compares the two)."""
    from . import lookdev_scene

    world = lookdev_scene.add_hdri_world(scene, hdri, strength, rotation_z)
    world.cycles.sampling_method = "NONE"
    world.cycles_visibility.camera = False
    return world


def build_demo_scene(lut_dir=None, resolution=256, hdri=DEFAULT_HDRI, world_strength=0.5):
    """Build the scene in the current (emptied) file; returns {sphere name: features}.
    ``hdri=None`` (or "none"): no world, so no World term."""
    import bpy

    from . import convert, materials
    from . import world_sync as rtl_world
    from .lookdev_scene import light, ortho_camera, principled_material, sphere
    from ..core.materials.rt_lit_interface import Features

    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    scene.world = None
    if hdri and hdri != "none":
        add_hdri_world(bpy, scene, hdri, world_strength)
    rtl_world.sync_world(scene)       # a world that shows nothing: no "RTL World" group, no World term

    # lights first: the RT Lit groups are built for the scene's lights
    root = scene.collection
    light("Quad Key", "AREA", 600.0, (-2.0, -3.0, 2.5), (0.9, 0.0, -0.6), root, (1.0, 0.95, 0.9),
          shape="RECTANGLE", size=2.0, size_y=1.0)
    light("Disk Fill", "AREA", 300.0, (3.0, -2.5, 0.5), (1.45, 0.0, 0.85), root, (0.8, 0.9, 1.0),
          shape="DISK", size=1.5, size_y=1.5)
    materials.sync_scene_lights(scene)

    def factory(features):
        return materials.ensure_rt_lit_group(features, scene, lut_dir)

    spheres = {}
    x0 = -0.5 * (len(ROUGHNESS) - 1) * SPACING
    for row, (label, values, feats) in enumerate(ROWS):
        for col, r in enumerate(ROUGHNESS):
            name = f"{label} r{r:.2f}"
            mat = principled_material(name, dict(values, Roughness=r))
            features = Features(**feats)
            convert.principled_to_rt_lit(mat, factory, features)
            sphere(name, (x0 + col * SPACING, 0.0, (1 - row) * SPACING), mat, root, RADIUS)
            spheres[name] = features
    for col, (label, values, feats, rt_values) in enumerate(VARIANTS):
        mat = principled_material(label, values)
        features = Features(**feats)
        convert.principled_to_rt_lit(mat, factory, features)
        group = mat.node_tree.nodes["RT Lit"]
        for key, value in rt_values.items():
            group.inputs[key].default_value = value
        sphere(label, (x0 + col * SPACING, 0.0, -SPACING), mat, root, RADIUS)
        spheres[label] = features

    scene.camera = ortho_camera("Demo Camera", (0.0, -10.0, 0.0), (1.5707963267948966, 0.0, 0.0),
                                SPACING * len(ROUGHNESS) + 0.2, root)
    r = scene.render
    r.resolution_x = resolution
    r.resolution_y = resolution          # square (256^2 by default): the rows sit in the middle
    r.resolution_percentage = 100
    return spheres


def parse_args(argv):
    """The options of scripts/build_demo_scene.py parsed from ``argv`` (the arguments after Blender's
    ``--`` when run inside Blender: the script strips them)."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT)
    parser.add_argument("--lut-dir", type=Path, default=None)
    parser.add_argument("--resolution", type=int, default=256)
    parser.add_argument("--hdri", default=DEFAULT_HDRI, help="studio HDRI name or EXR path; 'none' for no world")
    parser.add_argument("--world-strength", type=float, default=0.5)
    return parser.parse_args(argv)


def run(args, log=print):
    """Build the scene in the current file and save it to ``args.out``; returns {sphere name: features}."""
    import bpy

    spheres = build_demo_scene(args.lut_dir, args.resolution, args.hdri, args.world_strength)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    bpy.ops.wm.save_as_mainfile(filepath=str(args.out.resolve()))
    log(f"demo scene: {len(spheres)} RT Lit spheres, saved to {args.out}")
    return spheres
