"""The talk's light controls measured (issue 17, item 4): the quad-to-spot fallback against the full quad light,
for the talk's three angle pairs, and what each control costs.

    python scripts/benchmark_light_fallback.py [--out docs/benchmarks] [--quick]

The talk (epilogue) shows a quad light and its fallback, a spot at the projector apex p = (d/2)/tan(phi/2) behind
the quad with the cone falloff between the inner and outer angles (theta, phi), side by side at
100/90, 120/110 and 140/130 degrees, and notes the worse fit for non-square lights.  Here both are RT Lit's own
numpy evaluation (core/materials/rt_lit.py, the function the node groups are emitted from) of the same material on
a floor H = 2, 6 and 20 m below the light, 4H x 4H, seen from 45 degrees: the quad light with its cone falloff
("quad+cone") against its fallback ("quad_spot": the quad's far field from its centre, core/lights.py), for a
1 x 1 m square and a 2 x 0.5 m rectangle, under Lambert, CoD and GGX r = 0.5.  Error: |fallback - quad| / quad over
the floor points where the quad gives > 1% of its maximum, pooled over the materials' channels.  Beside it, on the
Lambert floor, the two other readings of the talk's fallback: an isotropic spot at the apex (its images) and a
Lambertian spot at the apex.  Cost: the operations of one light in the Cycles tree (``flat_node_count`` of the
traced shading, Linear table reads) for the plain quad, the quad with range and cone, and the fallback.
Writes ``light_fallback.md`` and ``.json`` in ``--out``.
"""
from __future__ import annotations

import argparse
import math
import time

import numpy as np

from ..harness import entry, outputs
from ...core import lights
from ...core.ir.expr import table_filter
from ...core.ir.numpy_backend import flat_node_count
from ...core.lights import area_light_diameter
from ...core.lut import lookup
from ...core.lut.catalog import default_lut_dir
from ...core.materials import rt_lit
from ...core.materials.rt_lit_interface import Features, RT_LIT_INPUTS

ANGLE_PAIRS = ((100.0, 90.0), (120.0, 110.0), (140.0, 130.0))     # (outer, inner), degrees: the talk's
SHAPES = {"square 1 x 1 m": (1.0, 1.0), "rectangle 2 x 0.5 m": (2.0, 0.5)}
HEIGHT = 2.0
MATERIALS = {"Lambert": ("none", "lambert", 0.5), "CoD": ("none", "cod", 0.5), "GGX r 0.5": ("single", "lambert", 0.5)}
HEIGHTS = (2.0, 6.0, 20.0)


def _light_params(size, size_y, outer, inner, height, power=100.0):
    """Driver values of a quad light ``height`` above the origin, facing down (the identity rotation: it emits
    along -Z)."""
    return {"Location X": 0.0, "Location Y": 0.0, "Location Z": height, "Rotation W": 1.0, "Rotation X": 0.0,
            "Rotation Y": 0.0, "Rotation Z": 0.0, "Scale X": 1.0, "Scale Y": 1.0, "Scale Z": 1.0, "Power": power,
            "Color R": 1.0, "Color G": 1.0, "Color B": 1.0, "Size": size, "Size Y": size_y,
            "Cone Inner": math.radians(inner), "Cone Outer": math.radians(outer), "Exposure": 0.0, "Normalize": 1.0,
            "Determinant": 1.0}


def _floor(points, height):
    x = np.linspace(-2.0 * height, 2.0 * height, points)
    xx, yy = np.meshgrid(x, x, indexing="ij")
    pos = np.stack([xx, yy, np.zeros_like(xx)], -1).reshape(-1, 3)
    view = np.broadcast_to(np.array([0.0, -1.0, 1.0]) / math.sqrt(2.0), pos.shape)
    return pos, view


def radiance(tables, kind, material, params, pos, view):
    """RT Lit's radiance from one light of ``kind`` at the floor points (numpy, float64)."""
    specular, diffuse, roughness = material
    built = rt_lit.build_rt_lit(Features(specular, diffuse), (kind,))
    n = len(pos)
    values = {name: (np.full(n, float(s.default)) if s.kind == "float" else np.tile(np.asarray(s.default[:3], float),
                                                                                     (n, 1)))
              for name, s in RT_LIT_INPUTS.items()}
    values.update({"Roughness": np.full(n, roughness), "Base Color": np.ones((n, 3)), "Normal": np.zeros((n, 3)),
                   "Metallic": np.full(n, 1.0 if specular != "none" else 0.0),
                   "Position": pos, "Geometry Normal": np.tile([0.0, 0.0, 1.0], (n, 1)), "Incoming": view})
    for param, name in built.light_inputs[0].items():
        values[name] = np.full(n, float(params[param]))
    return built.evaluate(values, tables, np.float64)["Radiance"]


def _errors(quad, other):
    ok = quad > 0.01 * quad.max()
    rel = np.abs(other - quad)[ok] / quad[ok]
    return {"median": float(np.median(rel)), "p90": float(np.percentile(rel, 90)), "values": int(rel.size)}


