"""The automatic light sync (addon/light_sync.py), measured: what a depsgraph update costs when no light
changed, and what a re-sync costs when one did.

    python scripts/benchmark_light_sync.py [--objects 100] [--lights 10] [--repeats 200]

The scene: ``objects`` objects, of which ``lights`` are lights (quad, disk, point, spot, sun in turn) and the
rest meshes, with three RT Lit materials (default, every technique on, single + Lambert).  Measured in one
process (medians of ``repeats`` calls):
- ``no_change_check``: the handler's work on a relevant update that changes no light (a light moved): the
  scene's light signature against the stored one;
- ``update_moving_a_light``: Blender's whole ``view_layer.update()`` after moving a light, with the handler
  registered and without it, and their difference;
- ``resync_adding_a_light``: the handler's re-sync when a light is added (groups rebuilt).
"""
from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path
from ...core.lut import catalog
from ...core.materials.rt_lit_interface import Features

REPO = Path(__file__).resolve().parents[2]
KINDS = (("AREA", "SQUARE"), ("AREA", "DISK"), ("POINT", None), ("SPOT", None), ("SUN", None))


def _scene(bpy, objects, lights, lut_dir):
    from ...addon import compat, materials

    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    mats = []
    for features in (Features(), Features("kulla_conty", "wrapped", sheen=True, cloth=True), Features("single", "lambert")):
        mat = compat.new_material(f"RT Lit {features.label()}")
        materials.assign_rt_lit(mat, features, scene, lut_dir)
        mats.append(mat)
    for i in range(objects - lights):
        obj = bpy.data.objects.new(f"Mesh {i:03d}", bpy.data.meshes.new(f"Mesh {i:03d}"))
        obj.data.materials.append(mats[i % len(mats)])
        obj.location = (i % 10, i // 10, 0.0)
        scene.collection.objects.link(obj)
    made = []
    for i in range(lights):
        kind, shape = KINDS[i % len(KINDS)]
        data = bpy.data.lights.new(f"Light {i:02d}", kind)
        if shape:
            data.shape = shape
        obj = bpy.data.objects.new(f"Light {i:02d}", data)
        obj.location = (i, -3.0, 4.0)
        scene.collection.objects.link(obj)
        made.append(obj)
    materials.sync_scene_lights(scene)
    materials.rebuild_rt_lit_groups(scene, lut_dir)
    return scene, made


def _median_ms(fn, repeats):
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        times.append((time.perf_counter() - t) * 1e3)
    return statistics.median(times)


def run(args, log=print):
    import bpy

    from ...addon import light_sync

    lut_dir = args.lut_dir or catalog.default_lut_dir()
    scene, made = _scene(bpy, args.objects, args.lights, lut_dir)
    light = made[0]
    step = [0]

    def move():
        step[0] += 1
        light.location.x = 0.001 * (step[0] % 100)
        bpy.context.view_layer.update()

    light_sync.unregister()
    without = _median_ms(move, args.repeats)
    light_sync.register()
    try:
        with_handler = _median_ms(move, args.repeats)
        check = _median_ms(lambda: light_sync.sync_if_needed(scene), args.repeats)
        assert not light_sync.sync_if_needed(scene), "a moved light must not re-sync"
        resync = []
        for i in range(5):
            obj = bpy.data.objects.new(f"Added {i}", bpy.data.lights.new(f"Added {i}", "POINT"))
            scene.collection.objects.link(obj)
            t = time.perf_counter()
            assert light_sync.sync_if_needed(scene)
            resync.append((time.perf_counter() - t) * 1e3)
        # lights with a range: each update also checks which lights reach which material (materials.cull_lights)
        for obj in [o for o in scene.objects if o.type == "LIGHT" and o.data.type != "SUN"]:
            obj.data["rtl_use_range"], obj.data["rtl_range"] = True, 1000.0
        bpy.context.view_layer.update()
        light_sync.sync_if_needed(scene)
        ranged = _median_ms(lambda: light_sync.sync_if_needed(scene), args.repeats)
        assert not light_sync.sync_if_needed(scene), "a reach that did not change must not re-sync"
    finally:
        light_sync.unregister()
    result = {"objects": args.objects, "lights": args.lights, "repeats": args.repeats,
              "no_change_check_ms": round(check, 4), "no_change_check_with_ranges_ms": round(ranged, 4),
              "update_moving_a_light_ms": {"without_handler": round(without, 4), "with_handler": round(with_handler, 4),
                                           "difference": round(with_handler - without, 4)},
              "resync_adding_a_light_ms": round(statistics.median(resync), 1),
              "blender": bpy.app.version_string}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.with_suffix(".json").write_text(json.dumps(result, indent=1) + "\n")
    args.out.write_text(format_markdown(result))
    log(f"[light sync] no-change check {check:.3f} ms; update with handler {with_handler:.3f} ms, without "
        f"{without:.3f} ms; re-sync {result['resync_adding_a_light_ms']} ms -> {args.out}")
    return result


def format_markdown(r):
    u = r["update_moving_a_light_ms"]
    return "\n".join([
        "# Automatic light sync: cost per depsgraph update", "",
        "Written by `python scripts/benchmark_light_sync.py` (validation/benchmarks/light_sync_benchmark.py).  Scene: "
        f"{r['objects']} objects, {r['lights']} of them lights (quad, disk, point, spot, sun), three RT Lit "
        f"materials; medians of {r['repeats']} calls, Blender {r['blender']}, one process.", "",
        "| what | median |", "|---|---|",
        f"| handler's check on an update that changes no light (a light moved) | {r['no_change_check_ms']:.3f} ms |",
        f"| the same with every light given a range (the check of which lights reach which material) | "
        f"{r['no_change_check_with_ranges_ms']:.3f} ms |",
        f"| `view_layer.update()` after moving a light, without the handler | {u['without_handler']:.3f} ms |",
        f"| the same with the handler registered | {u['with_handler']:.3f} ms |",
        f"| difference | {u['difference']:.3f} ms |",
        f"| re-sync when a light is added (RT Lit groups rebuilt) | {r['resync_adding_a_light_ms']:.1f} ms |", ""])


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--objects", type=int, default=100)
    p.add_argument("--lights", type=int, default=10)
    p.add_argument("--repeats", type=int, default=200)
    p.add_argument("--lut-dir", type=Path, default=None)
    p.add_argument("--out", type=Path, default=REPO / "docs" / "benchmarks" / "light_sync.md")
    return p.parse_args(argv)
