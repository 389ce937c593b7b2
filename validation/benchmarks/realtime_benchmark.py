"""Frame time of the emitted RT Lit material: the real-time backend's speed.

    python scripts/benchmark_realtime.py [--width 1920 --height 1080] [--frames 5] [--lights 1,4,16]
                                         [--out docs/benchmarks/realtime.md] [--quick]

For each feature set (minimal: single-scattering GGX + Lambert, no world; all: Kulla-Conty, wrapped
diffuse, sheen, cloth and the World term) and light count (1: a quad; 4: quad, disk, point, spot; 16: the
five kinds in turn), a scene description is written (core/export/scene.py) and drawn by the standalone
renderer (validation/harness/realtime_render.py): one UV sphere (64 x 32) filling the whole frame behind an
orthographic camera, so every pixel is shaded once.  Measured, with Mesa's shader cache off:

- emit: writing the traced material as GLSL (core/ir/shader_text.py; the trace itself is cached per
  process and shared with the node backend);
- compile: the driver's compile and link of the program (``ctx.program``);
- first frame: the first draw, which on llvmpipe includes the JIT (LLVM) compilation of the shader;
- frame: median (and min, max) of ``frames`` draws after the first, each timed to ``glFinish``;
for the ``precise`` shaders (the backend's default: the arithmetic of the numpy backend) and without
``precise`` (what an engine may choose; its deviation is in docs/realtime.md).  The world's prefiltered
table is synthetic (grids.smooth_environment at the bake's size, 9 levels of 128 x 64): shading time
does not depend on its values.  Rows from a GPU (``--device-label``) go into the same table, marked.
"""
from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from ...core.export import scene as scene_io
from ...core.lights import SHADING_POINT_INPUTS, light_data
from ...core.lut import catalog, exr_io
from ...core.materials import rt_lit
from ...core.materials.rt_lit_interface import HORIZON_MODELS, LIGHT_KINDS, Features
from ..harness import entry, glsl_runner, grids
from ...core.ir.semantics import sample_bilinear
from ...core.lut.lookup import LutSet
from ..harness.realtime_render import RealtimeRenderer

REPO = Path(__file__).resolve().parents[2]
FEATURE_SETS = {"minimal": (Features("single", "lambert"), False),
                "all": (Features("kulla_conty", "wrapped", sheen=True, cloth=True), True)}


def uv_sphere(radius=1.0, segments=64, rings=32):
    """Triangle corners (3T, 3) and smooth normals (3T, 3) of a UV sphere at the origin."""
    theta = np.linspace(0.0, np.pi, rings + 1)
    phi = np.linspace(0.0, 2.0 * np.pi, segments + 1)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    n = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], -1)
    quads = []
    for i in range(rings):
        for j in range(segments):
            a, b, c, d = n[i, j], n[i + 1, j], n[i + 1, j + 1], n[i, j + 1]
            if i > 0:
                quads.append((a, b, d))
            if i < rings - 1:
                quads.append((b, c, d))
    normals = np.asarray(quads).reshape(-1, 3)
    return normals * radius, normals


def light_parameters(kind, k, count):
    """Driver parameters of the ``k``-th of ``count`` lights: spread on a ring in front of the sphere,
    aimed at its centre."""
    angle = 2.0 * np.pi * (k + 0.5) / count
    loc = np.array([2.5 * np.cos(angle), -3.0, 2.5 * np.sin(angle)])
    forward = -loc / np.linalg.norm(loc)                 # the light's -Z axis looks at the origin
    z = -forward
    x = np.cross([0.0, 0.0, 1.0], z)
    x = x / np.linalg.norm(x) if np.linalg.norm(x) > 1e-9 else np.array([1.0, 0.0, 0.0])
    y = np.cross(z, x)
    w, qx, qy, qz = _quaternion(np.stack([x, y, z], axis=1))
    values = dict(_LIGHT_SETTINGS, **{"Rotation W": w, "Rotation X": qx, "Rotation Y": qy, "Rotation Z": qz,
                                     "Location X": loc[0], "Location Y": loc[1], "Location Z": loc[2],
                                     "Power": _LIGHT_POWER.get(kind, 100.0)})
    return {param: float(values[param]) for param in light_data(kind).input_sockets
            if param not in SHADING_POINT_INPUTS}


