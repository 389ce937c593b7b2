"""How RT Lit's cost grows: Cycles render time and node count against lights, resolution and features,
and EEVEE's shader compile time per material (issue 15, "Scaling").

One sphere with one RT Lit material (``rt_lit_benchmark.lights_scene``: quad lights on a circle in front of
it, values that keep every lobe alive) rendered by Cycles at 1 sample, 2 threads.  Each timed scene is
built once and saved; each of ``rounds`` interleaved rounds opens every file and renders it twice,
timing the second (the first after a load also loads images), so load on the machine affects all
configurations alike.  The time is the whole ``render.render`` call: Blender's depsgraph, Cycles' scene
sync and SVM compile, and the sampling.  Node counts: the flattened Blender nodes of the material's
Cycles tree (``addon/materials.ENGINE_TREES``) and of its EEVEE tree.

EEVEE compile: the first EEVEE render of a freshly opened file against the second in the same process
(the GPU material is compiled by the first), per feature set at 1 light; llvmpipe here.

Growth laws are least-squares lines t = a + b x (x = lights, or pixels), with their R^2.
"""
from __future__ import annotations

import statistics
import tempfile
import time
from pathlib import Path

import numpy as np
from ...core.materials.rt_lit_interface import Features
from .rt_lit_benchmark import captured_output, lights_scene

LIGHTS = (1, 2, 4, 8, 12)
LIGHTS_QUICK = (1, 4)
RESOLUTIONS = (128, 256, 512, 1024)
RESOLUTIONS_QUICK = (128, 256)
RESOLUTION_LIGHTS = 4
BASE_RESOLUTION = 128


def _features_sets():
    return [Features("single", "lambert"), Features("turquin", "cod"), Features("kulla_conty", "lambert"),
            Features("turquin", "cod", sheen=True), Features("single", "cod", cloth=True),
            Features("kulla_conty", "wrapped", sheen=True, cloth=True)]


def _tree_counts(mat):
    from ...addon.materials import engine_node_counts

    return engine_node_counts(mat.node_tree.nodes["RT Lit"].node_tree)


def _render_seconds(scene, engine, resolution):
    from ..harness.engines import render_engines

    image, seconds = render_engines(scene, engines=(engine,), resolution=resolution)[engine]
    if not image.max() > 0.0:
        raise RuntimeError(f"{engine} rendered black at {resolution}")
    return seconds


def timed_configs(configs, rounds, log=print):
    """configs: {key: (features, lights, resolution)} -> {key: {"seconds": median, "runs": [...],
    "nodes": {"Cycles": n, "EEVEE": n}}}."""
    import bpy

    out = {}
    with tempfile.TemporaryDirectory(prefix="rtl-scaling-") as tmp:
        files = {}
        for key, (features, lights, _) in configs.items():
            _, mat = lights_scene(features, lights)
            out[key] = {"runs": [], "nodes": _tree_counts(mat)}
            files[key] = str(Path(tmp) / f"{len(files)}.blend")
            bpy.ops.wm.save_as_mainfile(filepath=files[key], copy=True)
        for r in range(rounds):
            for key, path in files.items():
                bpy.ops.wm.open_mainfile(filepath=path)
                resolution = configs[key][2]
                with captured_output():
                    _render_seconds(bpy.context.scene, "CYCLES", resolution)
                    out[key]["runs"].append(_render_seconds(bpy.context.scene, "CYCLES", resolution))
            log(f"      scaling: round {r + 1}/{rounds}")
    for entry in out.values():
        entry["seconds"] = statistics.median(entry["runs"])
    return out


def eevee_compile(features_list, log=print):
    """{features label: {"first": s, "second": s, "compile": first - second}} (None when EEVEE cannot
    render here)."""
    import bpy

    from ..harness.engines import eevee_available

    ok, _ = eevee_available()
    if not ok:
        return None
    out = {}
    with tempfile.TemporaryDirectory(prefix="rtl-eevee-compile-") as tmp:
        for features in features_list:
            lights_scene(features, 1)
            path = str(Path(tmp) / "scene.blend")
            bpy.ops.wm.save_as_mainfile(filepath=path, copy=True)
            bpy.ops.wm.open_mainfile(filepath=path)
            with captured_output():
                first = _render_seconds(bpy.context.scene, "BLENDER_EEVEE", BASE_RESOLUTION)
                second = _render_seconds(bpy.context.scene, "BLENDER_EEVEE", BASE_RESOLUTION)
            out[features.label()] = {"first": first, "second": second, "compile": first - second}
            log(f"      EEVEE compile {features.label()}: {first - second:.2f} s")
    return out