def talk_readings(pos, params, albedo=1.0):
    """Lambert radiance under the two other readings of the talk's fallback, both at the projector apex: an
    isotropic spot of intensity P / pi (its images) and a Lambertian one, P cos(theta) / pi; cone falloff as RT Lit."""
    loc = np.array([params["Location X"], params["Location Y"], params["Location Z"]])
    apex, axis = lights.projector_apex(loc, 1.0, 0.0, 0.0, 0.0, params["Scale X"], params["Scale Y"],
                                       params.get("Scale Z", 1.0), params["Size"], params["Size Y"],
                                       params["Cone Outer"], "quad")
    d = apex - pos
    dist2 = np.maximum(np.sum(d * d, -1), lights.MIN_DISTANCE ** 2)
    l = d / np.sqrt(np.sum(d * d, -1))[:, None]
    cone = lights.apex_cone_falloff(pos, apex, axis, params["Cone Inner"], params["Cone Outer"])
    iso = params["Power"] / math.pi / dist2 * cone * np.maximum(l[:, 2], 0.0) * albedo / math.pi
    return {"isotropic spot at the apex": iso, "Lambertian spot at the apex": iso * np.maximum(-(l @ axis), 0.0)}


def costs():
    """Operations of one light in the Cycles tree (Linear table reads) for each way of shading a quad."""
    out = {}
    with table_filter("linear"):
        for label, features in (("Turquin + CoD", Features()), ("single + Lambert", Features("single", "lambert"))):
            base = flat_node_count(tuple(rt_lit.build_rt_lit(features, ()).function.outputs.values()))
            row = {}
            for kind in ("quad", "quad+range", "quad+cone", "quad+cone+range", "quad_spot", "quad_spot+range"):
                built = rt_lit.build_rt_lit(features, (kind,))
                row[kind] = flat_node_count(tuple(built.function.outputs.values())) - base
            out[label] = row
    return out


def run(args, progress=entry.flush_log):
    """Measure every shape, height and angle pair, and the costs; writes light_fallback.md and .json in
    ``args.out``."""
    t0 = time.perf_counter()
    tables = lookup.LutSet.from_folder(args.lut_dir or default_lut_dir())
    rows = []
    for shape, (sx, sy) in SHAPES.items():
        diameter = float(area_light_diameter(1.0, 1.0, sx, sy, "quad"))
        for height in HEIGHTS:
            pos, view = _floor(31 if args.quick else 81, height)
            for outer, inner in ANGLE_PAIRS:
                params = _light_params(sx, sy, outer, inner, height)
                quads, spots = [], []
                for material in MATERIALS.values():
                    quads.append(radiance(tables, "quad+cone", material, params, pos, view))
                    spots.append(radiance(tables, "quad_spot", material, params, pos, view))
                lambert = quads[0][:, 0]
                rows.append({"shape": shape, "height": height, "height_diameters": height / diameter,
                             "outer": outer, "inner": inner,
                             "projector_distance": 0.5 * diameter / math.tan(math.radians(outer) / 2),
                             "shipped": _errors(np.concatenate(quads, 1), np.concatenate(spots, 1)),
                             "materials": {name: _errors(q, sp) for name, q, sp in zip(MATERIALS, quads, spots)},
                             "talk": {name: _errors(lambert, v) for name, v in talk_readings(pos, params).items()}})
    result = {"quick": args.quick, "rows": rows, "costs": costs()}
    result["seconds"] = time.perf_counter() - t0
    md = to_markdown(result)
    outputs.write_results(args.out, "light_fallback", result, md)
    progress(md)
    return result


def _cell(s):
    return f"{s['median']:.1%} / {s['p90']:.1%}"


def to_markdown(result):
    """The result as Markdown (light_fallback.md)."""
    talk = list(result["rows"][0]["talk"])
    L = ["# Light controls: the quad-to-spot fallback against the quad, and what the controls cost", "",
         f"`python scripts/benchmark_light_fallback.py` (validation/benchmarks/light_fallback_benchmark.py; numpy, "
         f"{result['seconds']:.0f} s). A quad light H above a 4H x 4H floor, seen from 45 degrees, facing down, with "
         "the cone falloff of each of the talk's angle pairs at its projector apex (d/2)/tan(outer/2) behind it. RT "
         "Lit's fallback (core/lights.py `quad_spot_incidence`) is the quad's far field, P cos / pi from its centre, "
         "with the same cone falloff. Relative error against the quad, median / p90, over the floor where the quad "
         "gives > 1% of its maximum: the shipped fallback with the materials' channels pooled (Lambert, CoD, GGX "
         "r 0.5) and per material; on the Lambert floor, the other readings of the talk's fallback, both at the apex.",
         "", "| light | H (diameters) | outer / inner | apex behind | shipped, pooled | "
         + " | ".join(MATERIALS) + " | " + " | ".join(talk) + " |",
         "|---|---|---|---|---|" + "---|" * (len(MATERIALS) + len(talk))]
    for row in result["rows"]:
        L.append(f"| {row['shape']} | {row['height']:g} m ({row['height_diameters']:.1f}) | {row['outer']:g} / "
                 f"{row['inner']:g} deg | {row['projector_distance']:.3f} m | {_cell(row['shipped'])} | "
                 + " | ".join(_cell(row["materials"][m]) for m in MATERIALS) + " | "
                 + " | ".join(_cell(row["talk"][t]) for t in talk) + " |")
    L += ["", "## Cost of one light in the Cycles tree (operations, Linear table reads)", "",
          "| feature set | " + " | ".join(next(iter(result["costs"].values()))) + " |",
          "|---|" + "---|" * len(next(iter(result["costs"].values())))]
    for label, row in result["costs"].items():
        L.append(f"| {label} | " + " | ".join(str(v) for v in row.values()) + " |")
    return "\n".join(L) + "\n"


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--out", default="docs/benchmarks", help="folder for light_fallback.md / .json")
    p.add_argument("--quick", action="store_true", help="a coarser floor")
    p.add_argument("--lut-dir", default=None)
    return p.parse_args(argv)
