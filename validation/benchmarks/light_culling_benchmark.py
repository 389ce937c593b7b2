"""Lights out of range left out of each material's tree (issue 15, "skip what a scene does not need"), measured.

    python scripts/benchmark_light_culling.py [--out docs/benchmarks] [--repeats 3] [--quick]

Two scenes, each rendered by Cycles at 1 sample, 2 threads, with every light's range on (core/lights.py option
"range": Karis 2013's window, exactly 0 at and beyond the range):
- the demo scene (addon/demo_scene.py: 15 RT Lit spheres, each its own material, a quad and a disk light, the
  World term), each light's range set to its distance to the scene's centre, so each reaches about half of it;
- a 16-light grid: 4 x 4 spheres 4 m apart, a point light 1.5 m in front of each with a 5 m range, one RT Lit
  material per row of spheres (Turquin + CoD).
Per scene, culled (``addon.materials.cull_lights``: each material's group holds only the lights that reach its
objects) against every light in every tree (the same ranges, culling off): the Cycles-tree nodes per material, the
render time (median of ``repeats`` timed renders per round after an untimed one, two alternating rounds, whole
``render.render`` calls), and the two images' largest difference (0: the culled lights give exactly 0).
Writes ``light_culling.md`` and ``.json``.
"""
from __future__ import annotations

import argparse
import math
import statistics
import time

import numpy as np

from ..harness import entry, outputs, scene_render
from ...core.materials.rt_lit_interface import Features


def demo_scene(lut_dir, resolution):
    """The demo scene with each light's range its distance to the scene's centre."""
    import bpy

    from ...addon import materials
    from ...addon.demo_scene import build_demo_scene

    build_demo_scene(lut_dir, resolution, "forest", 0.5)
    scene = bpy.context.scene
    bpy.context.view_layer.update()                   # the world matrices the ranges are measured from
    for obj, kind in materials.scene_lights(scene):
        obj.data["rtl_use_range"] = True
        obj.data["rtl_range"] = float(obj.matrix_world.translation.length)
    bpy.context.view_layer.update()
    materials.sync_scene_lights(scene)
    return scene


