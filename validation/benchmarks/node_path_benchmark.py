"""The Cycles node path before and after per-engine trees, on the demo scene (issue 15, "Make the node
path earn its place").

The same measurement runs in two fresh processes: one imports this checkout, the other a git worktree
of ``BASELINE`` (the last commit with one four-fetch tree for every engine and emission sampled as a
light), each through ``PYTHONPATH`` pointing at a folder whose ``rt_lookdev`` is that tree.  Each process
builds the demo scene (addon/demo_scene.py: 15 RT Lit spheres, a quad and a disk light, the studio HDRI
``forest`` as World term), counts the flattened Blender nodes of each material's Cycles tree, renders
it with Cycles at 1 sample ``repeats + 1`` times (the first is not timed: it loads images) and saves
the last image.  Times are whole ``render.render`` calls (depsgraph, Cycles sync and SVM compile,
light tree, sampling); the two processes alternate ``rounds`` times so that load affects both alike.
"Same values": the two images' max and median relative difference where the baseline is > 1e-3.
"""
from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
#: The last commit before per-engine trees (one four-fetch tree for Cycles and EEVEE).
BASELINE = "60fb909"

_CHILD = r"""
import json, sys, time
import numpy as np
import bpy
import rt_lookdev
from rt_lookdev.addon.demo_scene import build_demo_scene
from rt_lookdev.addon import materials
from rt_lookdev.addon.node_emit import flat_tree_node_count
try:
    from rt_lookdev.validation.harness.engines import render_engines
except ImportError:            # a tree from before the split of validation/ (issue 28): the baseline's
    from rt_lookdev.validation.engines import render_engines
resolution, repeats, out = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3]
t0 = time.perf_counter()
build_demo_scene(None, resolution, "forest", 0.5)
build = time.perf_counter() - t0
counts = {}
for m in bpy.data.materials:
    node = m.node_tree.nodes.get("RT Lit") if m.node_tree else None
    if node is None:
        continue
    per_engine = getattr(materials, "engine_node_counts", None)
    counts[m.name] = per_engine(node.node_tree)["Cycles"] if per_engine else flat_tree_node_count(node.node_tree)
scene = bpy.context.scene
times = []
for i in range(repeats + 1):
    image, seconds = render_engines(scene, engines=("CYCLES",), resolution=resolution)["CYCLES"]
    if i:
        times.append(seconds)
np.save(out, image)
# where one render's time goes: Cycles' status messages (render start -> first sample = depsgraph, scene and
# shader sync, SVM compile, light tree; first sample -> end = sampling and the film)
marks = []
bpy.app.handlers.render_stats.append(lambda stats, *a: marks.append((time.perf_counter(), stats)))
start = time.perf_counter()
render_engines(scene, engines=("CYCLES",), resolution=resolution)
first = next((t for t, st in marks if "Sample 0/" in st or "Sample 1/" in st), None)
end = next((t for t, st in reversed(marks) if "Finished" in st), marks[-1][0] if marks else None)
phases = {"to_first_sample": None if first is None else first - start,
          "sampling": None if first is None or end is None else end - first}
bpy.app.handlers.render_stats.clear()
# the same scene with every RT Lit material's outputs fed by a plain Emission (the groups stay in the file)
for m in bpy.data.materials:
    if m.node_tree is None or m.node_tree.nodes.get("RT Lit") is None:
        continue
    emission = m.node_tree.nodes.new("ShaderNodeEmission")
    for o in m.node_tree.nodes:
        if o.bl_idname == "ShaderNodeOutputMaterial":
            m.node_tree.links.new(emission.outputs[0], o.inputs["Surface"])
plain = []
for i in range(repeats + 1):
    seconds = render_engines(scene, engines=("CYCLES",), resolution=resolution)["CYCLES"][1]
    if i:
        plain.append(seconds)
print("RTL_NODE_PATH " + json.dumps({"package": rt_lookdev.__file__, "build_seconds": build, "nodes": counts,
                                     "seconds": times, "phases": phases, "plain_seconds": plain}), flush=True)
"""


def _package_dir(tree, tmp):
    """A folder whose ``rt_lookdev`` is ``tree`` (for PYTHONPATH)."""
    folder = Path(tmp) / f"pkg_{abs(hash(str(tree)))}"
    folder.mkdir(exist_ok=True)
    link = folder / "rt_lookdev"
    if not link.exists():
        link.symlink_to(tree, target_is_directory=True)
    return folder


def _measure(tree, resolution, repeats, image_path, tmp):
    env = dict(os.environ, PYTHONPATH=str(_package_dir(tree, tmp)))
    proc = subprocess.run([sys.executable, "-c", _CHILD, str(resolution), str(repeats), str(image_path)],
                          capture_output=True, text=True, env=env, cwd=tmp, timeout=1800)
    line = next((ln for ln in proc.stdout.splitlines() if ln.startswith("RTL_NODE_PATH ")), None)
    if proc.returncode != 0 or line is None:
        raise RuntimeError(f"node-path measurement in {tree} failed ({proc.returncode}):\n{proc.stderr[-3000:]}")
    result = json.loads(line.split(" ", 1)[1])
    if Path(result["package"]).resolve().parent != Path(tree).resolve():
        raise RuntimeError(f"imported {result['package']}, not the tree {tree}")
    return result


