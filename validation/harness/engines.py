"""EEVEE vs Cycles parity: render the current scene with each engine and compare per pixel.

``render_engines(scene)`` renders the scene's camera with Cycles (``configure_cycles_measurement``,
1 sample, no bounces) and with EEVEE (``configure_eevee_measurement``, 1 sample, film filter 0,
inside ``eevee_texture_filtering()``: no anisotropic filtering) to 32-bit float EXRs and reads
them back with OpenEXR. ``compare(cycles, eevee)`` gives the relative error where Cycles is above
a floor, and counts the pixels where Cycles is negative and EEVEE returned 0 (EEVEE clamps
negative emission). ``eevee_available()`` probes, once per process,
whether EEVEE can render here at all (it needs an OpenGL/Vulkan context; headless that is EGL, e.g.
Mesa llvmpipe).

Meant for emission-only scenes (a plane in front of a camera, black world): EEVEE's film is half
precision (relative error up to ~1e-3 from rounding alone, 2^-10), it writes 0 for negative
emission and returns 0 for out-of-domain asin/acos where Cycles clamps the input
(docs/blender.md, "EEVEE measurement"). With anisotropic filtering off, Linear image lookups
match exact bilinear filtering to half precision on llvmpipe (with the default 2x they are off by up
to 0.1 texel).

``render_engines`` changes the scene's render settings (engine, resolution, output format, the
settings of both configure functions) and leaves them as the last engine needs them.
"""
from __future__ import annotations

import contextlib
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np


from ...addon import compat
from . import exr_images
from .render_setup import configure_cycles_measurement, configure_eevee_measurement, eevee_texture_filtering

ENGINES = ("CYCLES", "BLENDER_EEVEE")


def read_exr_rgb(path):
    """RGB of a rendered EXR as float32 (H, W, 3), row 0 = top."""
    return exr_images.read_layer(path, "", "RGB")


def output_settings(scene, w, h, filepath):
    r = scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = int(w), int(h), 100
    r.use_border = False
    r.dither_intensity = 0.0
    r.use_compositing = False
    r.use_sequencer = False
    s = r.image_settings
    compat.set_exr_output(s)
    s.color_mode = "RGBA"
    s.exr_codec = "ZIP"
    r.filepath = str(filepath)


def configure_engine(scene, engine, samples=1):
    """Apply the measurement settings of ``engine`` ("CYCLES" or "BLENDER_EEVEE") to ``scene``."""
    if engine == "CYCLES":
        configure_cycles_measurement(scene, samples=samples, seed=0)
        scene.cycles.max_bounces = 0          # emission seen by camera rays needs no bounce
    elif engine == "BLENDER_EEVEE":
        configure_eevee_measurement(scene, samples=samples)
    else:
        raise ValueError(f"unknown engine {engine!r}; expected one of {ENGINES}")


def render_engines(scene, engines=ENGINES, resolution=(64, 64), path=None, samples=1):
    """Render ``scene``'s camera once per engine.

    ``resolution``: (width, height) or one int for a square. ``path``: folder for the EXRs
    (``<engine>.exr``; kept), a temporary folder (removed) when None.
    Returns {engine: (float32 array (H, W, 3), row 0 = top, render seconds)}.
    Call ``eevee_available()`` first: where EEVEE has no GPU context it aborts the process.
    The first EEVEE render of a process costs 1-3 s more than later ones (GPU module and shader
    set-up on llvmpipe); Cycles at 1 sample on a 64x64 emission plane takes about 10 ms.
    """
    import bpy

    if scene.camera is None:
        raise ValueError("the scene has no camera")
    w, h = (resolution, resolution) if np.isscalar(resolution) else resolution
    tmp = tempfile.TemporaryDirectory(prefix="rtl-eevee-parity-") if path is None else None
    folder = Path(tmp.name if tmp else path)
    folder.mkdir(parents=True, exist_ok=True)
    out = {}
    try:
        for engine in engines:
            exr = folder / f"{engine.lower()}.exr"
            configure_engine(scene, engine, samples=samples)
            output_settings(scene, w, h, exr)
            with eevee_texture_filtering() if engine == "BLENDER_EEVEE" else contextlib.nullcontext():
                t0 = time.perf_counter()
                bpy.ops.render.render(write_still=True, scene=scene.name)
                seconds = time.perf_counter() - t0
            out[engine] = (read_exr_rgb(exr), seconds)
    finally:
        if tmp is not None:
            tmp.cleanup()
    return out


