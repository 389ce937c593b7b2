"""The demo lookdev scene, measured: node counts, Cycles and EEVEE renders, their agreement.

    python scripts/demo_report.py [--out out/report/demo] [--lut-dir DIR] [--resolution 256]
                                  [--repeats 3] [--skip-eevee] [--skip-realtime]

Builds the demo scene (scripts/build_demo_scene.py), saves it, and reports:
- node counts of every emitted group (largest group, per RT Lit material flattened), and the
  IR operations of each RT Lit material with and without folding (constant folding, identities,
  dead-branch removal);
- the Cycles render of the RT Lit materials at 1 sample (median of ``repeats`` timed renders);
- one EEVEE render (headless, Mesa llvmpipe) and its relative error against Cycles where
  Cycles > 1e-3 (EEVEE's film is half precision and it writes 0 for negative values);
- the real-time backend: the scene exported (addon/scene_export.py, into <out>/realtime_scene) and drawn
  by the standalone GLSL renderer (validation/harness/realtime_render.py, headless OpenGL 4.5), compared with the
  Cycles render per value where Cycles > 1e-3: targets median <= 1e-4, 99th percentile <= 1e-3 relative;
  the share of pixels covered in one render only, shader compile and frame times;
- PNG previews (Cycles, EEVEE, GLSL, the error maps with their colour bars).
Writes demo.json and demo.md into --out; exit 1 when a Cycles pixel is not finite or EEVEE and
Cycles differ grossly (median relative error > 2e-3 or 99th percentile > 3e-2: a broken lookup or
node would exceed these; half precision and GPU rasterisation alone stay below).  The share of
values within the 1e-2 target is reported, with the pixels' conditioning (how much the numpy
evaluation moves under a 1e-4 perturbation of the normal).
"""
from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path

import numpy as np
from ...core.materials import rt_lit
from ...core.materials.rt_lit_interface import Features
from ..harness import glsl_runner
from ..harness import png as _png
from ..harness.realtime_render import RealtimeRenderer


REPO = Path(__file__).resolve().parents[2]

EEVEE_MEDIAN_TOL = 2e-3
EEVEE_P99_TOL = 3e-2
#: The real-time backend's end-to-end targets (issue 13): GLSL on the exported scene vs Cycles' node render.
GLSL_MEDIAN_TOL = 1e-4
GLSL_P99_TOL = 1e-3
#: The web viewer (engines/viewer, GLSL ES 3.00 in headless Chromium) against Cycles: issue 32's targets.  GLSL ES has
#: no ``precise``: the driver may fuse and reorder the arithmetic the GLSL 4.50 renderer keeps in numpy's order.
VIEWER_MEDIAN_TOL = 1e-3
VIEWER_P99_TOL = 1e-2
TARGET = 1e-2
POSITIVE_FLOOR = 1e-3


def _tonemap(rgb):
    x = np.clip(np.asarray(rgb, np.float64), 0.0, None)
    return np.clip(x / (1.0 + x), 0.0, 1.0) ** (1 / 2.2)


def node_counts(scene_materials):
    """{"groups": {name: nodes}, "materials": {material: {...}}} for the RT Lit groups in the file."""
    import bpy

    from ...addon import materials
    from ...addon.common import FEATURES_KEY
    from ...addon.node_emit import tree_node_counts

    groups = {}
    per_features = {}
    kinds = tuple(kind for _, kind in materials.synced_light_kinds())
    for ng in bpy.data.node_groups:
        if FEATURES_KEY not in ng.keys():
            continue
        features = Features.from_dict(ng[FEATURES_KEY])
        counts = tree_node_counts(ng)
        groups.update(counts)
        engines = materials.engine_node_counts(ng)
        per_features[features.label()] = {"group": ng.name,
                                          # what Cycles compiles: its own tree (addon/materials.ENGINE_TREES)
                                          "blender_nodes_flat": engines.get("Cycles", engines.get("All")),
                                          "blender_nodes_flat_eevee": engines.get("EEVEE", engines.get("All")),
                                          "groups_nested": len(counts), "largest_group": max(counts.values()),
                                          **rt_lit.op_counts(features, kinds)}
    # all features on, for reference (not used by the demo)
    everything = Features("kulla_conty", "wrapped", sheen=True, cloth=True)
    per_features.setdefault(everything.label() + " (all on, not in the demo)", rt_lit.op_counts(everything, kinds))
    return {"groups": dict(sorted(groups.items())), "materials": per_features,
            "materials_using": {k: v.label() for k, v in scene_materials.items()}}