def _worktree(commit, tmp):
    path = Path(tmp) / f"baseline_{commit}"
    subprocess.run(["git", "-C", str(REPO), "worktree", "add", "--detach", "-f", str(path), commit], check=True,
                   capture_output=True, text=True)
    return path


def run(resolution=256, repeats=3, rounds=2, baseline=BASELINE, log=print):
    """Measure this checkout against ``baseline``; returns the JSON-ready result with "markdown"."""
    with tempfile.TemporaryDirectory(prefix="rtl-node-path-") as tmp:
        base_tree = _worktree(baseline, tmp)
        try:
            runs = {"baseline": [], "now": []}
            for r in range(rounds):
                for key, tree in (("baseline", base_tree), ("now", REPO)):
                    runs[key].append(_measure(tree, resolution, repeats, Path(tmp) / f"{key}.npy", tmp))
                log(f"      node path: round {r + 1}/{rounds}: baseline "
                    f"{statistics.median(runs['baseline'][-1]['seconds']):.3f} s, now "
                    f"{statistics.median(runs['now'][-1]['seconds']):.3f} s")
            images = {key: np.load(Path(tmp) / f"{key}.npy").astype(np.float64) for key in runs}
        finally:
            subprocess.run(["git", "-C", str(REPO), "worktree", "remove", "--force", str(base_tree)],
                           capture_output=True, text=True)
    out = {"baseline_commit": baseline, "resolution": resolution, "repeats": repeats, "rounds": rounds}
    for key, rs in runs.items():
        nodes = rs[0]["nodes"]
        out[key] = {"seconds": [t for r in rs for t in r["seconds"]], "nodes": nodes,
                    "nodes_median": statistics.median(nodes.values()), "nodes_total": sum(nodes.values()),
                    "build_seconds": statistics.median(r["build_seconds"] for r in rs),
                    "plain_seconds": [t for r in rs for t in r["plain_seconds"]],
                    "to_first_sample": statistics.median(r["phases"]["to_first_sample"] for r in rs),
                    "sampling": statistics.median(r["phases"]["sampling"] for r in rs)}
        out[key]["seconds_median"] = statistics.median(out[key]["seconds"])
        out[key]["plain_seconds_median"] = statistics.median(out[key]["plain_seconds"])
    b, n = images["baseline"], images["now"]
    big = b > 1e-3
    rel = np.abs(n[big] - b[big]) / b[big]
    out["values"] = {"count": int(big.sum()), "max_rel": float(rel.max()), "median_rel": float(np.median(rel)),
                     "p99_rel": float(np.percentile(rel, 99))}
    out["speedup"] = out["baseline"]["seconds_median"] / out["now"]["seconds_median"]
    out["node_ratio_median"] = out["baseline"]["nodes_median"] / out["now"]["nodes_median"]
    out["node_ratio_total"] = out["baseline"]["nodes_total"] / out["now"]["nodes_total"]
    out["markdown"] = markdown(out)
    return out


def markdown(r):
    b, n, v = r["baseline"], r["now"], r["values"]
    lines = [f"### The Cycles node path on the demo scene: now against {r['baseline_commit']}", "",
             f"Demo scene, {r['resolution']}^2, Cycles 1 sample, 2 threads; median of {len(n['seconds'])} timed renders "
             f"per version ({r['rounds']} alternating processes x {r['repeats']}), whole `render.render` call.", "",
             "| version | Cycles-tree nodes per material (median) | all materials | render (s) | of which: to the "
             "first sample | sampling | plain Emission instead (s) | scene build (s) |",
             "|---|---|---|---|---|---|---|---|"]
    for label, e in ((f"{r['baseline_commit']} (one four-fetch tree)", b), ("now (per-engine trees, emission not a light)", n)):
        lines.append(f"| {label} | {e['nodes_median']:.0f} | {e['nodes_total']} | {e['seconds_median']:.3f} | "
                     f"{e['to_first_sample']:.3f} | {e['sampling']:.3f} | {e['plain_seconds_median']:.3f} | "
                     f"{e['build_seconds']:.2f} |")
    lines += ["",
             "*To the first sample*: render start to Cycles' first sample status (depsgraph, scene and shader sync, SVM "
             "compile, light tree), one render's phases; *plain Emission instead*: the same file with every RT Lit "
             "material's outputs fed by an Emission node (the RT Lit groups stay in the file): the scene's cost "
             "without RT Lit's shading.", "",
             f"Nodes {r['node_ratio_median']:.2f}x fewer (median material; {r['node_ratio_total']:.2f}x in total), render "
             f"{r['speedup']:.2f}x faster. Values: the two renders differ by a median {v['median_rel']:.1e} and at "
             f"most {v['max_rel']:.1e} relative ({v['count']} values > 1e-3; 0 is bit for bit: Cycles' Linear "
             "filter sums the four weighted texels in the order the four-fetch groups do)"
             + ("." if v["max_rel"] < 1e-3 else "; where they differ more, the shading itself changed since the "
                "baseline (the GGX LTC's band for r >= 0.65, the metal and dielectric shaded apart, the sheen's "
                "layering), which this comparison of the node path does not separate.")]
    return "\n".join(lines) + "\n"