#: The driver values every light of the benchmark shares (a light kind takes those its driver has).
_LIGHT_SETTINGS = {"Color R": 1.0, "Color G": 0.9, "Color B": 0.8, "Exposure": 0.0, "Normalize": 1.0, "Scale X": 1.0,
                   "Scale Y": 1.0, "Scale Z": 1.0, "Determinant": 1.0, "Size": 1.0, "Size Y": 0.6, "Spot Size": 1.0,
                   "Spot Blend": 0.3, "Strength": 1.0, "Radius": 0.1, "Soft Falloff": 1.0,
                   "Angle": float(np.radians(0.526)), "Cone Inner": float(np.radians(90.0)),
                   "Cone Outer": float(np.radians(100.0))}
_LIGHT_POWER = {"quad": 200.0, "disk": 200.0, "spot": 300.0, "spot_sphere": 300.0}


def _quaternion(m):
    """(w, x, y, z) of a rotation matrix (Shepperd's method)."""
    t = np.trace(m)
    if t > 0:
        s = 2.0 * np.sqrt(1.0 + t)
        return (0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s)
    i = int(np.argmax(np.diag(m)))
    j, k = (i + 1) % 3, (i + 2) % 3
    s = 2.0 * np.sqrt(1.0 + m[i, i] - m[j, j] - m[k, k])
    q = [0.0, 0.0, 0.0]
    q[i] = 0.25 * s
    q[j] = (m[j, i] + m[i, j]) / s
    q[k] = (m[k, i] + m[i, k]) / s
    return ((m[k, j] - m[j, k]) / s, *q)


def light_kinds(count):
    """1: a quad; 4: quad, disk, point, spot; otherwise every light kind in turn but the quad-to-spot fallback."""
    if count == 1:
        return ("quad",)
    if count == 4:
        return ("quad", "disk", "point", "spot")
    kinds = tuple(k for k in LIGHT_KINDS if k != "quad_spot")      # the Blender light types, no fallback
    return tuple(kinds[k % len(kinds)] for k in range(count))


