"""RT Lit in Cycles: how many lights fit one material, and what each costs (with and without the World term).

    python scripts/benchmark_rt_lit.py [--out docs/benchmarks] [--repeats 3] [--only LABEL]

Cycles' SVM keeps a material's live values on a stack of 255 floats; a material with too many
values alive at once fails to compile ("out of SVM stack space") and renders black.  RT Lit emits
one closure per light so that Cycles compiles the lights one after another, but values shared
between lights stay live.  For each feature set this script adds quad lights one at a time
(doubling, then bisecting) until the material no longer renders, and times a 64x64, 1-sample
render with 1 light and with the most that fit.

The same search is repeated with the World term on: a studio HDRI world (``build_demo_scene.
add_hdri_world``: Background <- Environment Texture <- Mapping, no importance map, invisible to the
camera) synced by ``addon.world.sync_world`` so the RT Lit group includes the World term.  It
starts at 0 lights (the World term alone must render) and from the capacity without world.  The
World term's cost is timed on the 1-light scene (no world / the HDRI world but no World term in the
material / the World term) and at the World capacity, and counted in flattened IR operations.

"Renders" means any pixel of the 64x64 image is > 0 (the camera does not see the world, so only the
material can light a pixel).  Cycles' log line "out of SVM stack space" is captured as a cross-check.
The bake of the world is cached (``RTL_ENVIRONMENT_CACHE``, else ``~/.cache/rt_lookdev/environments``).
Writes rt_lit.md / rt_lit.json.
"""
from __future__ import annotations

import argparse
import contextlib
import json
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from ..harness import entry
from ...core.materials.cycles_capacity import SEARCHED_UP_TO as MAX_LIGHTS
from ...core.materials import rt_lit
from ...core.materials.rt_lit_interface import Features
from ...core.materials.rt_lit_interface import rt_lit_group_name


REPO = Path(__file__).resolve().parents[2]
RESOLUTION = (64, 64)
HDRI, WORLD_STRENGTH = "forest", 0.5
SVM_OVERFLOW = "out of SVM stack space"
#: World setups of ``lights_scene``: no world; the HDRI world but RT Lit without World term (no sync); both.
NO_WORLD, HDRI_ONLY, WORLD_TERM = "none", "hdri", "term"

VALUES = {"Base Color": (0.7, 0.3, 0.2, 1.0), "Metallic": 0.3, "Roughness": 0.35, "Wrap": 0.4,
          "Sheen Weight": 0.6, "Cloth Weight": 0.5, "Cloth Color": (0.5, 0.9, 0.6, 1.0)}

_BAKE = {}


def _world(scene, mode):
    """Give ``scene`` the HDRI world (``mode`` HDRI_ONLY or WORLD_TERM) and, for WORLD_TERM, the
    "RTL World" group (the bake is made or found in the cache once per process)."""
    import bpy

    from ...addon import demo_scene as build_demo_scene
    from ...addon import world_sync as rtl_world

    build_demo_scene.add_hdri_world(bpy, scene, HDRI, WORLD_STRENGTH)
    if mode == WORLD_TERM:
        if "bake" not in _BAKE:
            _BAKE["bake"] = rtl_world.bake_world(scene)
        if rtl_world.sync_world(scene, bake=_BAKE["bake"]) is None:
            raise RuntimeError(f"the {HDRI} world is not usable: {rtl_world.world_setup(scene.world).reason}")