def compare(cycles, eevee, positive_floor=1e-3):
    """Per-pixel, per-channel relative error of ``eevee`` against ``cycles`` where cycles > floor.

    Returns a dict: ``count`` (compared values), ``max``, ``p99``, ``median``, ``mean`` (relative
    errors, 0 when count is 0), ``argmax`` (index of the worst value), ``negative_clamped`` (values
    where Cycles < 0 and EEVEE == 0), ``negative`` (values where Cycles < 0), ``abs_max_below_floor``
    (max |eevee - cycles| where 0 <= cycles <= floor).
    """
    c = np.asarray(cycles, np.float64)
    e = np.asarray(eevee, np.float64)
    if c.shape != e.shape:
        raise ValueError(f"shape mismatch: cycles {c.shape}, eevee {e.shape}")
    big = c > positive_floor
    rel = np.abs(e[big] - c[big]) / c[big]
    small = (c >= 0) & ~big
    stats = {
        "count": int(big.sum()),
        "max": float(rel.max()) if rel.size else 0.0,
        "p99": float(np.percentile(rel, 99)) if rel.size else 0.0,
        "median": float(np.median(rel)) if rel.size else 0.0,
        "mean": float(rel.mean()) if rel.size else 0.0,
        "argmax": tuple(int(i) for i in np.argwhere(big)[int(rel.argmax())]) if rel.size else None,
        "negative": int((c < 0).sum()),
        "negative_clamped": int(((c < 0) & (e == 0)).sum()),
        "abs_max_below_floor": float(np.abs(e[small] - c[small]).max()) if small.any() else 0.0,
    }
    return stats


_PROBE = {}

_PROBE_CODE = r"""
import os, tempfile
import bpy
bpy.ops.wm.read_homefile(use_empty=True)
scene = bpy.context.scene
cam = bpy.data.objects.new("probe_camera", bpy.data.cameras.new("probe_camera"))
scene.collection.objects.link(cam)
scene.camera = cam
from rt_lookdev.addon import compat
scene.render.engine = compat.eevee_engine()
scene.eevee.taa_render_samples = 1
r = scene.render
r.resolution_x = r.resolution_y = 4
r.resolution_percentage = 100
r.image_settings.file_format = "OPEN_EXR"
with tempfile.TemporaryDirectory() as d:
    r.filepath = os.path.join(d, "probe.exr")
    bpy.ops.render.render(write_still=True)
    written = os.path.exists(r.filepath)
import gpu
print("RTL_EEVEE_PROBE", written, gpu.platform.backend_type_get(), gpu.platform.renderer_get(), flush=True)
"""


def eevee_available(timeout=120):
    """(True, renderer) when EEVEE can render here, else (False, reason). Probed once per process.

    The probe renders a 4x4 EEVEE image of an empty scene in a child interpreter: without a GPU
    context (no EGL / display) Blender does not raise, it aborts the whole process (epoxy: "Couldn't
    find current GLX or EGL context"), which must not take the test run with it. Costs about 3 s.
    """
    if "result" in _PROBE:
        return _PROBE["result"]
    try:
        proc = subprocess.run([sys.executable, "-c", _PROBE_CODE], capture_output=True, text=True,
                              timeout=timeout, env=dict(os.environ))
    except subprocess.TimeoutExpired:
        result = (False, f"EEVEE probe render did not finish in {timeout} s")
    else:
        lines = [ln.partition("RTL_EEVEE_PROBE ")[2] for ln in proc.stdout.splitlines()
                 if "RTL_EEVEE_PROBE " in ln]
        if proc.returncode == 0 and lines and lines[0].startswith("True "):
            result = (True, lines[0][len("True "):].strip())
        else:
            tail = " | ".join((proc.stdout + proc.stderr).strip().splitlines()[-2:])
            result = (False, f"EEVEE cannot render here (no GPU context, e.g. no EGL; probe exit "
                             f"{proc.returncode}): {tail[-300:]}")
    _PROBE["result"] = result
    return result


