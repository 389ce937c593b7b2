"""Cycles settings shared by every headless measurement (validation renders, conformance tests).

A measurement render must be linear, unclamped, reproducible and point-sampled:
- Cycles on the CPU, fixed seed, no adaptive sampling, no denoising, no sample clamping;
- pixel filter Gaussian at its minimum width 0.01, so each sample is taken at the pixel centre.
  Not Box: Cycles' Box filter ignores ``filter_width`` and spreads samples over the whole pixel
  (measured: 320 partly covered silhouette pixels on a 96 px sphere with Box at 0.01, 9 with
  Gaussian; docs/blender.md, "Render passes"; scripts/validate_energy.py);
- view transform Standard, look None, exposure 0, gamma 1 (the EXR holds scene-linear values);
- a fixed number of threads.

``configure_eevee_measurement`` and ``eevee_texture_filtering`` are the EEVEE counterpart, for
comparing emission-only materials with Cycles (EEVEE's film is half precision and it writes 0 for
negative emission, so it is never the ground truth).
"""
from __future__ import annotations

import contextlib


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


def configure_eevee_measurement(scene, samples=1, filter_size=0.0, black_world=True):
    """EEVEE settings for a per-pixel comparison of emission-only materials with Cycles.

    EEVEE (Blender 4.2+/5.0, "EEVEE Next") cannot match Cycles bit for bit: its film is half
    precision (relative error up to 2^-10) and it writes 0 where the emission is negative
    (docs/blender.md, "EEVEE measurement"). These settings remove every other source of
    difference found on Mesa llvmpipe (EGL):
    - ``taa_render_samples`` = ``samples`` (1: a single sample, no temporal accumulation);
    - film filter ``filter_size`` 0 (default 1.5 px; the RNA minimum; EEVEE has no filter type).
      Measured on a one-pixel checker: 1 sample is taken at the pixel centre and matches Cycles
      exactly with any filter size; with 4 samples and 1.5 px the checker is blurred (relative
      error 1.24), with 0 it stays exact (the sub-pixel jitter apparently scales with the filter
      size), so
      ``samples`` > 1 only averages identical centre samples;
    - ray tracing, fast GI, shadows, overscan, volume shadows, motion blur off; the indirect and
      glossy clamps set to 0 (they only clamp lighting, never emission, but keep them out of the way);
    - view transform Standard, look None, exposure 0, gamma 1, no curves, no white balance, no
      dithering, no compositing or sequencer pass, opaque film (the EXR holds scene-linear values).
    - ``black_world``: the scene gets the world ``RTL_black_world`` (colour and background 0,
      created once and reused; the scene's own world data is not edited), so uncovered pixels are 0
      and no world light reaches the film.
    EEVEE 5.0 has no bloom, AO or SSR settings any more (replaced by the ray-tracing module and the
    compositor's Glare node) and no precision switch for its film. ``scene.render.threads`` is left
    alone: it makes no measurable difference (the work is on the GPU, or in llvmpipe's own
    threads). Materials keep their own settings; an opaque emission material needs none.
    Image textures: also render inside ``eevee_texture_filtering()`` (a preference, not a scene
    setting): with the default 2x anisotropic filtering, Linear lookups on llvmpipe are off by up to
    0.1 texel; without it they match exact bilinear filtering to the film's half precision.
    """
    from ...addon import compat

    scene.render.engine = compat.eevee_engine()
    e = scene.eevee
    e.taa_render_samples = int(samples)
    e.use_taa_reprojection = False
    e.use_raytracing = False
    e.use_fast_gi = False
    e.use_shadows = False
    e.use_volumetric_shadows = False
    e.use_overscan = False
    e.use_bokeh_jittered = False
    e.clamp_surface_direct = 0.0
    e.clamp_surface_indirect = 0.0
    e.gi_glossy_clamp = 0.0
    r = scene.render
    r.filter_size = float(filter_size)
    r.use_motion_blur = False
    r.dither_intensity = 0.0
    r.use_compositing = False
    r.use_sequencer = False
    r.film_transparent = False
    vs = scene.view_settings
    vs.view_transform = "Standard"
    vs.look = "None"
    vs.exposure = 0.0
    vs.gamma = 1.0
    vs.use_curve_mapping = False
    vs.use_white_balance = False
    if black_world:
        scene.world = _black_world()


def _black_world():
    import bpy

    from ...addon import compat

    return blacken_world(bpy.data.worlds.get("RTL_black_world") or compat.new_world("RTL_black_world"))


def blacken_world(world):
    """``world`` with a black colour and every Background node at colour 0, strength 0."""
    world.color = (0.0, 0.0, 0.0)
    if world.node_tree is not None:
        for node in world.node_tree.nodes:
            if node.bl_idname == "ShaderNodeBackground":
                node.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
                node.inputs["Strength"].default_value = 0.0
    return world


@contextlib.contextmanager
def eevee_texture_filtering(anisotropic_filter="FILTER_0"):
    """Set the GPU texture anisotropic filtering preference for the duration of a ``with`` block.

    EEVEE samples Linear image textures with mipmaps and anisotropic filtering (preference
    ``system.anisotropic_filter``, default ``FILTER_2``). On Mesa llvmpipe that moves magnified
    lookups by up to 0.1 texel (measured on a 16-texel ramp over 64 px: 0.049 texel with FILTER_2,
    0.009 texel = one half-float ulp with FILTER_0). Cycles ignores the preference. The previous
    value is restored on exit; nothing is saved to the user's preferences file.
    """
    import bpy

    system = bpy.context.preferences.system
    old = system.anisotropic_filter
    system.anisotropic_filter = anisotropic_filter
    try:
        yield
    finally:
        system.anisotropic_filter = old
