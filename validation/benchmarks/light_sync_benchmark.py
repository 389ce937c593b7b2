"""The automatic light sync (addon/light_sync.py), measured: what its depsgraph handler costs per update when nothing
it shades changed, and what a re-sync costs when something did.

    python scripts/benchmark_light_sync.py [--objects 100 1000] [--lights 10] [--repeats 200] [--runs 5]
                                           [--sync-lights 10 100] [--sync-runs 3]
                                           [--before earlier.json --before-label "..."]

Each scene: ``objects`` objects, of which ``lights`` are lights (quad, disk, point, spot, sun in turn) and the rest
meshes, with three RT Lit materials (default, every technique on, single + Lambert) in turn.  Measured in one
process, each scene built anew for each of ``runs`` runs; a run's figure is the median of ``repeats`` updates, the
report's the median of the runs' (with their range):
- ``handler_ms``: the handler's own time in one ``view_layer.update()`` (timed around it, registered in its place),
  for updates that change nothing it must act on: a light moved, one mesh moved, the selection changed, a value of
  an RT Lit material edited; without light ranges, and with every light but the sun given a range that reaches
  every object (which lights reach which material is then checked: ``materials.material_reach``);
- ``full_check_ms``: ``light_sync.sync_if_needed(scene)`` without a depsgraph (everything checked);
- ``update_moving_a_light_ms``: Blender's whole ``view_layer.update()`` after moving a light, with the handler
  registered and without it;
- ``resync_adding_a_light_ms``: the handler's re-sync when a point light is added (groups rebuilt), and
  ``snapshot_ms`` the part of it that makes a sync all or nothing (``common.node_groups_kept_on_error``);
- ``sync_sizes`` (``--sync-lights``, ``--sync-runs``): Sync Lights on a scene of one RT Lit material and that many
  point lights: the first sync (every group built), a sync with nothing changed, and one after a light was deleted
  and another made under its name (its drivers must be made again).
"""
from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path

from ...core.lut import catalog
from ...core.materials.rt_lit_interface import Features
from ..harness import entry

REPO = Path(__file__).resolve().parents[2]
KINDS = (("AREA", "SQUARE"), ("AREA", "DISK"), ("POINT", None), ("SPOT", None), ("SUN", None))
#: The updates timed, in order: name -> what the markdown calls it.
UPDATES = {"light_moved": "a light moved", "object_moved": "one mesh moved", "selection": "the selection changed",
           "material_edited": "an RT Lit material's Roughness edited"}
RESYNCS = 3