def write_scene(folder, features, world, count, resolution, lut_dir):
    """A benchmark scene description in ``folder`` (one frame-filling sphere)."""
    folder = Path(folder)
    w, h = resolution
    half_w = 0.85                                      # frame corners inside the unit sphere
    half_h = half_w * h / w
    if half_w ** 2 + half_h ** 2 >= 1.0:
        raise ValueError(f"{w} x {h}: the sphere cannot fill a frame this tall")
    matrix = [[1.0, 0.0, 0.0, 0.0], [0.0, 0.0, -1.0, -5.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
    camera = scene_io.Camera(matrix, "ORTHO", 2.0 * half_w, clip_start=0.1, clip_end=20.0, resolution=(w, h))
    kinds = light_kinds(count)
    lights = [scene_io.SceneLight(f"{kind} {k}", kind, light_parameters(kind, k, count)) for k, kind in enumerate(kinds)]
    table_files, tables, world_desc = {}, {}, None
    env = None
    if world:
        from ...core.environment.prefilter import ROUGHNESS_LEVELS

        name = "env_benchmark"
        path = folder.parent / f"{folder.name}_{name}.exr"
        exr_io.write_table(path, grids.smooth_environment(64, 128),
                           {"table": name, "roughness_levels": json.dumps(list(ROUGHNESS_LEVELS))})
        params = {f"SH {i}": [0.5 / (1 + i)] * 3 for i in range(9)}
        params.update({"Strength": 1.0, "Rotation": [0.0, 0.0, 0.3]})
        world_desc = scene_io.SceneWorld(name, f"{name}.exr", params)
        table_files[f"{name}.exr"] = path
        tables[name] = f"{name}.exr"
        from ...core.materials.world_shading import WorldEnvironment
        env = WorldEnvironment.load(path, name)
    material = rt_lit.build_rt_lit(features, kinds, env)
    for table in material.table_names():
        if table in catalog.TABLES:
            spec = catalog.TABLES[table]
            tables[table] = spec.filename
            table_files[spec.filename] = Path(lut_dir) / spec.filename
    # every input at its socket default (inputs added later are covered), then the benchmark's values
    inputs = {name: (float(s.default) if s.kind == "float" else [float(x) for x in s.default[:3]])
              for name, s in rt_lit.RT_LIT_INPUTS.items()}
    inputs.update({"Base Color": [0.8, 0.5, 0.3], "Metallic": 0.3, "Roughness": 0.4, "IOR": 1.5,
                   "Specular IOR Level": 0.5, "Specular Tint": [1.0, 1.0, 1.0], "Wrap": 0.3, "Sheen Weight": 0.5,
                   "Sheen Tint": [1.0, 1.0, 1.0], "Cloth Weight": 0.3, "Cloth Color": [0.9, 0.7, 0.8],
                   "Emission Color": [1.0, 1.0, 1.0], "Emission Strength": 0.0, "Normal": [0.0, 0.0, 0.0],
                   "Diffuse Roughness": 0.6, "Sheen Roughness": 0.5})
    mat = scene_io.SceneMaterial("benchmark", features.as_dict(), inputs)
    positions, normals = uv_sphere()
    obj = scene_io.SceneObject("sphere", "benchmark", "0", len(positions) // 3)
    desc = scene_io.SceneDescription(camera, lights, world_desc, {"benchmark": mat}, [obj], tables,
                                     source="validation/benchmarks/realtime_benchmark.py")
    scene_io.write(folder, desc, {"0": (positions, normals)}, table_files)
    return scene_io.read(folder)


def measure(desc, frames, precise):
    """One configuration: {"emit_seconds", "compile_seconds", "first_frame_seconds", "frame_*", ...}."""
    t0 = time.perf_counter()
    with RealtimeRenderer(desc, precise=precise) as renderer:
        setup = time.perf_counter() - t0
        first = renderer.frame_seconds()
        times = [renderer.frame_seconds() for _ in range(frames)]
        image = renderer.render()
        t = renderer.timings
        shader = next(iter(renderer.shaders.values()))
        return {"emit_seconds": t["emit_seconds"], "compile_seconds": t["compile_seconds"],
                "setup_seconds": setup, "first_frame_seconds": first, "frame_seconds_median": statistics.median(times),
                "frame_seconds_min": min(times), "frame_seconds_max": max(times), "frames": len(times),
                "shader_lines": shader.fragment.count("\n"), "functions": len(shader.module.functions),
                "finite": bool(np.isfinite(image).all()), "covered": float((image.max(-1) > 0).mean())}


_FILTER_PROBE = """#version 450 core
uniform sampler2D lut;
uniform sampler2D coords;
layout(location = 0) out vec4 result;
void main()
{
    vec2 uv = texelFetch(coords, ivec2(gl_FragCoord.xy), 0).xy;
    result = textureLod(lut, uv, 0.0);
}
"""


def hardware_filtering_deviation(table, samples=256, seed=1):
    """Max relative deviation (where |exact| >= 1e-2) of the driver's own bilinear filtering (LINEAR,
    clamp to edge, no mipmaps) from exact bilinear filtering (core.ir.semantics.sample_bilinear) on
    ``table`` at random coordinates.  The backend does not rely on it (four texel fetches instead): the
    D3D11/12 specifications require only 8 bits of sub-texel precision (D3D11_SUBTEXEL_FRACTIONAL_BIT_COUNT),
    so GPUs quantise the weights; llvmpipe computes them in float."""
    ctx = glsl_runner.context()
    rng = np.random.default_rng(seed)
    uv = rng.uniform(0.0, 1.0, (samples, samples, 3)).astype(np.float32)
    program = glsl_runner.compile_program(ctx, _FILTER_PROBE)
    lut = glsl_runner.texture(ctx, table)
    lut.filter = (ctx.LINEAR, ctx.LINEAR)
    lut.repeat_x = lut.repeat_y = False
    coords = glsl_runner.texture(ctx, uv)
    target = ctx.texture((samples, samples), 4, dtype="f4")
    fbo = ctx.framebuffer([target])
    vao = ctx.vertex_array(program, [])
    try:
        lut.use(0)
        coords.use(1)
        program["lut"], program["coords"] = 0, 1
        fbo.use()
        ctx.viewport = (0, 0, samples, samples)
        vao.render(ctx.TRIANGLES, vertices=3)
        got = np.frombuffer(fbo.read(components=4, dtype="f4"), np.float32).reshape(samples, samples, 4)
    finally:
        for obj in (vao, fbo, target, coords, lut, program):
            obj.release()
    exact = sample_bilinear(table, uv[..., 0], uv[..., 1])
    return float((np.abs(got - exact) / np.maximum(np.abs(exact), 1e-2)).max())


def parse_args(argv):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--width", type=int, default=1920)
    p.add_argument("--height", type=int, default=1080)
    p.add_argument("--frames", type=int, default=5, help="timed frames after the first (median reported)")
    p.add_argument("--lights", default="1,4,16")
    p.add_argument("--features", default="minimal,all")
    p.add_argument("--horizon", default=Features().horizon, choices=HORIZON_MODELS,
                   help="the feature sets' area-light horizon (Features.horizon)")
    p.add_argument("--lut-dir", type=Path, default=None)
    p.add_argument("--out", type=Path, default=REPO / "docs" / "benchmarks" / "realtime.md")
    p.add_argument("--device-label", default=None, help="mark the rows as measured on this device (a GPU)")
    p.add_argument("--quick", action="store_true", help="960 x 540, 3 frames, lights 1 and 4 (the main job)")
    args = p.parse_args(argv)
    if args.quick:
        args.width, args.height, args.frames, args.lights = 960, 540, 3, "1,4"
    return args


def _machine():
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    return {"cpu": cpu, "cores": os.cpu_count(), "python": platform.python_version(), "numpy": np.__version__}


def run(args, progress=entry.flush_log):
    """Measure every feature set and light count; writes ``args.out`` (Markdown) and the JSON beside it (keeping the
    GPU rows measured elsewhere)."""
    glsl_runner.disable_shader_cache()
    ok, why = glsl_runner.available()
    if not ok:
        raise SystemExit(f"benchmark_realtime: {why}")
    lut_dir = args.lut_dir or catalog.default_lut_dir()
    device = args.device_label or why
    rows = []
    with tempfile.TemporaryDirectory(prefix="rtl-realtime-bench-") as tmp:
        for fname in args.features.split(","):
            features, world = FEATURE_SETS[fname]
            features = replace(features, horizon=args.horizon)
            for count in (int(c) for c in args.lights.split(",")):
                desc = write_scene(Path(tmp) / f"{fname}_{count}", features, world, count,
                                   (args.width, args.height), lut_dir)
                for precise in (True, False):
                    r = measure(desc, args.frames, precise)
                    r.update({"features": fname, "label": features.label() + (" + world" if world else ""),
                              "lights": count, "kinds": list(light_kinds(count)), "precise": precise,
                              "device": device, "gpu": bool(args.device_label)})
                    rows.append(r)
                    progress(f"{fname:8s} {count:2d} lights precise={precise!s:5s}: frame {1e3 * r['frame_seconds_median']:8.1f} ms "
                        f"(min {1e3 * r['frame_seconds_min']:.1f}), compile {r['compile_seconds']:.2f} s, first frame "
                        f"{r['first_frame_seconds']:.2f} s, {r['shader_lines']} lines")

    filtering = hardware_filtering_deviation(LutSet.from_folder(lut_dir).array("ltc_ggx_inv"))
    result = {"date": time.strftime("%Y-%m-%d"), "resolution": [args.width, args.height], "frames": args.frames,
              "machine": _machine(), "device": device, "rows": rows,
              "shader_cache_disabled": glsl_runner.shader_cache_disabled(),
              "hardware_filtering": {"device": device, "table": "ltc_ggx_inv", "max_rel": filtering}}
    out = Path(args.out)
    out.parent.mkdir(parents=True, exist_ok=True)
    previous = []
    json_path = out.with_suffix(".json")
    if args.device_label is None and json_path.exists():        # keep GPU rows measured elsewhere
        try:
            previous = [r for r in json.loads(json_path.read_text()).get("rows", []) if r.get("gpu")]
        except (OSError, ValueError):
            previous = []
    result["rows"] = rows + previous
    json_path.write_text(json.dumps(result, indent=1))
    out.write_text(to_markdown(result))
    progress(f"wrote {out} and {json_path}")
    return result


def to_markdown(result):
    """The result as Markdown (realtime.md)."""
    m = result["machine"]
    w, h = result["resolution"]
    lines = ["# Real-time backend: frame time of the emitted RT Lit material", "",
             f"Measured {result['date']} with `python scripts/benchmark_realtime.py` on {m['cpu']} ({m['cores']} cores), "
             f"{result['device']}; Mesa's shader cache {'off' if result['shader_cache_disabled'] else 'on'}. "
             f"{w} x {h}, every pixel shaded once (one frame-filling sphere, validation/benchmarks/realtime_benchmark.py); "
             f"frame = draw + glFinish, median of {result['frames']} after the first. Compile = the driver's compile "
             "and link; the first frame includes llvmpipe's JIT compilation of the shader; emit = writing the GLSL. `precise`: the backend's "
             "default (numpy's float32 arithmetic, docs/realtime.md); without it the compiler may fuse and reorder.", "",
             "| device | features | lights | precise | frame median (ms) | min–max (ms) | Mpixel/s | compile (s) | "
             "first frame (s) | emit (s) | GLSL lines |", "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in result["rows"]:
        mpx = w * h / r["frame_seconds_median"] / 1e6
        device = ("GPU: " if r.get("gpu") else "") + r["device"]
        lines.append(f"| {device} | {r['label']} | {r['lights']} | {'yes' if r['precise'] else 'no'} | "
                     f"{1e3 * r['frame_seconds_median']:.1f} | {1e3 * r['frame_seconds_min']:.1f}–"
                     f"{1e3 * r['frame_seconds_max']:.1f} | {mpx:.2f} | {r['compile_seconds']:.2f} | "
                     f"{r['first_frame_seconds']:.2f} | {r['emit_seconds']:.3f} | {r['shader_lines']} |")
    hf = result.get("hardware_filtering")
    if hf:
        lines += ["", f"Hardware bilinear filtering ({hf['device']}) against exact bilinear filtering on the "
                      f"{hf['table']} table: max relative deviation {hf['max_rel']:.2e}. The shaders do not use it "
                      "(four exact texel fetches, as the node groups): GPUs need only 8 bits of sub-texel precision "
                      "(D3D11_SUBTEXEL_FRACTIONAL_BIT_COUNT)."]
    if not any(r.get("gpu") for r in result["rows"]):
        lines += ["", "No GPU rows: no GPU was available to this run (the script runs unchanged on one: "
                      "`python scripts/benchmark_realtime.py --device-label \"<GPU name>\"` adds its rows)."]
    return "\n".join(lines) + "\n"