def measure_realtime(scene, cycles, out_dir, lut_dir=None, repeats=5, log=print):
    """Export ``scene``, draw it with the GLSL renderer at the render's size and compare with ``cycles``
    (H, W, 3, row 0 at the top): the "realtime" entry of demo.json."""
    from ...addon import scene_export
    from ..harness.engines import compare

    glsl_runner.disable_shader_cache()
    ok, why = glsl_runner.available()
    if not ok:
        log(f"      GLSL renderer not available: {why}")
        return {"available": why, "passed": False}
    t0 = time.perf_counter()
    desc = scene_export.export_scene(scene, out_dir / "realtime_scene", lut_dir)
    export_seconds = time.perf_counter() - t0
    h, w = cycles.shape[:2]
    with RealtimeRenderer(desc, resolution=(w, h)) as renderer:
        image = renderer.render()
        first = renderer.timings["frame_seconds"]
        frames = [renderer.frame_seconds() for _ in range(repeats)]
        timings = {k: v for k, v in renderer.timings.items() if k != "frame_seconds"}
        timings["programs"] = len(renderer.programs)
    stats = compare(cycles, image, positive_floor=POSITIVE_FLOOR)
    c, g = cycles.astype(np.float64), image.astype(np.float64)
    hit_c, hit_g = c.max(-1) > 0, g.max(-1) > 0
    big = c > POSITIVE_FLOOR
    err = np.where(big, np.abs(g - c) / np.maximum(c, POSITIVE_FLOOR), 0.0).max(axis=-1)
    _png.write_rgb(out_dir / "glsl.png", _tonemap(image))
    _png.heatmap(out_dir / "glsl_vs_cycles_rel.png", np.flipud(err), GLSL_P99_TOL, scale=2)
    np.save(out_dir / "glsl.npy", image)
    result = {"renderer": why, "stats": stats, "export_seconds": export_seconds, "finite": bool(np.isfinite(image).all()),
              "coverage_mismatch": int((hit_c != hit_g).sum()), "covered": int(hit_c.sum()),
              "shader_cache_disabled": glsl_runner.shader_cache_disabled(), "first_frame_seconds": first, "frame_seconds_median": statistics.median(frames), "frame_seconds": frames,
              **timings}
    result["passed"] = bool(result["finite"] and stats["median"] <= GLSL_MEDIAN_TOL and stats["p99"] <= GLSL_P99_TOL)
    # reported, not gated: on the demo scene the viewer misses issue 32's p99 (SwiftShader's arithmetic at grazing
    # views; docs/realtime.md, "The web viewer")
    result["viewer"] = measure_viewer(desc, cycles, out_dir, log)
    log(f"      GLSL ({why}): {result['programs']} programs compiled in {timings['compile_seconds']:.2f} s, frame "
        f"{result['frame_seconds_median'] * 1e3:.1f} ms (median of {repeats}; first {first:.2f} s); vs Cycles where > "
        f"{POSITIVE_FLOOR}: median {stats['median']:.2e}, p99 {stats['p99']:.2e}, max {stats['max']:.2e}; "
        f"{result['coverage_mismatch']} of {result['covered']} covered pixels covered in one render only")
    return result