def fit_line(x, y):
    """(a, b, r2) of the least-squares line y = a + b x."""
    x, y = np.asarray(x, np.float64), np.asarray(y, np.float64)
    b, a = np.polyfit(x, y, 1)
    resid = y - (a + b * x)
    total = np.sum((y - y.mean()) ** 2)
    return float(a), float(b), float(1.0 - np.sum(resid ** 2) / total) if total > 0 else 1.0


def run(quick=False, rounds=3, eevee=True, log=print):
    """Measure; returns the JSON-ready result with a "markdown" entry."""
    t0 = time.perf_counter()
    typical = Features("turquin", "cod")
    lights = LIGHTS_QUICK if quick else LIGHTS
    resolutions = RESOLUTIONS_QUICK if quick else RESOLUTIONS
    feature_sets = _features_sets()[:2] if quick else _features_sets()
    configs = {("lights", n): (typical, n, BASE_RESOLUTION) for n in lights}
    configs.update({("resolution", r): (typical, RESOLUTION_LIGHTS, r) for r in resolutions})
    configs.update({("features", f.label()): (f, 1, BASE_RESOLUTION) for f in feature_sets})
    log(f"      scaling: {len(configs)} scenes x {rounds} rounds")
    timed = timed_configs(configs, rounds, log=log)
    light_rows = [{"lights": n, **timed[("lights", n)]} for n in lights]
    res_rows = [{"resolution": r, "pixels": r * r, **timed[("resolution", r)]} for r in resolutions]
    feat_rows = [{"features": f.label(), **timed[("features", f.label())]} for f in feature_sets]
    result = {
        "lights": light_rows, "resolution": res_rows, "features": feat_rows,
        "lights_fit": dict(zip(("a", "b", "r2"), fit_line([r["lights"] for r in light_rows],
                                                          [r["seconds"] for r in light_rows]))),
        "nodes_fit": dict(zip(("a", "b", "r2"), fit_line([r["lights"] for r in light_rows],
                                                         [r["nodes"]["Cycles"] for r in light_rows]))),
        "resolution_fit": dict(zip(("a", "b", "r2"), fit_line([r["pixels"] for r in res_rows],
                                                              [r["seconds"] for r in res_rows]))),
        "eevee_compile": eevee_compile(feature_sets, log=log) if eevee else None,
        "rounds": rounds, "quick": quick,
    }
    result["seconds"] = time.perf_counter() - t0
    result["markdown"] = markdown(result)
    return result


def markdown(result):
    lf, nf, rf = result["lights_fit"], result["nodes_fit"], result["resolution_fit"]
    lines = ["### Scaling (Cycles, 1 sample, one sphere; median of "
             f"{result['rounds']} interleaved rounds, whole render call)", "",
             f"Lights (turquin, cod; {BASE_RESOLUTION}^2): time = {lf['a'] * 1e3:.1f} ms + {lf['b'] * 1e3:.1f} ms "
             f"per light (R^2 {lf['r2']:.3f}); Cycles-tree nodes = {nf['a']:.0f} + {nf['b']:.0f} per light "
             f"(R^2 {nf['r2']:.4f}): both linear in the lights.", "",
             "| lights | Cycles-tree nodes | EEVEE-tree nodes | time (ms) |", "|---|---|---|---|"]
    for r in result["lights"]:
        lines.append(f"| {r['lights']} | {r['nodes']['Cycles']} | {r['nodes']['EEVEE']} | {r['seconds'] * 1e3:.1f} |")
    lines += ["", f"Resolution ({RESOLUTION_LIGHTS} lights): time = {rf['a'] * 1e3:.1f} ms + "
              f"{rf['b'] * 1e9:.1f} ns per pixel (R^2 {rf['r2']:.3f}): a fixed cost (sync, compile) plus a "
              "cost per pixel.", "", "| resolution | time (ms) | ns per pixel |", "|---|---|---|"]
    for r in result["resolution"]:
        lines.append(f"| {r['resolution']}^2 | {r['seconds'] * 1e3:.1f} | {r['seconds'] / r['pixels'] * 1e9:.0f} |")
    lines += ["", f"Feature sets (1 light, {BASE_RESOLUTION}^2):", "",
              "| features | Cycles-tree nodes | EEVEE-tree nodes | time (ms) | EEVEE compile (s) |", "|---|---|---|---|---|"]
    comp = result.get("eevee_compile") or {}
    for r in result["features"]:
        c = comp.get(r["features"])
        lines.append(f"| {r['features']} | {r['nodes']['Cycles']} | {r['nodes']['EEVEE']} | {r['seconds'] * 1e3:.1f} | "
                     f"{'-' if c is None else format(c['compile'], '.2f')} |")
    if not comp:
        lines += ["", "EEVEE compile time: not measured (EEVEE cannot render here)."]
    else:
        lines += ["", "EEVEE compile = first EEVEE render of a freshly opened file minus the second (llvmpipe; "
                  "the GPU material is compiled by the first)."]
    return "\n".join(lines) + "\n"