def _scene(bpy, objects, lights, lut_dir):
    from ...addon import compat, materials

    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    mats = []
    for features in (Features(), Features("kulla_conty", "wrapped", sheen=True, cloth=True), Features("single", "lambert")):
        mat = compat.new_material(f"RT Lit {features.label()}")
        materials.assign_rt_lit(mat, features, scene, lut_dir)
        mats.append(mat)
    meshes = []
    for i in range(objects - lights):
        obj = bpy.data.objects.new(f"Mesh {i:04d}", bpy.data.meshes.new(f"Mesh {i:04d}"))
        obj.data.materials.append(mats[i % len(mats)])
        obj.location = (i % 32, i // 32, 0.0)
        scene.collection.objects.link(obj)
        meshes.append(obj)
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
    bpy.context.view_layer.update()
    return scene, made, meshes, mats


def _median_ms(fn, repeats):
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        times.append((time.perf_counter() - t) * 1e3)
    return statistics.median(times)


class _TimedHandler:
    """The light sync's handler, timed: registered in its place, it records its time per call."""

    def __init__(self, bpy, light_sync):
        self.bpy, self.light_sync, self.times = bpy, light_sync, []

        def handler(scene, depsgraph=None):
            t = time.perf_counter()
            light_sync.on_depsgraph_update(scene, depsgraph)
            self.times.append((time.perf_counter() - t) * 1e3)
        self.handler = handler

    def __enter__(self):
        self.bpy.app.handlers.depsgraph_update_post.append(self.handler)
        return self

    def __exit__(self, *exc):
        self.bpy.app.handlers.depsgraph_update_post.remove(self.handler)

    def median_ms(self, change, repeats):
        """The handler's median time over ``repeats`` updates, each after ``change(step)``."""
        per_update = []
        for step in range(repeats):
            self.times.clear()
            change(step)
            self.bpy.context.view_layer.update()
            per_update.append(sum(self.times))
        return statistics.median(per_update)


def _changes(bpy, light, mesh, material):
    """The updates timed (``UPDATES``): step -> a change that leaves the lights and what they reach as they are."""
    from ...addon.common import RT_LIT_NODE_NAME

    roughness = material.node_tree.nodes[RT_LIT_NODE_NAME].inputs["Roughness"]

    def light_moved(step):
        light.location.x = 0.001 * (step % 100)

    def object_moved(step):
        mesh.location.z = 0.001 * (step % 100)

    def selection(step):
        mesh.select_set(step % 2 == 0)

    def material_edited(step):
        roughness.default_value = 0.3 + 0.001 * (step % 100)
    return {"light_moved": light_moved, "object_moved": object_moved, "selection": selection,
            "material_edited": material_edited}


def measure(bpy, objects, lights, repeats, lut_dir):
    """One run on a scene of ``objects`` objects: the figures of one entry of the report's ``scenes``."""
    from ...addon import light_sync

    scene, made, meshes, mats = _scene(bpy, objects, lights, lut_dir)
    light, step = made[0], [0]
    changes = _changes(bpy, light, meshes[0], mats[0])

    def move():
        step[0] += 1
        light.location.x = 0.001 * (step[0] % 100)
        bpy.context.view_layer.update()

    light_sync.unregister()
    without = _median_ms(move, repeats)
    light_sync.register()
    try:
        with_handler = _median_ms(move, repeats)
    finally:
        light_sync.unregister()
    handler = {}
    with _TimedHandler(bpy, light_sync) as timed:
        handler["without_ranges"] = {name: round(timed.median_ms(change, repeats), 4) for name, change in changes.items()}
        full = {"without_ranges": round(_median_ms(lambda: light_sync.sync_if_needed(scene), repeats), 4)}
        assert not light_sync.sync_if_needed(scene), "a moved light must not re-sync"
        snapshot = _snapshot_ms(bpy, RESYNCS)
        resync = []
        for i in range(RESYNCS):
            obj = bpy.data.objects.new(f"Added {i}", bpy.data.lights.new(f"Added {i}", "POINT"))
            scene.collection.objects.link(obj)
            t = time.perf_counter()
            assert light_sync.sync_if_needed(scene)
            resync.append((time.perf_counter() - t) * 1e3)
        # every light but the sun with a range that reaches every object: which lights reach which material is checked
        for obj in [o for o in scene.objects if o.type == "LIGHT" and o.data.type != "SUN"]:
            obj.data["rtl_use_range"], obj.data["rtl_range"] = True, 1000.0
            obj.data.update_tag()
        bpy.context.view_layer.update()
        light_sync.sync_if_needed(scene)
        bpy.context.view_layer.update()
        handler["with_ranges"] = {name: round(timed.median_ms(change, repeats), 4) for name, change in changes.items()}
        full["with_ranges"] = round(_median_ms(lambda: light_sync.sync_if_needed(scene), repeats), 4)
        assert not light_sync.sync_if_needed(scene), "a reach that did not change must not re-sync"
    return {"objects": objects, "lights": lights, "handler_ms": handler, "full_check_ms": full,
            "update_moving_a_light_ms": {"without_handler": round(without, 4), "with_handler": round(with_handler, 4),
                                         "difference": round(with_handler - without, 4)},
            "resync_adding_a_light_ms": round(statistics.median(resync), 1), "snapshot_ms": snapshot,
            "node_groups": len(bpy.data.node_groups)}


def measure_sync_size(bpy, lights, lut_dir):
    """One run of Sync Lights (``light_sync.sync_lights``) at ``lights`` point lights: {what: ms}."""
    from ...addon import compat, light_sync, materials

    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    mat = compat.new_material("RT Lit")
    materials.assign_rt_lit(mat, Features(), scene, lut_dir)
    obj = bpy.data.objects.new("Ball", bpy.data.meshes.new("Ball"))
    obj.data.materials.append(mat)
    scene.collection.objects.link(obj)
    light_sync.sync_lights(scene, lut_dir)

    def add_light(name, i):
        light = bpy.data.objects.new(name, bpy.data.lights.new(name, "POINT"))
        light.location = (0.1 * i, 2.0, 3.0)
        scene.collection.objects.link(light)

    def timed_sync():
        t = time.perf_counter()
        light_sync.sync_lights(scene, lut_dir)
        return round((time.perf_counter() - t) * 1e3, 1)

    for i in range(lights):
        add_light(f"Light {i:03d}", i)
    figures = {"first_ms": timed_sync(), "unchanged_ms": timed_sync()}
    bpy.data.objects.remove(bpy.data.objects["Light 000"])
    add_light("Light 000", 0)
    figures["replaced_light_ms"] = timed_sync()
    return figures


def _snapshot_ms(bpy, repeats):
    """What a sync's all-or-nothing costs when it succeeds (``common.node_groups_kept_on_error`` around nothing: the
    add-on's groups copied, then the copies removed); None for code without it."""
    try:
        from ...addon.common import node_groups_kept_on_error
    except ImportError:
        return None

    def transaction():
        with node_groups_kept_on_error():
            pass
    return round(_median_ms(transaction, repeats), 1)


def _median_of_runs(runs):
    """The runs' figures merged: each number the median of the runs' (``runs``: dicts of the same shape), with
    ``<key>_runs`` = [min, max] beside it for the timings."""
    first = runs[0]
    out = {}
    for key, value in first.items():
        if isinstance(value, dict):
            out[key] = _median_of_runs([r[key] for r in runs])
        elif isinstance(value, float) and all(isinstance(r[key], float) for r in runs):
            values = [r[key] for r in runs]
            out[key] = round(statistics.median(values), 4)
            out[f"{key}_runs"] = [min(values), max(values)]
        else:
            out[key] = value
    return out


def run(args, progress=entry.flush_log):
    """Measure the scenes of ``args.objects`` and the Sync Lights sizes; writes ``args.out`` (Markdown) and the JSON
    beside it."""
    import bpy

    lut_dir = args.lut_dir or catalog.default_lut_dir()
    scenes = []
    for objects in args.objects:
        runs = []
        for i in range(args.runs):
            runs.append(measure(bpy, objects, args.lights, args.repeats, lut_dir))
            h = runs[-1]["handler_ms"]["with_ranges"]
            progress(f"[light sync] {objects} objects, run {i + 1}/{args.runs}: handler with ranges "
                + ", ".join(f"{name} {ms:.3f} ms" for name, ms in h.items()))
        scenes.append(_median_of_runs(runs))
    sizes = []
    for lights in args.sync_lights:
        runs = []
        for i in range(args.sync_runs):
            runs.append(measure_sync_size(bpy, lights, lut_dir))
            progress(f"[light sync] Sync Lights at {lights} lights, run {i + 1}/{args.sync_runs}: "
                + ", ".join(f"{name} {ms:.0f}" for name, ms in runs[-1].items()))
        sizes.append({"lights": lights, **_median_of_runs(runs)})
    result = {"lights": args.lights, "repeats": args.repeats, "runs": args.runs, "scenes": scenes,
              "sync_runs": args.sync_runs, "sync_sizes": sizes, "blender": bpy.app.version_string}
    if args.before is not None:
        result["before"] = before_figures(json.loads(args.before.read_text()), args.before_label)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.with_suffix(".json").write_text(json.dumps(result, indent=1) + "\n")
    args.out.write_text(to_markdown(result))
    progress(f"[light sync] -> {args.out}")
    return result


def before_figures(before, label):
    """What the report shows of an earlier run of this benchmark (its JSON, ``before``), e.g. on the code before a
    change: its handler figures per scene, and ``label`` (what the code was)."""
    return {"label": label, "runs": before["runs"], "repeats": before["repeats"],
            "scenes": [{"objects": s["objects"], "handler_ms": s["handler_ms"], "full_check_ms": s["full_check_ms"]}
                       for s in before["scenes"]],
            "sync_runs": before.get("sync_runs"), "sync_sizes": before.get("sync_sizes", [])}


def _handler_table(scenes):
    lines = ["| update | " + " | ".join(f"{s['objects']} objects{ranged}" for s in scenes
                                         for ranged in ("", ", ranged lights")) + " |",
             "|---|" + "---|" * (2 * len(scenes))]
    for name, label in UPDATES.items():
        lines.append(f"| {label} | " + " | ".join(_ms(s["handler_ms"][ranges], name) for s in scenes
                                                    for ranges in ("without_ranges", "with_ranges")) + " |")
    return lines


def _ms(scene_figures, key, digits=3):
    value, (lo, hi) = scene_figures[key], scene_figures[f"{key}_runs"]
    return f"{value:.{digits}f} ms ({lo:.{digits}f}-{hi:.{digits}f})"


#: The Sync Lights figures (``measure_sync_size``): key -> what the markdown calls it.
SYNC_FIGURES = {"first_ms": "first sync (every group built)", "unchanged_ms": "again, nothing changed",
                "replaced_light_ms": "after a light was deleted and another made under its name"}


def _sync_size_table(sizes):
    lines = ["| Sync Lights | " + " | ".join(f"{s['lights']} lights" for s in sizes) + " |",
             "|---|" + "---|" * len(sizes)]
    for key, label in SYNC_FIGURES.items():
        lines.append(f"| {label} | " + " | ".join(_ms(s, key, 0) for s in sizes) + " |")
    return lines


def to_markdown(r):
    """The result as Markdown (light_sync.md)."""
    lines = [
        "# Automatic light sync: cost per depsgraph update", "",
        "Written by `python scripts/benchmark_light_sync.py` (validation/benchmarks/light_sync_benchmark.py).  Each scene: "
        f"its objects, {r['lights']} of them lights (quad, disk, point, spot, sun), the rest meshes with three RT Lit "
        f"materials in turn; Blender {r['blender']}, one process.  Each figure is the median of {r['runs']} runs "
        f"(their range in brackets), each run's the median of {r['repeats']} updates on a scene built anew.", "",
        "The handler's own time per `view_layer.update()`, for updates that change nothing it must act on (with "
        "ranges: every light but the sun has a range reaching every object, so which lights reach which material "
        "is checked):", "", *_handler_table(r["scenes"])] if r["scenes"] else [
        "# Automatic light sync: cost per depsgraph update", "",
        "Written by `python scripts/benchmark_light_sync.py` (validation/benchmarks/light_sync_benchmark.py); Blender "
        f"{r['blender']}, one process.  This run measured Sync Lights only (`--objects` with no sizes)."]
    if r["scenes"]:
        lines += ["", "| what | " + " | ".join(f"{s['objects']} objects" for s in r["scenes"]) + " |",
                  "|---|" + "---|" * len(r["scenes"])]
        rows = [("`sync_if_needed(scene)` without a depsgraph (everything checked)", "full_check_ms", "without_ranges", 3),
                ("the same with ranged lights", "full_check_ms", "with_ranges", 3),
                ("`view_layer.update()` after moving a light, without the handler", "update_moving_a_light_ms",
                 "without_handler", 3),
                ("the same with the handler registered", "update_moving_a_light_ms", "with_handler", 3)]
        for label, group, key, digits in rows:
            lines.append(f"| {label} | " + " | ".join(_ms(s[group], key, digits) for s in r["scenes"]) + " |")
        lines.append("| re-sync when a light is added (RT Lit groups rebuilt) | "
                     + " | ".join(_ms(s, "resync_adding_a_light_ms", 0) for s in r["scenes"]) + " |")
        if all(s.get("snapshot_ms") is not None for s in r["scenes"]):
            lines.append("| of which its all-or-nothing: the groups a sync changes copied, and the copies removed (of "
                         + " and ".join(f"{s['node_groups']}" for s in r["scenes"]) + " node groups in the file) | "
                         + " | ".join(_ms(s, "snapshot_ms", 1) for s in r["scenes"]) + " |")
    if r.get("sync_sizes"):
        lines += ["", f"Sync Lights (`light_sync.sync_lights`) on a scene of one RT Lit material and that many point "
                      f"lights; the median of {r['sync_runs']} runs (their range), each on a scene built anew:", "",
                  *_sync_size_table(r["sync_sizes"])]
    before = r.get("before")
    if before is not None and before.get("sync_sizes"):
        lines += ["", f"Before: {before['label']} (the same benchmark; medians of {before['sync_runs']} runs):", "",
                  *_sync_size_table(before["sync_sizes"])]
    if before is not None and before["scenes"]:
        lines += ["", f"Before: {before['label']} (the same benchmark; medians of {before['runs']} runs of "
                      f"{before['repeats']} updates):", "", *_handler_table(before["scenes"]), "",
                  "| `sync_if_needed(scene)` without a depsgraph | "
                  + " | ".join(f"{s['objects']} objects{ranged}" for s in before["scenes"]
                               for ranged in ("", ", ranged lights")) + " |",
                  "|---|" + "---|" * (2 * len(before["scenes"])),
                  "| everything checked | " + " | ".join(_ms(s["full_check_ms"], ranges) for s in before["scenes"]
                                                       for ranges in ("without_ranges", "with_ranges")) + " |"]
    return "\n".join(lines) + "\n"


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--objects", type=int, nargs="*", default=[100, 1000],
                   help="scene sizes for the handler's figures (none: only the Sync Lights figures)")
    p.add_argument("--sync-lights", type=int, nargs="*", default=[10, 100],
                   help="light counts for the Sync Lights figures (none: skip them)")
    p.add_argument("--sync-runs", type=int, default=3)
    p.add_argument("--lights", type=int, default=10)
    p.add_argument("--repeats", type=int, default=200)
    p.add_argument("--runs", type=int, default=5)
    p.add_argument("--lut-dir", type=Path, default=None)
    p.add_argument("--out", type=Path, default=REPO / "docs" / "benchmarks" / "light_sync.md")
    p.add_argument("--before", type=Path, default=None,
                   help="the JSON of an earlier run (e.g. on the code before a change), shown beside this one's")
    p.add_argument("--before-label", default="an earlier run", help="what the earlier run measured")
    return p.parse_args(argv)
