"""The GGX LTC's error on a suite-like set, in numpy: the validation suite's area lights and sphere layouts
(``suite_cases.build_cases``) seen by its orthographic camera, every sphere shaded at a range of roughness
values, the LTC estimate of the single-scattering GGX lobe (F = 1) against its brute-force integral.

Why a numpy set beside the suite: the suite's spheres measure RT Lit against Cycles' closures, whose noise
(and Cycles' own GGX, equal to ours) blurs the LTC's share; here the truth is the lobe's integral over the
light (``core/ltc/reference.py``: Gauss-Legendre over the light's area, clipped at the shading point's horizon,
with its two-resolution error estimate), and every roughness is measured at every sphere of every light, so
the error can be reported per roughness band and per light kind.

- Geometry: ``suite_cases.build_cases()`` (full set): each area light (quads 0-3, disks 4-6, the two sweeps'
  lights) with the sphere centres of its case; the light's frame as Blender's track-to constraint gives it
  (``suite_scene._aim``: local -Z towards the target, local +Y towards world +Z); view direction -Y (the
  orthographic camera); shading points at the pixel centres of a grid of ``cell`` pixels per sphere cell (the
  suite renders 64; 24 by default), off the silhouette's last 1%.
- Values: LTC magnitude x integral (the lobe's radiance per unit light radiance, F0 = 1) against the brute
  force; statistics over the values above ``floor`` x the sphere's maximum (the suite's floor, 0.1), per
  roughness and per light kind: median, p90 and RMS of the relative error, and the mean signed error.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import platform
import subprocess
import tempfile
import time
from pathlib import Path

import numpy as np

from ...core.ltc import fit_lobes, shading
from ...core.lut import catalog, lookup
from ..checks import suite_cases
from ..checks import suite_brute_force
from ..harness import entry, outputs

#: Roughness values measured at every sphere.
ROUGHNESS = (0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 1.0)
#: Bands reported (inclusive ranges of ``ROUGHNESS``), the issue's "glossy r <= 0.3" split further.
BANDS = ((0.1, 0.2), (0.3, 0.4), (0.5, 0.6), (0.7, 0.8), (0.9, 1.0))
FLOOR = 0.1


def _track_frame(location, target):
    """Local X, Y, Z axes of an object aimed with ``to_track_quat("-Z", "Y")`` (``suite_scene._aim``): -Z
    along the direction to the target, +Y as close to world +Z as the track allows."""
    d = np.asarray(target, np.float64) - np.asarray(location, np.float64)
    z = -d / np.linalg.norm(d)
    up = np.array([0.0, 0.0, 1.0])
    y = up - z * (up @ z)
    if np.linalg.norm(y) < 1e-9:
        y = np.array([0.0, 1.0, 0.0]) - z * z[1]
    y /= np.linalg.norm(y)
    return np.cross(y, z), y, z


def light_geometry(spec):
    """A suite ``LightSpec`` (quad or disk) as world-space geometry: {"kind", "corners"} or
    {"kind", "center", "axis_u", "axis_v"} (``core.lights``' corner order and axes)."""
    x, y, _ = _track_frame(spec.location, spec.target)
    loc = np.asarray(spec.location, np.float64)
    eu, ev = x * spec.size * 0.5, y * (spec.size_y or spec.size) * 0.5
    if spec.kind == "quad":
        return {"kind": "quad", "corners": np.stack([loc - eu - ev, loc + eu - ev, loc + eu + ev, loc - eu + ev])}
    return {"kind": "disk", "center": loc, "axis_u": eu, "axis_v": ev}


def build_set(seed=0, cell=24, pixels=None):
    """The suite's area lights with their spheres' shading points: a list of dicts with the light's
    geometry, its case name, and P, N (world space, (M, 3)) and the sphere index of every point.  Points: the
    pixel centres of a ``cell`` x ``cell`` grid per sphere cell, or a seeded subset of ``pixels`` of them (a
    subset may miss a sharp highlight, and the floor is relative to the sphere's maximum)."""
    rng = np.random.default_rng(seed)
    out = []
    seen = set()
    for case in suite_cases.build_cases(seed):
        light = case.lights[0]
        if light.kind not in ("quad", "disk"):
            continue
        key = (light.kind, tuple(light.location), tuple(light.target), light.size, light.size_y)
        if key in seen:           # the closures and brute cases of a config share a light and a layout
            continue
        seen.add(key)
        centres, cols, _ = suite_cases.sphere_centres(case)
        step = suite_cases.CELL / cell
        g = (np.arange(cell) + 0.5) * step - 0.5 * suite_cases.CELL
        gx, gz = np.meshgrid(g, g)
        inside = gx * gx + gz * gz < 0.98          # off the silhouette, where the view is exactly grazing
        gx, gz = gx[inside], gz[inside]
        P, N, idx = [], [], []
        for i, c in enumerate(centres):
            pick = (np.arange(gx.size) if pixels is None or pixels >= gx.size
                    else np.sort(rng.choice(gx.size, pixels, replace=False)))
            x, z = gx[pick], gz[pick]
            n = np.stack([x, -np.sqrt(1.0 - x * x - z * z), z], axis=-1)
            P.append(np.asarray(c) + n)
            N.append(n)
            idx.append(np.full(len(x), i))
        out.append({"case": case.name, "light": light_geometry(light), "P": np.concatenate(P),
                    "N": np.concatenate(N), "sphere": np.concatenate(idx)})
    return out


VIEW = np.array([0.0, -1.0, 0.0])      # towards the orthographic camera (suite_scene.build_scene)


def _local(frame, d):
    t1, t2, n = frame
    return np.stack([d @ t1, d @ t2, d @ n], axis=-1)


def _rule(light, p, n, panels, order):
    """Unit directions from p and solid-angle weights of the light clipped at the horizon of normal n (the suite's
    brute-force rule, ``suite_brute_force.quadrature_rule``), or None."""
    geo = ({"corners": light["corners"]} if light["kind"] == "quad"
           else {"center": light["center"], "u": light["axis_u"], "v": light["axis_v"]})
    rule = suite_brute_force.quadrature_rule(light["kind"], geo, p, n, panels, order)
    if rule is None or len(rule[1]) == 0:
        return None
    x, w, normal = rule
    dist = np.linalg.norm(x, axis=-1)
    return x / dist[:, None], w * np.abs(x @ normal) / dist ** 3


def brute_force(entry, roughness=ROUGHNESS, panels=(4, 8, 16, 32, 64), order=8, rtol=1e-3, atol=1e-6):
    """(truth (M, R), quadrature error estimate (M, R)): int_light f_ggx(l, v) cos dl for every point and r.
    Per point the rule is refined (``panels`` in turn) until the difference to the previous level is within
    rtol x value + atol for every r (sharp lobes need more panels); that difference is the error estimate."""
    ggx = fit_lobes.LOBES["ggx"]
    light = entry["light"]
    P, N = entry["P"], entry["N"]
    r = np.asarray(roughness, np.float64)[:, None]
    truth = np.zeros((len(P), r.size))
    error = np.zeros((len(P), r.size))
    for k in range(len(P)):
        n = N[k]
        t = VIEW - n * (VIEW @ n)
        t1 = t / np.linalg.norm(t)
        frame = (t1, np.cross(n, t1), n)
        v_local = _local(frame, VIEW)
        previous = None
        for pan in panels:
            rule = _rule(light, P[k], n, pan, order)
            if rule is None:
                break
            l, jac = rule
            value = ggx.eval_cos(_local(frame, l)[None], v_local, r) @ jac
            if previous is not None:
                truth[k], error[k] = value, np.abs(value - previous)
                if np.all(error[k] <= rtol * np.abs(value) + atol):
                    break
            previous = value
    return truth, error


def ltc_lobe(tables, entry, roughness=ROUGHNESS, dtype=np.float64):
    """The RT Lit GGX lobe's area form at every point and r: magnitude x integral (``shading.lobe_integral``,
    the code the node groups are traced from), (M, R)."""
    light = entry["light"]
    if light["kind"] == "quad":
        shape = shading.QuadLight([q.astype(dtype) for q in light["corners"]])
    else:
        shape = shading.DiskLight(*(light[k].astype(dtype) for k in ("center", "axis_u", "axis_v")))
    P, N = entry["P"].astype(dtype), entry["N"].astype(dtype)
    V = np.broadcast_to(VIEW, P.shape).astype(dtype)
    cols = []
    for r in roughness:
        value, magnitude, _ = shading.lobe_integral(tables, "ltc_ggx", shape, P, N, V, np.full(len(P), r, dtype))
        cols.append(np.asarray(value * magnitude, np.float64))
    return np.stack(cols, axis=-1)


def truth_cached(entries, roughness=ROUGHNESS, panels=(4, 8, 16, 32, 64), order=8, cache_dir=None,
                 progress=entry.flush_log):
    """``brute_force`` of every entry, cached in ``cache_dir`` by a hash of the geometry and the rule."""
    results = []
    for e in entries:
        h = hashlib.sha256()
        for k in ("P", "N"):
            h.update(np.ascontiguousarray(e[k]).tobytes())
        h.update(json.dumps({k: np.asarray(v).tolist() for k, v in e["light"].items() if k != "kind"}).encode())
        h.update(json.dumps([list(roughness), list(panels), order, 2]).encode())
        path = Path(cache_dir) / f"truth_{h.hexdigest()[:16]}.npz" if cache_dir else None
        if path is not None and path.exists():
            data = np.load(path)
            results.append((data["truth"], data["error"]))
            continue
        t0 = time.perf_counter()
        truth, err = brute_force(e, roughness, panels, order)
        progress(f"[suite-like] {e['case']}: {len(e['P'])} points x {len(roughness)} r in "
                 f"{time.perf_counter() - t0:.1f} s")
        if path is not None:
            path.parent.mkdir(parents=True, exist_ok=True)
            np.savez(path, truth=truth, error=err)
        results.append((truth, err))
    return results


def gather(entries, truths, estimates, roughness=ROUGHNESS, floor=FLOOR):
    """Per value above the floor: dict of arrays (rel error, signed rel error, r, light kind, case, quadrature
    error relative to the truth)."""
    rows = {"rel": [], "signed": [], "r": [], "kind": [], "quad_err": []}
    for e, (truth, qerr), est in zip(entries, truths, estimates):
        for j, r in enumerate(roughness):
            for s in np.unique(e["sphere"]):
                mine = e["sphere"] == s
                t = truth[mine, j]
                if t.max() <= 0.0:
                    continue
                sel = t > floor * t.max()
                d = (est[mine, j][sel] - t[sel]) / t[sel]
                rows["rel"].append(np.abs(d))
                rows["signed"].append(d)
                rows["r"].append(np.full(d.size, r))
                rows["kind"].append(np.full(d.size, e["light"]["kind"]))
                rows["quad_err"].append(qerr[mine, j][sel] / t[sel])
    return {k: np.concatenate(v) for k, v in rows.items()}


def summary(values, select):
    rel = values["rel"][select]
    if rel.size == 0:
        return None
    return {"values": int(rel.size), "median": float(np.median(rel)), "p90": float(np.quantile(rel, 0.9)),
            "rms": float(np.sqrt(np.mean(rel ** 2))), "bias": float(np.mean(values["signed"][select])),
            "max": float(rel.max()), "quadrature_p99": float(np.quantile(values["quad_err"][select], 0.99))}


def report(values, roughness=ROUGHNESS, bands=BANDS):
    """Statistics per light kind (quad, disk, both) x (each roughness band, each r, r >= 0.3, all)."""
    out = {}
    for kind in ("quad", "disk", "all"):
        k_sel = np.ones(values["rel"].size, bool) if kind == "all" else values["kind"] == kind
        groups = {f"r={r:g}": np.isclose(values["r"], r) for r in roughness}
        groups.update({f"{lo:g}-{hi:g}": (values["r"] >= lo - 1e-9) & (values["r"] <= hi + 1e-9) for lo, hi in bands})
        groups["r>=0.3"] = values["r"] >= 0.3 - 1e-9
        groups["all"] = np.ones(values["rel"].size, bool)
        out[kind] = {g: summary(values, k_sel & sel) for g, sel in groups.items()}
    return out


def measure(tables, entries=None, truths=None, cache_dir=None, progress=entry.flush_log):
    """Everything above for one table set: (report, values)."""
    entries = entries if entries is not None else build_set()
    truths = truths if truths is not None else truth_cached(entries, cache_dir=cache_dir, progress=progress)
    estimates = [ltc_lobe(tables, e) for e in entries]
    values = gather(entries, truths, estimates)
    return report(values), values


def markdown_rows(before, after, groups=None, kinds=("quad", "disk", "all")):
    """Table rows "| kind | group | n | median before -> after | p90 | RMS | bias |"."""
    lines = ["| light | r | values | median | p90 | RMS | mean signed |", "|---|---|---|---|---|---|---|"]
    for kind in kinds:
        for g in groups or before[kind]:
            b, a = before[kind][g], after[kind][g]
            if b is None:
                continue
            lines.append(f"| {kind} | {g} | {b['values']} | {100 * b['median']:.2f} -> {100 * a['median']:.2f}% | "
                         f"{100 * b['p90']:.2f} -> {100 * a['p90']:.2f}% | {100 * b['rms']:.2f} -> {100 * a['rms']:.2f}% | "
                         f"{100 * b['bias']:+.2f} -> {100 * a['bias']:+.2f}% |")
    return lines


def default_tables(lut_dir=None):
    return lookup.LutSet.from_folder(lut_dir)


# --- the benchmark: two table sets on the same set ---------------------------------------------------

#: The last commit whose GGX LTC has no band (the "before" of docs/benchmarks/ltc_suite_like.md).
BEFORE = "a8bb34f"


def tables_at_revision(rev, folder):
    """The catalog's tables as committed at git revision ``rev``, written to ``folder``: a LutSet."""
    repo = Path(__file__).resolve().parents[2]
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    for spec in catalog.TABLES.values():
        data = subprocess.run(["git", "-C", str(repo), "show", f"{rev}:luts/{spec.filename}"], capture_output=True,
                              check=True).stdout
        (folder / spec.filename).write_bytes(data)
    return lookup.LutSet.from_folder(folder)


def parse_args(argv):
    p = argparse.ArgumentParser(description="The GGX LTC's error on a suite-like set, two table sets compared")
    p.add_argument("--out", type=Path, default=Path(__file__).resolve().parents[2] / "docs" / "benchmarks")
    p.add_argument("--lut-dir", type=Path, default=None, help="the tables measured (default: the shipped luts/)")
    p.add_argument("--before", default=BEFORE, help="git revision whose committed luts/ are the comparison")
    p.add_argument("--cache", type=Path, default=Path("out") / "ltc_suite_like", help="brute-force results cache")
    p.add_argument("--pixels", type=int, default=None, help="a seeded subset of this many points per sphere (default all)")
    p.add_argument("--cell", type=int, default=24, help="pixels per sphere cell of the grid of shading points")
    p.add_argument("--seed", type=int, default=0)
    return p.parse_args(argv)


def to_markdown(res):
    """The result as Markdown (ltc_suite_like.md)."""
    lines = ["# The GGX LTC on a suite-like set", "",
             f"Command: `python scripts/benchmark_ltc_suite_like.py` ({res['machine']}, {res['date']}; "
             f"{res['seconds']:.0f} s, brute force cached in `--cache`). Module: `validation/benchmarks/ltc_suite_like.py`.", "",
             "The validation suite's area lights (`suite_cases.build_cases()`: quads 0-3, disks 4-6 and the two sweeps' "
             "lights) with their cases' sphere layouts, seen by its orthographic camera; "
             f"{res['points']} shading points (the pixel centres of a {res['cell']} x {res['cell']} grid per sphere "
             f"cell{'' if res['pixels'] is None else ', ' + str(res['pixels']) + ' per sphere'}), each shaded at "
             f"r = {', '.join(f'{r:g}' for r in res['roughness'])}. Value: the single-scattering "
             "GGX lobe with F = 1 over the light, LTC (`shading.lobe_integral`, magnitude x integral) against its "
             "brute-force integral (`core/ltc/reference.py`, refined per point to 1e-3 relative; its error estimate "
             "is the `quadrature p99` column). Relative error over the values above "
             f"{res['floor']:g} x the sphere's maximum at that roughness (the suite's floor).", "",
             f"Before: the tables committed at `{res['before']}` (no band); after: `{res['after']}`.", ""]
    for kind in ("quad", "disk", "all"):
        lines += [f"## {'Quads' if kind == 'quad' else 'Disks' if kind == 'disk' else 'Quads and disks'}", "",
                  "| r | values | median before / after | p90 | RMS | mean signed | quadrature p99 |",
                  "|---|---|---|---|---|---|---|"]
        for g, b in res["before_report"][kind].items():
            a = res["after_report"][kind][g]
            if b is None:
                continue
            lines.append(f"| {g} | {b['values']} | {100 * b['median']:.2f}% / **{100 * a['median']:.2f}%** | "
                         f"{100 * b['p90']:.2f}% / **{100 * a['p90']:.2f}%** | {100 * b['rms']:.2f}% / "
                         f"**{100 * a['rms']:.2f}%** | {100 * b['bias']:+.2f}% / {100 * a['bias']:+.2f}% | "
                         f"{100 * b['quadrature_p99']:.1e}% |")
        lines.append("")
    return "\n".join(lines)


def run(args, progress=entry.flush_log):
    """Measure the tables of ``args.lut_dir`` and of revision ``args.before``; write ltc_suite_like.{json,md}."""
    t0 = time.perf_counter()
    entries = build_set(args.seed, args.cell, args.pixels)
    truths = truth_cached(entries, cache_dir=args.cache, progress=progress)
    after = lookup.LutSet.from_folder(args.lut_dir)
    with tempfile.TemporaryDirectory(prefix="rtl-luts-before-") as tmp:
        before = tables_at_revision(args.before, tmp)
        before_report, _ = measure(before, entries, truths)
    after_report, _ = measure(after, entries, truths)
    res = {"machine": f"{platform.machine()}, {os.cpu_count()} cores", "date": time.strftime("%Y-%m-%d"),
           "before": args.before, "after": str(args.lut_dir or "luts/ of this checkout"), "roughness": list(ROUGHNESS),
           "floor": FLOOR, "pixels": args.pixels, "cell": args.cell, "points": int(sum(len(e["P"]) for e in entries)),
           "before_report": before_report, "after_report": after_report, "seconds": time.perf_counter() - t0}
    markdown = to_markdown(res)
    outputs.write_results(args.out, "ltc_suite_like", res, markdown)
    progress(markdown)
    return res