def lights_scene(features, count, world=NO_WORLD):
    """A fresh scene: one sphere with an RT Lit material of ``features`` before ``count`` quad lights on a circle,
    the world of ``world`` (NO_WORLD, HDRI_ONLY or WORLD_TERM); returns (scene, material)."""
    from ...addon import compat
    import bmesh
    import bpy

    from ...addon import materials

    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    scene.world = None
    if world != NO_WORLD:
        _world(scene, world)
    for i in range(count):
        data = bpy.data.lights.new(f"Quad {i:02d}", "AREA")
        data.shape, data.size, data.size_y, data.energy = "RECTANGLE", 1.0, 0.5, 100.0
        obj = bpy.data.objects.new(data.name, data)
        angle = 2.0 * np.pi * i / max(count, 1)
        obj.location = (2.0 * np.cos(angle), -2.5, 2.0 * np.sin(angle))
        obj.rotation_mode = "QUATERNION"
        obj.rotation_quaternion = (-obj.location).to_track_quat("-Z", "Y")
        scene.collection.objects.link(obj)
    materials.sync_scene_lights(scene)
    mesh = bpy.data.meshes.new("sphere")
    bm = bmesh.new()
    bmesh.ops.create_uvsphere(bm, u_segments=32, v_segments=16, radius=1.0)
    bm.to_mesh(mesh)
    bm.free()
    mat = compat.new_material("m")
    materials.assign_rt_lit(mat, features, scene)
    node = mat.node_tree.nodes["RT Lit"]
    for k, v in VALUES.items():
        node.inputs[k].default_value = v
    mesh.materials.append(mat)
    scene.collection.objects.link(bpy.data.objects.new("sphere", mesh))
    cam = bpy.data.objects.new("cam", bpy.data.cameras.new("cam"))
    cam.data.type, cam.data.ortho_scale = "ORTHO", 2.4
    cam.location, cam.rotation_euler = (0.0, -6.0, 0.0), (np.pi / 2, 0.0, 0.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    return scene, mat


@contextlib.contextmanager
def captured_output():
    """Collect what the process writes to fd 1 and 2 (Cycles logs there from C++); yields a list that
    holds the text afterwards."""
    text = []
    sys.stdout.flush()
    sys.stderr.flush()
    saved = (os.dup(1), os.dup(2))
    with tempfile.TemporaryFile(mode="w+b") as tmp:
        try:
            os.dup2(tmp.fileno(), 1)
            os.dup2(tmp.fileno(), 2)
            yield text
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            os.close(saved[0])
            os.close(saved[1])
            tmp.seek(0)
            text.append(tmp.read().decode("utf-8", "replace"))


def _renders(features, count, repeats=1, world=NO_WORLD, detail=False):
    """(renders, median render seconds) of ``count`` quad lights; with ``detail``, a third item
    {"svm_overflow": Cycles logged it}."""
    from ..harness.engines import render_engines

    scene, mat = lights_scene(features, count, world)
    times, image = [], None
    with captured_output() as log:
        for _ in range(repeats):
            out = render_engines(scene, engines=("CYCLES",), resolution=RESOLUTION)
            image, seconds = out["CYCLES"]
            times.append(seconds)
    result = (bool(image.max() > 0.0), statistics.median(times))
    return result + ({"svm_overflow": SVM_OVERFLOW in "".join(log)},) if detail else result


def capacity(features, world=NO_WORLD, hint=None, log=print, checks=None, max_lights=None):
    """(largest N <= max_lights (default MAX_LIGHTS) whose material renders, capped at max_lights).  Without world the
    search starts at 1 light (0 lights light nothing), with the World term at 0 lights; N is one less
    than that start (0, or -1: the World term alone does not fit) when the start fails.  ``hint``: a
    likely answer (the capacity without world), tried first, then hint + 1 or hint - 1, -2, -4, ...
    Assumes more lights never fit when fewer do not.  ``checks`` (a dict): filled with
    {N: (renders, svm_overflow logged)}."""
    cap = MAX_LIGHTS if max_lights is None else max_lights
    works = {} if checks is None else checks

    def ok(n):
        if n not in works:
            rendered, _, info = _renders(features, n, world=world, detail=True)
            works[n] = (rendered, info["svm_overflow"])
        return works[n][0]

    lo = 0 if world == WORLD_TERM else 1
    if not ok(lo):
        return lo - 1, False
    hi = None
    if hint is not None and lo < hint <= cap:
        if ok(hint):
            lo = hint
        else:                        # gallop down from the hint
            hi, step = hint, 1
            while hi - step > lo and not ok(hi - step):
                hi, step = hi - step, step * 2
            lo = max(lo, hi - step)
    while hi is None:                # ok(lo): grow (lo + 1 right after a hint, else doubling)
        if lo >= cap:
            return cap, True
        nxt = lo + 1 if lo == hint else min(max(2 * lo, 1), cap)
        lo, hi = (nxt, None) if ok(nxt) else (lo, nxt)
    while hi - lo > 1:               # ok(lo), not ok(hi)
        mid = (lo + hi) // 2
        lo, hi = (mid, hi) if ok(mid) else (lo, mid)
    return lo, False


def timed(features, configs, rounds):
    """{(count, world): median render seconds} of each config (lights, world), measured in interleaved
    rounds so that other load on the machine affects all alike: each config's scene is built once and
    saved; each round opens each saved file and renders it twice, timing the second (the first render
    after a load also loads images)."""
    import bpy

    from ..harness.engines import render_engines

    times = {cfg: [] for cfg in configs}
    with tempfile.TemporaryDirectory(prefix="rtl-benchmark-") as tmp:
        files = {}
        for count, world in configs:
            lights_scene(features, count, world)
            files[(count, world)] = str(Path(tmp) / f"{count}_{world}.blend")
            bpy.ops.wm.save_as_mainfile(filepath=files[(count, world)], copy=True)
        for _ in range(rounds):
            for cfg, path in files.items():
                bpy.ops.wm.open_mainfile(filepath=path)
                with captured_output():
                    for _ in range(2):
                        image, seconds = render_engines(bpy.context.scene, engines=("CYCLES",),
                                                        resolution=RESOLUTION)["CYCLES"]
                if not image.max() > 0.0:
                    raise RuntimeError(f"{features.label()}: {cfg[0]} lights, world {cfg[1]!r} rendered black")
                times[cfg].append(seconds)
    return {cfg: statistics.median(v) for cfg, v in times.items()}


def ir_counts(features, lights=1):
    """Flattened IR operation counts (``flat_node_count``, as scripts/demo_report.py) of the RT Lit
    material for ``lights`` quad lights, without and with the World term (folded as built, and
    unfolded), and the Blender nodes of the built group's Cycles tree (flattened).  Builds the World scene."""
    import bpy

    from ...addon import materials, world_sync

    counts = {}
    for world in (NO_WORLD, WORLD_TERM):
        lights_scene(features, lights, world)
        kinds = tuple(kind for _, kind in materials.synced_light_kinds())
        env = world_sync.world_environment()[0] if world == WORLD_TERM else None
        ng = bpy.data.node_groups[rt_lit_group_name(features)]
        key = "world" if world == WORLD_TERM else "no_world"
        counts[key] = {**rt_lit.op_counts(features, kinds, env), "blender_nodes_flat": materials.engine_node_counts(ng)["Cycles"]}
    counts["world_term"] = {k: counts["world"][k] - counts["no_world"][k] for k in counts["world"]}
    return counts


def _fmt_cap(most, capped):
    if most < 0:
        return "**none: the World term alone overflows**"
    return f"{most}{'+' if capped else ''}"


def _ratio(a, b):
    return a / b if a is not None and b else None


def feature_sets(only=None):
    """The measured feature sets; with ``only``, those whose label contains one of its strings."""
    sets = [Features("single", "lambert"), Features("turquin", "cod"), Features("fdez_aguera", "lambert"),
            Features("kulla_conty", "lambert"), Features("turquin", "cod", sheen=True),
            Features("single", "cod", cloth=True), Features("kulla_conty", "wrapped", sheen=True, cloth=True)]
    if only:
        sets = [f for f in sets if any(o in f.label() for o in only)]
    return sets


def _timing_configs(most, n):
    """The (lights, world) scenes timed for capacity ``most`` without and ``n`` with the World term."""
    configs = [(1, NO_WORLD), (1, HDRI_ONLY)] if most >= 1 else []
    configs += [(1, WORLD_TERM)] if n >= 1 else []
    configs += [(0, WORLD_TERM)] if n >= 0 else []
    configs += [(n, NO_WORLD), (n, WORLD_TERM)] if n >= 1 else []
    configs += [(most, NO_WORLD)] if most >= 1 else []
    return list(dict.fromkeys(configs))


def measure(features, reps, max_lights=None):
    """One row of the report: capacities without and with the World term, render times, node counts."""
    t0 = time.perf_counter()
    checks, world_checks = {}, {}
    most, capped = capacity(features, checks=checks, max_lights=max_lights)
    world_most, world_capped = capacity(features, WORLD_TERM, hint=most, checks=world_checks, max_lights=max_lights)
    t1 = time.perf_counter()
    n = world_most
    t = timed(features, _timing_configs(most, n), reps)
    one, many = t.get((1, NO_WORLD)), t.get((most, NO_WORLD))
    one_hdri, one_world, zero_world = t.get((1, HDRI_ONLY)), t.get((1, WORLD_TERM)), t.get((0, WORLD_TERM))
    many_world, many_no_world = t.get((n, WORLD_TERM)), t.get((n, NO_WORLD))
    t2 = time.perf_counter()
    counts = ir_counts(features, 1)
    # the cross-check: Cycles logs the overflow exactly when the image is black
    disagree = sorted({f"{'world ' if w else ''}{k}" for w, c in ((0, checks), (1, world_checks))
                       for k, (rendered, overflow) in c.items() if rendered == overflow})
    return {"features": features.label(), "max_quad_lights": most, "capped": capped,
            "render_1_light_s": one, "render_max_lights_s": many,
            "world_max_quad_lights": world_most, "world_capped": world_capped,
            "world_alone_overflows": world_most < 0,
            "render_1_light_hdri_world_no_term_s": one_hdri,
            "render_1_light_world_s": one_world,
            "world_ratio_1_light": _ratio(one_world, one),
            "render_0_lights_world_s": zero_world,
            "render_world_max_lights_no_world_s": many_no_world,
            "render_world_max_lights_world_s": many_world,
            "world_ratio_world_max_lights": _ratio(many_world, many_no_world),
            "node_counts_1_light": counts,
            "capacity_checks": {str(k): v[0] for k, v in sorted(checks.items())},
            "world_capacity_checks": {str(k): v[0] for k, v in sorted(world_checks.items())},
            "svm_log_disagrees": disagree,
            "seconds": round(time.perf_counter() - t0, 1),
            "seconds_by_part": {"capacity": round(t1 - t0, 1), "timing": round(t2 - t1, 1),
                                "node_counts": round(time.perf_counter() - t2, 1)}}


def _s(v):
    return "-" if v is None else f"{v:.3f} s"


def _x(v):
    return "-" if v is None else f"{v:.2f}x"


def _markdown_capacity(rows, reps):
    lines = ["# RT Lit in Cycles: lights per material", "",
             "Generated by `python scripts/benchmark_rt_lit.py`. A sphere with one RT Lit material (non-zero "
             "wrap, sheen, cloth and metallic, so Cycles folds nothing away) under N rectangle lights; the "
             "largest N whose material still compiles in Cycles (SVM stack of 255 floats: any pixel > 0), and "
             f"the {RESOLUTION[0]}x{RESOLUTION[1]}, 1-sample Cycles render time with 1 and with that many lights "
             f"(median of {reps} interleaved rounds: each timed scene is built once and saved, each round opens "
             "each file and renders it twice, timing the second; the time includes Cycles' scene sync and SVM compile, which dominate at this "
             "size).", "",
             f"With the World term: the same scene with the studio HDRI `{HDRI}` as the world (Background "
             f"strength {WORLD_STRENGTH} <- Environment Texture <- Mapping; no importance map, invisible to the "
             "camera, as `scripts/build_demo_scene.py add_hdri_world`), synced by `addon.world.sync_world` so "
             "the RT Lit material adds the World term (one more Emission closure). Its search starts at 0 "
             "lights: the World term alone must render.", "",
             "## Capacity", "",
             "| features | max quad lights | with World term | render, 1 light | render, max lights |",
             "|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['features']} | {_fmt_cap(r['max_quad_lights'], r['capped'])} | "
                     f"{_fmt_cap(r['world_max_quad_lights'], r['world_capped'])} | "
                     f"{_s(r['render_1_light_s'])} | {_s(r['render_max_lights_s'])} |")
    overflowing = [r["features"] for r in rows if r["world_alone_overflows"]]
    lines += ["", ("**The World term alone overflows Cycles' SVM stack (black even with 0 lights) for: "
                   + ", ".join(overflowing) + ".**") if overflowing else
              "The World term alone (0 lights) renders for every feature set."]
    bad = [f"{r['features']}: {', '.join(r['svm_log_disagrees'])}" for r in rows if r["svm_log_disagrees"]]
    lines.append("Cycles' log line \"out of SVM stack space\" was printed exactly for the black renders"
                 + (" except: " + "; ".join(bad) + "." if bad else "."))
    return lines


def _markdown_world_time(rows):
    lines = ["", "## Render time of the World term", "",
             "Same process and rounds as above. *HDRI, no term*: the world is there (Cycles "
             "loads its image and shades its background) but the RT Lit material has no World term. N = the "
             "capacity with the World term; ratio = World term / no world.", "",
             "| features | 1 light: no world | HDRI, no term | World term | ratio | 0 lights, World term | "
             "N | N lights: no world | World term | ratio |", "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        n = r["world_max_quad_lights"]
        lines.append(f"| {r['features']} | {_s(r['render_1_light_s'])} | {_s(r['render_1_light_hdri_world_no_term_s'])} | "
                     f"{_s(r['render_1_light_world_s'])} | {_x(r['world_ratio_1_light'])} | "
                     f"{_s(r['render_0_lights_world_s'])} | {n if n >= 1 else '-'} | "
                     f"{_s(r['render_world_max_lights_no_world_s'])} | {_s(r['render_world_max_lights_world_s'])} | "
                     f"{_x(r['world_ratio_world_max_lights'])} |")
    return lines


def _markdown_node_counts(rows, total):
    lines = ["", "## Node counts of the World term", "",
             "One RT Lit material with 1 quad light: flattened IR operations (`core/ir/numpy_backend."
             "flat_node_count`, every function call expanded, as `scripts/demo_report.py`), folded (as built) "
             "and without constant folding, and the Blender nodes of the built group's Cycles tree with nested "
             "groups flattened (addon/materials.ENGINE_TREES).", "",
             "| features | IR ops, no world | with world | World term | unfolded: no world | with world | "
             "World term | Blender nodes: no world | with world | World term |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        c = r["node_counts_1_light"]
        cells = [c[k][m] for m in ("ir_ops_folded", "ir_ops_unfolded", "blender_nodes_flat")
                 for k in ("no_world", "world", "world_term")]
        lines.append(f"| {r['features']} | " + " | ".join(f"{v:+d}" if i % 3 == 2 else str(v)
                                                           for i, v in enumerate(cells)) + " |")
    lines += ["", f"Whole run: {total:.0f} s."]
    return lines


def parse_args(argv):
    """The options of scripts/benchmark_rt_lit.py parsed from ``argv``."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, default=REPO / "docs" / "benchmarks")
    p.add_argument("--repeats", type=int, default=3, help="interleaved rounds per timing (median)")
    p.add_argument("--only", action="append", help="only the feature sets whose label contains this (repeatable)")
    p.add_argument("--quick", action="store_true",
                   help="smoke run: single + Lambert only, capacities searched up to 2 lights, 1 round")
    return p.parse_args(argv)


def run(args, progress=entry.flush_log):
    """Measure every feature set, write rt_lit.json and rt_lit.md to ``args.out``; returns the JSON's dict."""
    quick = getattr(args, "quick", False)
    reps = 1 if quick else args.repeats
    max_lights = 2 if quick else MAX_LIGHTS
    rows = []
    t_start = time.perf_counter()
    for features in feature_sets(args.only or (["single, lambert"] if quick else None)):
        rows.append(measure(features, reps, max_lights))
        progress(str(rows[-1]))
    total = round(time.perf_counter() - t_start, 1)
    args.out.mkdir(parents=True, exist_ok=True)
    result = {"resolution": list(RESOLUTION), "samples": 1, "repeats": reps, "hdri": HDRI,
              "world_strength": WORLD_STRENGTH, "max_lights": max_lights, "total_seconds": total,
              "cycles_threads": _threads(), "rows": rows}
    (args.out / "rt_lit.json").write_text(json.dumps(result, indent=2))
    markdown = to_markdown(result)
    (args.out / "rt_lit.md").write_text(markdown)
    progress(markdown.removesuffix("\n"))
    return result


def to_markdown(result):
    """The result as Markdown (rt_lit.md)."""
    rows = result["rows"]
    lines = (_markdown_capacity(rows, result["repeats"]) + _markdown_world_time(rows)
             + _markdown_node_counts(rows, result["total_seconds"]))
    return "\n".join(lines) + "\n"


def _threads():
    import bpy

    scene = bpy.context.scene
    return {"threads_mode": scene.render.threads_mode, "threads": scene.render.threads}
