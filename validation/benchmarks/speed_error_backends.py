"""The speed-vs-error benchmark's renders: the path-traced reference and ladder (``render``), and the four
backends timed on a prepared scene: RT Lit in Cycles and EEVEE, GLSL and numpy at the Cycles passes."""
from __future__ import annotations

import statistics
import time
from pathlib import Path

import numpy as np

from .speed_error_scenes import (CHEAP_SECONDS, CYCLES_SLOPE_SPP, EEVEE_REPEATS, EEVEE_SLOPE_SPP, GLSL_FRAMES,
    GLSL_WIDTH, TIMING_REPEATS)
from ...core.ir import shader_text
from ...core.materials import rt_lit
from ...core.materials.rt_lit_interface import RADIANCE_OUTPUT
from ..checks.suite_scene import configure_truth_render
from ..checks.suite_scene import material_values, scene_light_params
from ..checks.suite_scene import numpy_radiance
from ..harness import exr_images
from ..harness import glsl_runner


# --- renders -----------------------------------------------------------------------------------------

def render(scene, spp, seed, folder, threads=2, passes=False):
    """One Cycles render of ``scene`` with the truth settings (``suite_cases.configure_truth_render``: CPU,
    fixed seed, no adaptive sampling or denoising, pixel-centre filter, direct light only), timed around
    ``bpy.ops.render.render`` (sync, compile, samples and the EXR write).  Returns {"rgb" (H, W, 3) float64,
    "seconds"} and, with ``passes``, "position", "normal" and "index" (the Object Index pass, 0 = none)."""
    import bpy

    from ...addon import compat
    from ..harness.engines import output_settings

    w, h = scene.render.resolution_x, scene.render.resolution_y
    path = Path(folder) / f"se_{abs(hash(scene.name)) % 10**8}_{spp}_{seed}.exr"
    configure_truth_render(scene, spp, seed, threads)
    output_settings(scene, w, h, path)
    compat.set_exr_output(scene.render.image_settings, multilayer=True)
    vl = scene.view_layers[0]
    vl.use_pass_combined = True
    vl.use_pass_normal = vl.use_pass_position = vl.use_pass_object_index = bool(passes)
    t0 = time.perf_counter()
    bpy.ops.render.render(write_still=True, scene=scene.name)
    seconds = time.perf_counter() - t0
    ch = exr_images.read_channels(path)
    out = {"rgb": exr_images.find_pass(ch, "Combined", "RGB").astype(np.float64), "seconds": seconds}
    if passes:
        out["position"] = exr_images.find_pass(ch, "Position", "XYZ").astype(np.float64)
        out["normal"] = exr_images.find_pass(ch, "Normal", "XYZ").astype(np.float64)
        out["index"] = np.rint(exr_images.object_index_pass(ch)[..., 0]).astype(int)
    path.unlink()
    return out


def median(xs):
    return float(statistics.median(xs))


def _per_sample(t1, tk, k):
    """(fixed, per-sample) seconds from the median times at 1 and ``k`` samples (intercept and slope)."""
    slope = max((tk - t1) / (k - 1), 0.0)
    return max(t1 - slope, 0.0), slope


def backend_cycles(prep, folder, threads):
    """(1) The RT Lit node group in Cycles: the passes render (untimed warm-up; its Combined is the image),
    then ``TIMING_REPEATS`` renders at 1 and at ``CYCLES_SLOPE_SPP`` samples (one when it takes over a
    second).  Total: the median 1-sample render."""
    prep.use_rt()
    passes = render(prep.scene, 1, 0, folder, threads, passes=True)
    t1 = [render(prep.scene, 1, 0, folder, threads)["seconds"] for _ in range(TIMING_REPEATS)]
    tk = [render(prep.scene, CYCLES_SLOPE_SPP, 0, folder, threads)["seconds"]]
    if tk[0] < 2 * CHEAP_SECONDS:
        tk += [render(prep.scene, CYCLES_SLOPE_SPP, 0, folder, threads)["seconds"] for _ in range(TIMING_REPEATS - 1)]
    fixed, slope = _per_sample(median(t1), median(tk), CYCLES_SLOPE_SPP)
    return {"image": passes["rgb"], "total_s": median(t1), "render_s": slope, "fixed_s": fixed,
            "seconds_1spp": t1, f"seconds_{CYCLES_SLOPE_SPP}spp": tk, "first_s": passes["seconds"]}, passes


_EEVEE = {}