def measure_viewer(desc, cycles, out_dir, log=print):
    """The exported scene as a web bundle (``web_scene/``, core/export/web_scene.py) drawn by the viewer
    (engines/viewer) in headless Chromium, against ``cycles``: the "viewer" entry of the realtime result, whose "passed" says whether
    issue 32's targets are met (reported; the demo step does not gate on it).  Where node or Chromium is missing it
    says so."""
    from ...core.export import web_scene
    from ..harness import three_browser
    from ..harness.engines import compare

    why = three_browser.missing()
    if why:
        log(f"      viewer not run: {why}")
        return {"available": why}
    web_scene.write_web(out_dir / "web_scene", desc)
    image, info = three_browser.render_viewer(out_dir / "web_scene")
    if image.shape != cycles.shape:
        return {"available": "drawn", "passed": False, "error": f"viewer frame {image.shape} != Cycles {cycles.shape}"}
    stats = compare(cycles, image, positive_floor=POSITIVE_FLOOR)
    _png.write_rgb(out_dir / "viewer.png", _tonemap(image))
    result = {"available": "drawn", "renderer": info["renderer"], "seconds": info["seconds"], "stats": stats,
              "finite": bool(np.isfinite(image).all())}
    result["passed"] = bool(result["finite"] and stats["median"] <= VIEWER_MEDIAN_TOL
                            and stats["p99"] <= VIEWER_P99_TOL)
    result["coverage_mismatch"] = int(((cycles.max(-1) > 0) != (image.max(-1) > 0)).sum())
    log(f"      viewer (WebGL2 in headless Chromium, {info['seconds']:.1f} s): vs Cycles where > {POSITIVE_FLOOR}: "
        f"median {stats['median']:.2e}, p99 {stats['p99']:.2e}, max {stats['max']:.2e}")
    return result


def run(out_dir, lut_dir=None, resolution=256, repeats=3, eevee=True, log=print, realtime=True):
    import bpy

    from ...addon import demo_scene as build_demo_scene
    from ..harness.engines import compare, eevee_available, render_engines

    out_dir = Path(out_dir)
    out_dir.mkdir(parents=True, exist_ok=True)
    result = {"resolution": resolution, "folder": str(out_dir)}
    t0 = time.perf_counter()
    spheres = build_demo_scene.build_demo_scene(lut_dir, resolution)
    result["build_seconds"] = round(time.perf_counter() - t0, 3)
    blend = out_dir / "lookdev_demo.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(blend.resolve()))
    result["blend"] = str(blend)
    log(f"      demo scene: {len(spheres)} spheres, built in {result['build_seconds']} s, saved to {blend}")
    result["node_counts"] = node_counts(spheres)
    scene = bpy.context.scene
    size = (scene.render.resolution_x, scene.render.resolution_y)
    cycles_times = []
    for _ in range(repeats):
        renders = render_engines(scene, engines=("CYCLES",), resolution=size, path=out_dir)
        cycles_times.append(renders["CYCLES"][1])
    cycles = renders["CYCLES"][0]
    result["cycles"] = {"seconds_median": statistics.median(cycles_times), "seconds": cycles_times,
                        "samples": 1, "size": list(size), "finite": bool(np.isfinite(cycles).all()),
                        "max": float(cycles.max()), "min": float(cycles.min())}
    log(f"      Cycles {size[0]}x{size[1]}, 1 sample: median {result['cycles']['seconds_median']:.3f} s "
        f"of {repeats}")
    _png.write_rgb(out_dir / "cycles.png", _tonemap(cycles))
    result["passed"] = result["cycles"]["finite"]
    if eevee:
        ok, why = eevee_available()
        result["eevee_available"] = why
        if ok:
            times = []
            world = scene.world           # EEVEE's measurement setup swaps in a black world: put it back after
            try:
                for _ in range(2):
                    r = render_engines(scene, engines=("BLENDER_EEVEE",), resolution=size, path=out_dir)
                    times.append(r["BLENDER_EEVEE"][1])
            finally:
                scene.world = world
            ev = r["BLENDER_EEVEE"][0]
            stats = compare(cycles, ev, positive_floor=POSITIVE_FLOOR)
            c, e = cycles.astype(np.float64), ev.astype(np.float64)
            big = c > POSITIVE_FLOOR
            rel = np.abs(e[big] - c[big]) / c[big]
            stats["p999"] = float(np.percentile(rel, 99.9))
            stats["fraction_over_1e-2"] = float((rel > TARGET).mean())
            result["eevee"] = {"seconds_first": times[0], "seconds_second": times[1], "stats": stats,
                               "renderer": why}
            err = np.zeros(c.shape[:2])
            err_full = np.where(big, np.abs(e - c) / np.maximum(c, POSITIVE_FLOOR), 0.0)
            err = err_full.max(axis=-1)
            _png.write_rgb(out_dir / "eevee.png", _tonemap(ev))
            _png.heatmap(out_dir / "eevee_vs_cycles_rel.png", np.flipud(err), 1e-2, scale=2)   # rows: bottom first
            result["eevee"]["passed"] = stats["median"] <= EEVEE_MEDIAN_TOL and stats["p99"] <= EEVEE_P99_TOL
            result["passed"] = result["passed"] and result["eevee"]["passed"]
            log(f"      EEVEE: {times[0]:.1f} s first, {times[1]:.1f} s second; rel. error vs Cycles where > "
                f"{POSITIVE_FLOOR}: median {stats['median']:.2e}, p99 {stats['p99']:.2e}, p99.9 {stats['p999']:.2e}, "
                f"max {stats['max']:.2e}")
        else:
            log(f"      EEVEE not available: {why}")
    if realtime:
        result["realtime"] = measure_realtime(scene, cycles, out_dir, lut_dir, log=log)
        result["passed"] = result["passed"] and result["realtime"]["passed"]
    (out_dir / "demo.json").write_text(json.dumps(result, indent=2, default=float))
    (out_dir / "demo.md").write_text(format_markdown(result))
    return result