def render_cycles_passes(scene, resolution=(64, 64), path=None):
    """Cycles, 1 sample at pixel centres, emission only: {"Combined": (H, W, 3), "Position": ...,
    "Normal": ..., "seconds": s} (world space, row 0 = top; background pixels have Normal 0)."""
    import bpy

    w, h = (resolution, resolution) if np.isscalar(resolution) else resolution
    tmp = tempfile.TemporaryDirectory(prefix="rtl-passes-") if path is None else None
    folder = Path(tmp.name if tmp else path)
    folder.mkdir(parents=True, exist_ok=True)
    exr = folder / "cycles_passes.exr"
    try:
        configure_engine(scene, "CYCLES")
        output_settings(scene, w, h, exr)
        vl = scene.view_layers[0]
        vl.use_pass_position = vl.use_pass_normal = True
        compat.set_exr_output(scene.render.image_settings, multilayer=True)
        t0 = time.perf_counter()
        bpy.ops.render.render(write_still=True, scene=scene.name)
        seconds = time.perf_counter() - t0
        ch = exr_images.read_channels(exr)
        return {"Combined": exr_images.find_pass(ch, "Combined", "RGB"),
                "Position": exr_images.find_pass(ch, "Position", "XYZ"),
                "Normal": exr_images.find_pass(ch, "Normal", "XYZ"), "seconds": seconds}
    finally:
        if tmp is not None:
            tmp.cleanup()


def camera_incoming(scene, position):
    """Unit directions from shading points towards the camera (Geometry > Incoming)."""
    cam = scene.camera
    mw = np.array(cam.matrix_world, dtype=np.float64)
    if cam.data.type == "ORTHO":
        forward = -mw[:3, 2]
        return np.broadcast_to(-forward / np.linalg.norm(forward), np.shape(position)).astype(np.float64)
    d = mw[:3, 3] - np.asarray(position, np.float64)
    return d / np.maximum(np.linalg.norm(d, axis=-1, keepdims=True), 1e-30)


_RELOAD_CODE = """
import json, sys
import bpy
bpy.context.preferences.filepaths.use_scripts_auto_execute = False
bpy.ops.wm.open_mainfile(filepath=sys.argv[1], load_ui=False, use_scripts=False)
import numpy as np
from rt_lookdev.validation.harness.engines import render_cycles_passes
drivers = [fc.driver for ng in bpy.data.node_groups if ng.animation_data for fc in ng.animation_data.drivers]
np.save(sys.argv[2], render_cycles_passes(bpy.context.scene, (int(sys.argv[3]), int(sys.argv[4])))["Combined"])
print("RTL_RESULT " + json.dumps({"autoexec_fail": bpy.app.autoexec_fail, "drivers": len(drivers),
      "simple": all(d.is_simple_expression for d in drivers), "valid": all(d.is_valid for d in drivers)}))
"""


def render_reloaded(blend, resolution, timeout=300):
    """Open ``blend`` in a fresh process with Python auto-run off (as a user's Blender would) and render
    it as ``render_cycles_passes``: (Combined (H, W, 3), {"autoexec_fail", "drivers", "simple", "valid"}:
    whether a script was blocked, and the count and state of the drivers in node groups)."""
    import json

    w, h = resolution
    with tempfile.TemporaryDirectory(prefix="rtl-reload-") as tmp:
        out = Path(tmp) / "reloaded.npy"
        proc = subprocess.run([sys.executable, "-c", _RELOAD_CODE, str(blend), str(out), str(w), str(h)],
                              capture_output=True, text=True, timeout=timeout)
        lines = [ln for ln in proc.stdout.splitlines() if ln.startswith("RTL_RESULT ")]
        if proc.returncode != 0 or not lines:
            raise RuntimeError(f"reloading {blend} failed (exit {proc.returncode}):\n"
                               f"{proc.stdout[-2000:]}{proc.stderr[-2000:]}")
        return np.load(out), json.loads(lines[0][len("RTL_RESULT "):])