def _eevee_warm_up(folder):
    """One tiny EEVEE render in a scratch scene: the GPU module's start (1-3 s, once per process) is not
    charged to the first case."""
    import bpy

    from ..harness.engines import render_engines

    if _EEVEE.get("warm"):
        return
    scene = bpy.data.scenes.new("RTL_se_warm_up")
    cam = bpy.data.objects.new("RTL_se_warm_cam", bpy.data.cameras.new("RTL_se_warm_cam"))
    scene.collection.objects.link(cam)
    scene.camera = cam
    try:
        render_engines(scene, ("BLENDER_EEVEE",), (8, 8), path=folder)
    finally:
        bpy.data.scenes.remove(scene)
        bpy.data.objects.remove(cam)
    _EEVEE["warm"] = True


def backend_eevee(prep, folder, repeats=EEVEE_REPEATS):
    """(2) RT Lit in EEVEE (``engines.render_engines``: 1 sample, film filter 0, black measurement world; the
    scene's world is put back).  Total: the first render of the case (shader compile included); then
    ``repeats`` renders at 1 and at ``EEVEE_SLOPE_SPP`` samples give the fixed and per-sample parts."""
    from ..harness.engines import eevee_available, render_engines

    ok, why = eevee_available()
    if not ok:
        return {"skipped": why}
    _eevee_warm_up(folder)
    prep.use_rt()
    scene, res = prep.scene, prep.resolution
    world = scene.world
    try:
        image, first = render_engines(scene, ("BLENDER_EEVEE",), res, path=folder)["BLENDER_EEVEE"]
        t1 = [render_engines(scene, ("BLENDER_EEVEE",), res, path=folder)["BLENDER_EEVEE"][1]
              for _ in range(repeats)]
        tk = [render_engines(scene, ("BLENDER_EEVEE",), res, path=folder, samples=EEVEE_SLOPE_SPP)["BLENDER_EEVEE"][1]
              for _ in range(repeats)]
    finally:
        scene.world = world
    fixed, slope = _per_sample(median(t1), median(tk), EEVEE_SLOPE_SPP)
    return {"image": image.astype(np.float64), "total_s": first, "compile_s": max(first - median(t1), 0.0),
            "render_s": slope, "fixed_s": fixed, "seconds_1spp": t1, f"seconds_{EEVEE_SLOPE_SPP}spp": tk,
            "renderer": why}


def _material_inputs(prep, i, passes, mask):
    """(RtLitMaterial, input values) of sphere i at the pixels ``mask`` of the passes: what
    ``suite_cases.numpy_radiance`` evaluates, per-pixel arrays for Position, Geometry Normal, Incoming."""
    from ..harness.engines import camera_incoming

    lights = scene_light_params(prep.scene)
    env, world_params = prep.world if prep.world is not None else (None, {})
    material = rt_lit.build_rt_lit(prep.variants[i]["features"], tuple(k for k, _ in lights), env)
    values = material_values(prep.objects[i].data.materials[0])
    pos = passes["position"][mask]
    values.update({"Position": pos, "Geometry Normal": passes["normal"][mask],
                   "Incoming": camera_incoming(prep.scene, pos)})
    for names, (_, params) in zip(material.light_inputs, lights):
        values.update({names[p]: params[p] for p in names})
    values.update({material.world_inputs[p]: v for p, v in world_params.items()})
    return material, values


PER_PIXEL = ("Position", "Geometry Normal", "Incoming")


