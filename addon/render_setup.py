"""Cycles settings shared by every headless measurement (validation renders, conformance tests).

A measurement render must be linear, unclamped, reproducible and point-sampled:
- Cycles on the CPU, fixed seed, no adaptive sampling, no denoising, no sample clamping;
- pixel filter Gaussian at its minimum width 0.01, so each sample is taken at the pixel centre.
  Not Box: Cycles' Box filter ignores ``filter_width`` and spreads samples over the whole pixel
  (measured: 320 partly covered silhouette pixels on a 96 px sphere with Box at 0.01, 9 with
  Gaussian; ../shared/reference/blender_addon.md §5, scripts/validate_energy.py);
- view transform Standard, look None, exposure 0, gamma 1 (the EXR holds scene-linear values);
- a fixed number of threads.
"""
from __future__ import annotations


def configure_cycles_measurement(scene, samples=1, seed=0, threads=2):
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.device = "CPU"
    c.samples = int(samples)
    c.use_adaptive_sampling = False
    c.use_denoising = False
    c.seed = int(seed)
    c.use_animated_seed = False
    c.sample_clamp_direct = 0.0
    c.sample_clamp_indirect = 0.0
    c.pixel_filter_type = "GAUSSIAN"
    c.filter_width = 0.01
    scene.render.threads_mode = "FIXED"
    scene.render.threads = int(threads)
    scene.render.film_transparent = False
    vs = scene.view_settings
    vs.view_transform = "Standard"
    vs.look = "None"
    vs.exposure = 0.0
    vs.gamma = 1.0