def grid_scene(lut_dir, resolution, rows=4, columns=4, spacing=4.0, light_range=5.0):
    """``rows`` x ``columns`` spheres, a point light with a range in front of each, one material per row."""
    import bpy

    from ...addon import compat, materials

    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    centre = [(c - 0.5 * (columns - 1)) * spacing for c in range(columns)], \
             [(0.5 * (rows - 1) - r) * spacing for r in range(rows)]
    for r in range(rows):
        for c in range(columns):
            data = bpy.data.lights.new(f"Point {r}{c}", "POINT")
            data.energy, data.shadow_soft_size = 200.0, 0.0
            data["rtl_use_range"], data["rtl_range"] = True, light_range
            light = bpy.data.objects.new(f"Point {r}{c}", data)
            light.location = (centre[0][c] + 0.8, -1.5, centre[1][r] + 0.8)
            scene.collection.objects.link(light)
    materials.sync_scene_lights(scene)
    mesh = scene_render.uv_sphere_mesh("grid_sphere", 64, 32)
    for r in range(rows):
        mat = compat.new_material(f"Row {r}")
        materials.assign_rt_lit(mat, Features("turquin", "cod"), scene, lut_dir)
        for c in range(columns):
            obj = bpy.data.objects.new(f"Sphere {r}{c}", mesh.copy())
            obj.data.materials.append(mat)
            obj.location = (centre[0][c], 0.0, centre[1][r])
            scene.collection.objects.link(obj)
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.data.type, cam.data.ortho_scale = "ORTHO", spacing * columns
    cam.location, cam.rotation_euler = (0.0, -20.0, 0.0), (math.pi / 2, 0.0, 0.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    scene.render.resolution_x = scene.render.resolution_y = resolution
    bpy.context.view_layer.update()
    return scene


def _nodes(scene):
    import bpy

    from ...addon import materials

    out = {}
    for m in bpy.data.materials:
        node = m.node_tree.nodes.get("RT Lit") if m.node_tree else None
        if node is not None and node.node_tree is not None:
            out[m.name] = materials.engine_node_counts(node.node_tree)["Cycles"]
    return out


def _set_culling(scene, lut_dir, on):
    from ...addon import materials

    original = materials.material_reach
    if not on:
        materials.material_reach = lambda s, records: {}
    try:
        materials.rebuild_rt_lit_groups(scene, lut_dir)
    finally:
        materials.material_reach = original


def materials_lights(scene):
    from ...addon import materials

    return materials.scene_lights(scene)


def _lights_per_material(scene, lights):
    """{material: lights its culled group shades} (after a culled rebuild)."""
    from ...addon import materials

    _set_culling(scene, None, True)
    reach = materials.material_reach(scene, materials.scene_lights(scene))
    return {name: len(reach.get(name, range(lights))) for name in _nodes(scene)}


def measure(scene, lut_dir, resolution, repeats, rounds=2):
    from ..harness.engines import render_engines

    res = (scene.render.resolution_x, scene.render.resolution_y)
    runs = {"culled": {"seconds": []}, "every light": {"seconds": []}}
    for _ in range(rounds):
        for key, on in (("culled", True), ("every light", False)):
            _set_culling(scene, lut_dir, on)
            runs[key]["nodes"] = _nodes(scene)
            for i in range(repeats + 1):
                image, seconds = render_engines(scene, engines=("CYCLES",), resolution=res)["CYCLES"]
                if i:
                    runs[key]["seconds"].append(seconds)
            runs[key]["image"] = image
    lights = len(materials_lights(scene))
    runs["culled"]["lights_per_material"] = _lights_per_material(scene, lights)
    for key, r in runs.items():
        r["nodes_total"] = sum(r["nodes"].values())
        r["nodes_median"] = statistics.median(r["nodes"].values())
        r["seconds_median"] = statistics.median(r["seconds"])
    diff = float(np.abs(runs["culled"].pop("image") - runs["every light"].pop("image")).max())
    return {"runs": runs, "max_abs_difference": diff, "lights": lights,
            "node_ratio_total": runs["every light"]["nodes_total"] / runs["culled"]["nodes_total"],
            "speedup": runs["every light"]["seconds_median"] / runs["culled"]["seconds_median"]}


SCENES = {"demo": ("demo scene, ranges to its centre", demo_scene),
          "grid": ("16 point lights, 4 x 4 spheres, 5 m ranges", grid_scene)}


def run(args, progress=entry.flush_log):
    """Measure the scenes of ``args.scenes``; writes light_culling.md and .json in ``args.out``."""
    t0 = time.perf_counter()
    quick, lut_dir = args.quick, args.lut_dir
    resolution = 96 if quick else 256
    repeats = 1 if quick else args.repeats
    result = {"repeats": repeats, "resolution": resolution, "quick": quick, "scenes": {}}
    for key in (s for s in args.scenes.split(",") if s):
        name, build = SCENES[key]
        if quick and key == "grid":       # a 2 x 2 grid: the same code, seconds
            name, build = "4 point lights, 2 x 2 spheres, 5 m ranges", lambda d, r: grid_scene(d, r, 2, 2)
        scene = build(lut_dir, resolution)
        result["scenes"][name] = measure(scene, lut_dir, resolution, repeats, 1 if quick else 2)
        progress(f"[culling] {name}: nodes {result['scenes'][name]['node_ratio_total']:.2f}x fewer, render "
            f"{result['scenes'][name]['speedup']:.2f}x faster")
    result["seconds"] = time.perf_counter() - t0
    md = to_markdown(result)
    outputs.write_results(args.out, "light_culling", result, md)
    progress(md)
    return result


def to_markdown(result):
    """The result as Markdown (light_culling.md)."""
    L = ["# Lights out of range, left out of each material's tree", "",
         f"`python scripts/benchmark_light_culling.py` (validation/benchmarks/light_culling_benchmark.py; {result['seconds']:.0f} s "
         f"on 2 cores). Cycles, 1 sample, {result['resolution']}^2; every light has a range in both columns (the "
         "window is exactly 0 at and beyond it); 'culled': each material's RT Lit group holds only the lights that "
         "reach its objects (`addon/materials.py` `cull_lights`); 'every light': the same file with culling off. "
         f"Render: median of the timed renders ({result['repeats']} per round after an untimed one, alternating "
         "rounds), whole `render.render` calls.", "",
         "| scene | lights shaded per material, culled (of all) | Cycles-tree nodes per material, culled / every "
         "light (median) | all materials | render (s), culled / every light | nodes fewer | render faster | max "
         "difference of the images |",
         "|---|---|---|---|---|---|---|---|"]
    for name, s in result["scenes"].items():
        c, e = s["runs"]["culled"], s["runs"]["every light"]
        per = sorted(c["lights_per_material"].values())
        L.append(f"| {name} | {per[0]}-{per[-1]} (of {s['lights']}) | {c['nodes_median']:.0f} / {e['nodes_median']:.0f} | "
                 f"{c['nodes_total']} / "
                 f"{e['nodes_total']} | {c['seconds_median']:.3f} / {e['seconds_median']:.3f} | "
                 f"{s['node_ratio_total']:.2f}x | {s['speedup']:.2f}x | {s['max_abs_difference']:.1e} |")
    return "\n".join(L) + "\n"


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--out", default="docs/benchmarks", help="folder for light_culling.md / .json")
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--quick", action="store_true", help="96^2, one round of one render, a 2 x 2 grid")
    p.add_argument("--scenes", default="demo,grid", help="comma-separated: demo, grid")
    p.add_argument("--lut-dir", default=None)
    return p.parse_args(argv)