class _GlslDraws:
    """The GLSL backend's resources: one program per RT Lit function (feature set), one input texture array,
    target and framebuffer per sphere, the tables' textures once."""

    def __init__(self, ctx):
        self.ctx, self.keep, self.programs, self.tables, self.draws = ctx, [], {}, {}, []
        self.times = {"emit_s": 0.0, "compile_s": 0.0, "upload_s": 0.0}

    def _k(self, obj):
        self.keep.append(obj)
        return obj

    def program(self, material):
        key = material.function.name
        if key not in self.programs:
            t0 = time.perf_counter()
            module = shader_text.emit(material.function, "glsl450")
            source = glsl_runner.fragment_source(module, [RADIANCE_OUTPUT])
            t1 = time.perf_counter()
            program = self._k(glsl_runner.compile_program(self.ctx, source))
            self.times["emit_s"] += t1 - t0
            self.times["compile_s"] += time.perf_counter() - t1
            self.programs[key] = (module, program)
        return self.programs[key]

    def add(self, material, values, luts, n):
        module, program = self.program(material)
        t0 = time.perf_counter()
        h = -(-n // GLSL_WIDTH)
        pad = np.arange(h * GLSL_WIDTH) % n
        images = {k: np.asarray(v)[pad].reshape(h, GLSL_WIDTH, 3) if k in PER_PIXEL else v for k, v in values.items()}
        packed = glsl_runner.pack_inputs(module, images, h, GLSL_WIDTH)
        ctx = self.ctx
        array = self._k(ctx.texture_array((GLSL_WIDTH, h, packed.shape[0]), 4, data=packed.tobytes(), dtype="f4"))
        array.filter = (ctx.NEAREST, ctx.NEAREST)
        tables = material.tables(luts)
        units = []
        for unit, (table, (sampler, th, tw)) in enumerate(module.tables.items(), start=1):
            if table not in self.tables:
                self.tables[table] = self._k(glsl_runner.texture(ctx, tables[table].require_data()))
            units.append((unit, sampler, self.tables[table]))
        if "rtl_inputs" in program:
            program["rtl_inputs"] = 0
        for unit, sampler, _ in units:
            if sampler in program:
                program[sampler] = unit
        target = self._k(ctx.texture((GLSL_WIDTH, h), 4, dtype="f4"))
        fbo = self._k(ctx.framebuffer(color_attachments=[target]))
        vao = self._k(ctx.vertex_array(program, []))
        ctx.finish()
        self.times["upload_s"] += time.perf_counter() - t0
        self.draws.append((array, units, fbo, vao, h, n))

    def frame(self):
        """Draw every sphere's pass and wait for it: seconds."""
        ctx = self.ctx
        t0 = time.perf_counter()
        for array, units, fbo, vao, h, _ in self.draws:
            fbo.use()
            ctx.viewport = (0, 0, GLSL_WIDTH, h)
            array.use(0)
            for unit, _, tex in units:
                tex.use(unit)
            vao.render(mode=ctx.TRIANGLES, vertices=3)
        ctx.finish()
        return time.perf_counter() - t0

    def read(self):
        return [np.frombuffer(fbo.read(components=4, dtype="f4"), np.float32).reshape(h, GLSL_WIDTH, 4)
                .reshape(-1, 4)[:n, :3].astype(np.float64) for _, _, fbo, _, h, n in self.draws]

    def release(self):
        for obj in reversed(self.keep):
            obj.release()
        self.keep.clear()


def backend_glsl(prep, passes, masks_all, luts):
    """(3) The emitted GLSL 4.50 of each sphere's RT Lit function evaluated on this machine's OpenGL at the
    Cycles passes (every pixel of the sphere one fragment of a full-screen pass: deferred shading of a
    G-buffer).  Total: emit + compile + upload of the inputs and tables + the first frame (the driver
    finishes compiling at the first draw); render only: the median of ``GLSL_FRAMES`` frames after it."""
    ok, why = glsl_runner.available()
    if not ok:
        return {"skipped": why}
    gl = _GlslDraws(glsl_runner.context())
    try:
        for i, mask in enumerate(masks_all):
            material, values = _material_inputs(prep, i, passes, mask)
            gl.add(material, values, luts, int(mask.sum()))
        first = gl.frame()
        frames = [gl.frame() for _ in range(GLSL_FRAMES)]
        image = np.zeros(passes["rgb"].shape)
        for mask, got in zip(masks_all, gl.read()):
            image[mask] = got
        t = gl.times
        total = t["emit_s"] + t["compile_s"] + t["upload_s"] + first
        return {"image": image, "total_s": total, "render_s": median(frames), "compile_s": t["compile_s"],
                "emit_s": t["emit_s"], "upload_s": t["upload_s"], "first_frame_s": first, "frames_s": frames,
                "programs": len(gl.programs), "renderer": why,
                "shader_cache_disabled": glsl_runner.shader_cache_disabled()}
    finally:
        gl.release()


def backend_numpy(prep, passes, index0, luts):
    """(4) The numpy backend (float32, Cycles' node semantics) at the passes: ``suite_cases.numpy_radiance``,
    the median of ``TIMING_REPEATS`` evaluations (the traced function is built with the scene, for every
    backend, and not counted)."""
    from types import SimpleNamespace

    variants = [SimpleNamespace(features=v["features"]) for v in prep.variants]
    p = {"Position": passes["position"], "Normal": passes["normal"]}
    times, image = [], None
    for _ in range(TIMING_REPEATS):
        t0 = time.perf_counter()
        image = numpy_radiance(prep.scene, variants, prep.objects, p, index0, luts, prep.world, np.float32)
        times.append(time.perf_counter() - t0)
    return {"image": np.asarray(image, np.float64), "total_s": median(times), "render_s": median(times),
            "seconds": times}