def format_markdown(result, image_prefix=""):
    """demo.md; ``image_prefix``: the PNGs' folder relative to where the text goes ("demo/" in report.md)."""
    nc = result["node_counts"]
    lines = [f"Demo scene `{result['blend']}`: {result['cycles']['size'][0]}x{result['cycles']['size'][1]} px.", "",
             "| RT Lit material (features) | IR ops before folding | after | Blender nodes, flattened: Cycles tree | "
             "EEVEE tree | nested groups | largest group |", "|---|---|---|---|---|---|---|"]
    for label, m in nc["materials"].items():
        lines.append(f"| {label} | {m['ir_ops_unfolded']} | {m['ir_ops_folded']} | {m.get('blender_nodes_flat', '-')} | "
                     f"{m.get('blender_nodes_flat_eevee', '-')} | {m.get('groups_nested', '-')} | "
                     f"{m.get('largest_group', '-')} |")
    lines += ["", "Nodes per group:", "", "| group | nodes |", "|---|---|"]
    lines += [f"| {name} | {count} |" for name, count in nc["groups"].items()]
    c = result["cycles"]
    lines += ["", f"Cycles, 1 sample: median **{c['seconds_median']:.3f} s** of {len(c['seconds'])} renders "
                  f"({', '.join(f'{t:.3f}' for t in c['seconds'])} s); all pixels finite: {c['finite']}.", ""]
    ev = result.get("eevee")
    if ev:
        s = ev["stats"]
        lines += [f"EEVEE ({ev['renderer']}), 1 sample: {ev['seconds_first']:.1f} s first render, "
                  f"{ev['seconds_second']:.1f} s second.", "",
                  f"EEVEE vs Cycles, relative error where Cycles > {POSITIVE_FLOOR} ({s['count']} values): "
                  f"median {s['median']:.2e}, p99 {s['p99']:.2e}, p99.9 {s['p999']:.2e}, max {s['max']:.2e}; "
                  f"{100 * s['fraction_over_1e-2']:.3f}% of values over 1e-2 "
                  f"(gross-error guard: median <= {EEVEE_MEDIAN_TOL}, p99 <= {EEVEE_P99_TOL}): "
                  f"**{'PASS' if ev['passed'] else 'FAIL'}**", ""]
    else:
        lines += [f"EEVEE: not run ({result.get('eevee_available', 'skipped')}).", ""]
    rt = result.get("realtime")
    if rt and "stats" in rt:
        s = rt["stats"]
        lines += [f"GLSL, the real-time backend ({rt['renderer']}): the scene exported to `realtime_scene/` and drawn by "
                  f"the standalone renderer (validation/harness/realtime_render.py); {rt['programs']} programs compiled in "
                  f"{rt['compile_seconds']:.2f} s (Mesa's shader cache "
                  f"{'off' if rt.get('shader_cache_disabled') else 'on'}), first frame {rt['first_frame_seconds']:.2f} s, then "
                  f"{1e3 * rt['frame_seconds_median']:.1f} ms per frame (median of {len(rt['frame_seconds'])}).", "",
                  f"GLSL vs Cycles, relative error where Cycles > {POSITIVE_FLOOR} ({s['count']} values): median "
                  f"{s['median']:.2e}, p99 {s['p99']:.2e}, max {s['max']:.2e}; {rt['coverage_mismatch']} of "
                  f"{rt['covered']} covered pixels covered by one render only (targets: median <= {GLSL_MEDIAN_TOL}, "
                  f"p99 <= {GLSL_P99_TOL}): **{'PASS' if rt['passed'] else 'FAIL'}**", ""]
        v = rt.get("viewer", {})
        if "stats" in v:
            s = v["stats"]
            lines += [f"The web viewer (engines/viewer: the scene as a web bundle in `web_scene/`, drawn with WebGL2 "
                      f"in headless Chromium, {v['seconds']:.1f} s with the browser's start) vs Cycles: median "
                      f"{s['median']:.2e}, p99 {s['p99']:.2e}, max {s['max']:.2e}; {v['coverage_mismatch']} pixels "
                      f"covered by one render only (issue 32's targets: median <= {VIEWER_MEDIAN_TOL}, p99 <= "
                      f"{VIEWER_P99_TOL}: "
                      f"**{'met' if v['passed'] else 'not met'}**; reported, not gated)", ""]
        elif v:
            lines += [f"The web viewer: not run ({v['available']}).", ""]
    elif rt:
        lines += [f"GLSL: not run ({rt['available']}).", ""]
    images = [("Cycles", "cycles.png"), ("EEVEE", "eevee.png"), ("EEVEE vs Cycles", "eevee_vs_cycles_rel.png"),
              ("GLSL", "glsl.png"), ("GLSL vs Cycles (scale 0..1e-3)", "glsl_vs_cycles_rel.png"),
              ("Web viewer", "viewer.png")]
    folder = Path(result.get("folder", "."))
    shown = [f"![{label}]({image_prefix}{name})" for label, name in images if (folder / name).exists()]
    if shown:
        lines += [" ".join(shown), ""]
    return "\n".join(lines)


def parse_args(argv):
    """The options of scripts/demo_report.py parsed from ``argv``."""
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, default=REPO / "out" / "report" / "demo")
    p.add_argument("--lut-dir", type=Path, default=None)
    p.add_argument("--resolution", type=int, default=256)
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--skip-eevee", action="store_true")
    p.add_argument("--skip-realtime", action="store_true", help="skip the GLSL render of the exported scene")
    return p.parse_args(argv)


def run_args(args, log=print):
    """``run`` with the options of ``parse_args``; logs demo.md; returns the result (``"passed"``)."""
    result = run(args.out, args.lut_dir, args.resolution, args.repeats, not args.skip_eevee, log=log,
                 realtime=not args.skip_realtime)
    log((args.out / "demo.md").read_text())
    return result
