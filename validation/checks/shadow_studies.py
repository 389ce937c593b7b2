"""Shadow studies on top of the path-traced twin (validation/checks/lookdev_twin.py), issue 29: the concave scene
against its twin with one reference for every row and path tracing's own time-vs-error curve beside it
(``concave_study``), and EEVEE's shadows against Cycles' (``eevee_shadow_study``).  The floor study
(``lookdev_twin.shadow_study``) stays with the twin, which the main job runs."""
from __future__ import annotations

import tempfile
import time
from pathlib import Path

import numpy as np

from ..harness import exr_images, metrics
from . import lookdev_twin


#: Path tracing's own curve on the concave study: the twin at these samples per pixel, against the reference.
PATH_TRACING_SPP = (1, 2, 4, 8, 16, 32, 64)
#: The seed of the curve's renders (the reference's seeds are 0, 1).
CURVE_SEED = 7


def path_tracing_curve(twin, reference, spps, folder, runs=1, log=print):
    """The twin path traced at each of ``spps`` (seed ``CURVE_SEED``, not the reference's) against the reference
    (``render_reference``): [{"spp", "errors": per object and "all", "seconds": the median of ``runs``}]."""
    out = []
    for spp in spps:
        times = []
        for _ in range(max(1, int(runs))):
            image, _, seconds = lookdev_twin.render_measurement(twin, reference["resolution"], spp, CURVE_SEED, folder)
            times.append(seconds)
        errors = lookdev_twin.sphere_errors(image, reference["shadowed"], reference["index"], reference["names"])
        out.append({"spp": spp, "errors": errors, "seconds": float(np.median(times)), "runs": times})
        log(f"[concave] path traced at {spp} spp: median {errors['all']['median']:.1%}, p90 {errors['all']['p90']:.1%}, "
            f"{out[-1]['seconds']:.2f} s")
    return out


def _concave_row(scene, twin, row, reference, runs, log):
    """One row of the concave study measured against the shared reference."""
    from ...core.materials.rt_lit_interface import Features

    features = Features(**row.get("features", {}))
    result = lookdev_twin.compare(scene, twin, tuple(reference["resolution"]), reference["samples"],
                                  tuple(reference["seeds"]), eevee=False, log=log,
                                  rt_lit_samples=lookdev_twin.rt_lit_samples_for(features), reference=reference,
                                  runs=runs)
    without = result["without_shadows"]
    return {"features": row.get("features", {}), "light_shadows": row.get("light_shadows"),
            "label": features.label(), "rt_lit_samples": lookdev_twin.rt_lit_samples_for(features),
            "errors": result["with_shadows"], "errors_unshadowed_twin": without["all"] if without else None,
            "seconds": result["seconds"]["rt_lit_cycles"], "runs": result["seconds"]["rt_lit_runs"],
            "shadowed_fraction": result.get("shadowed_fraction"), "images": result["images"]}


def concave_study(rows, lut_dir=None, resolution=(256, 192), samples=64, seeds=(0, 1), curve_spps=PATH_TRACING_SPP,
                  runs=1, log=print, lights=True, world=True):
    """The concave scene (``lookdev_scene.new_concave_scene``) against its twin, one row per entry of ``rows``
    ({"features": keyword arguments of ``Features``, "light_shadows": None or those of ``shadows.enable_shadows``}):
    each row built afresh (``study_scene``) and its RT Lit render (``runs`` times) measured over every RT Lit
    object's pixels against ONE reference, the twin at ``samples`` spp x ``seeds``, rendered with the first row's
    twin, which also renders path tracing's own curve (``path_tracing_curve``, ``curve_spps``; none when empty).
    ``lights``: False removes the studio lights (the world alone); ``world``: False leaves the world out (the lights
    alone).  Returns {"reference": its settings, noise and seconds, "rows": [...], "path_tracing": [...]}; each row
    keeps its images (not JSON)."""
    from ...addon import lookdev_scene
    from ...core.materials.rt_lit_interface import Features

    reference, curve, out = None, [], []
    with tempfile.TemporaryDirectory(prefix="rtl-concave-") as tmp:
        for row in rows:
            features = Features(**row.get("features", {}))
            scene, twin = lookdev_twin.study_scene(lambda: lookdev_scene.new_concave_scene(
                "Concave Study", features, hdri=lookdev_scene.DEFAULT_HDRI if world else None, view_transform="Standard",
                lut_dir=lut_dir, resolution=resolution), lut_dir, lights, row.get("light_shadows"))
            if reference is None:
                reference = lookdev_twin.render_reference(twin, lookdev_twin.number_objects(scene, twin), resolution,
                                                          samples, seeds, tmp, log)
                curve = path_tracing_curve(twin, reference, curve_spps, tmp, runs, log)
            out.append(_concave_row(scene, twin, row, reference, runs, log))
            e = out[-1]["errors"]["all"]
            log(f"[concave] {out[-1]['label']}, light shadows {row.get('light_shadows')}: median {e['median']:.1%}, "
                f"p90 {e['p90']:.1%}, {out[-1]['seconds']:.2f} s")
    return {"reference": {"samples": samples, "seeds": list(seeds), "resolution": list(resolution),
                          "objects": reference["names"], "seconds": reference["seconds"],
                          "noise_median": out[0]["errors"]["all"]["noise_median"] if out else None},
            "rows": out, "path_tracing": curve}


def render_eevee_measurement(scene, resolution, samples, folder):
    """EEVEE with the measurement settings of ``render_setup.configure_eevee_measurement`` (film filter 0), but the
    scene's world and EEVEE's shadows on, transparent film: (RGB (H, W, 3), seconds).  A scene with RT Lit shadows on
    renders through its compositor (the RGB is the composited image)."""
    import bpy

    from ...addon import compat, shadows
    from ..harness.engines import output_settings
    from ..harness.render_setup import configure_eevee_measurement, eevee_texture_filtering

    exr = Path(folder) / f"{scene.name.replace(' ', '_')}_eevee.exr"
    world = scene.world
    with lookdev_twin.kept_settings(scene):
        configure_eevee_measurement(scene, samples=samples, black_world=False)
        scene.world = world
        scene.eevee.use_shadows = True
        output_settings(scene, *resolution, exr)
        scene.render.film_transparent = True
        shadowed = shadows.shadows_enabled(scene)
        scene.render.use_compositing = shadowed
        compat.set_exr_output(scene.render.image_settings, multilayer=True)
        with eevee_texture_filtering():
            t0 = time.perf_counter()
            bpy.ops.render.render(write_still=True, scene=scene.name)
            seconds = time.perf_counter() - t0
    ch = exr_images.read_channels(exr)
    if shadowed:
        return np.stack([ch[f"Composite.Combined.{c}"] for c in "RGB"], axis=-1).astype(np.float64), seconds
    return exr_images.find_pass(ch, "Combined", "RGB").astype(np.float64), seconds


#: The scenes of ``eevee_shadow_study``: name -> its builder's name in addon/lookdev_scene.py.
EEVEE_STUDY_SCENES = ("floor", "concave")


def _eevee_study_scene(kind, lut_dir):
    """The floor study's scene (``new_lookdev_scene(floor=True)``) or the concave scene (``new_concave_scene``),
    ``Features()``, Standard view transform, in a fresh file; returns (scene, its RT Lit objects)."""
    import bpy

    from ...addon import lookdev_scene
    from ...core.materials.rt_lit_interface import Features

    if kind not in EEVEE_STUDY_SCENES:
        raise ValueError(f"unknown scene {kind!r}: one of {EEVEE_STUDY_SCENES}")
    bpy.ops.wm.read_homefile(use_empty=True)
    if kind == "floor":
        scene = lookdev_scene.new_lookdev_scene("EEVEE Shadow Study", Features(), view_transform="Standard",
                                                lut_dir=lut_dir, floor=True)
    else:
        scene = lookdev_scene.new_concave_scene("EEVEE Concave Study", Features(), view_transform="Standard",
                                                lut_dir=lut_dir)
    return scene, lookdev_scene.lookdev_spheres(scene)


def _eevee_study_regions(kind, scene, objects, index):
    """{region: mask}: every RT Lit object's interior pixels ("all"), and the floor study's "floor" and "spheres" or
    each object of the concave scene (its name without the scene's)."""
    interior = metrics.interior_pixels(index)
    regions = {"all": interior & (index > 0)}
    names = [o.name for o in objects]
    if kind == "floor":
        floor_index = names.index(f"{scene.name} Floor") + 1
        regions["floor"] = interior & (index == floor_index)
        regions["spheres"] = interior & (index > 0) & (index != floor_index)
    else:
        for i, name in enumerate(names, start=1):
            regions[name.removeprefix(f"{scene.name} ")] = interior & (index == i)
    return regions


def eevee_shadow_study(lut_dir=None, resolution=(160, 100), eevee_samples=16, jitter=False, cycles_shadows=None,
                       log=print, scene_kind="floor"):
    """EEVEE with RT Lit shadows (its Shadow pass, addon/shadows.py) against Cycles with RT Lit shadows (the ratio
    estimator, ``world=False``: EEVEE does not shadow the World term) on ``scene_kind``'s scene
    (``EEVEE_STUDY_SCENES``: the floor study, the concave scene; the studio lights and world, ``Features()``), and
    EEVEE against Cycles without shadows for reference.  ``eevee_samples``: EEVEE's samples per pixel; ``jitter``:
    the lights' ``use_shadow_jitter`` (EEVEE's soft shadows by jittered shadow maps); ``cycles_shadows``: the options
    of ``enable_shadows`` for Cycles (default 4 spp, OIDN).  Per-pixel relative error (``metrics.rel_values``) per
    region (``_eevee_study_regions``): {region: {"shadows", "no_shadows"}: {"median", "p90", ...}}, how much the
    shadows change Cycles' render ("cycles_shadows_vs_cycles", "all" region), and the seconds of each F12."""
    from ...addon import compat, shadows

    scene, objects = _eevee_study_scene(scene_kind, lut_dir)
    for i, obj in enumerate(objects, start=1):
        obj.pass_index = i
    for obj in scene.objects:
        if obj.type == "LIGHT":
            obj.data.use_shadow_jitter = bool(jitter)
    cycles_shadows = dict(cycles_shadows or {"samples": 4, "denoise": True})
    images, seconds = {}, {}
    with tempfile.TemporaryDirectory(prefix="rtl-eevee-shadows-") as tmp:
        scene.render.engine = "CYCLES"
        images["cycles"], index, seconds["cycles"] = lookdev_twin.render_measurement(scene, resolution, 1, 0,
                                                                                       tmp)
        shadows.enable_shadows(scene, lut_dir=lut_dir, **dict(cycles_shadows, world=False))
        images["cycles_shadows"], _, seconds["cycles_shadows"] = lookdev_twin.render_measurement(scene, resolution,
                                                                                                  1, 0, tmp)
        shadows.disable_shadows(scene, lut_dir)
        scene.render.engine = compat.eevee_engine()
        images["eevee"], seconds["eevee"] = render_eevee_measurement(scene, resolution, eevee_samples, tmp)
        shadows.enable_shadows(scene, lut_dir=lut_dir)
        images["eevee_shadows"], seconds["eevee_shadows"] = render_eevee_measurement(scene, resolution,
                                                                                     eevee_samples, tmp)
        shadows.disable_shadows(scene, lut_dir)
    regions = _eevee_study_regions(scene_kind, scene, objects, index)
    out = {"scene": scene_kind, "resolution": list(resolution), "eevee_samples": eevee_samples,
           "jitter": bool(jitter), "cycles_shadows": cycles_shadows, "seconds": seconds, "regions": {}}
    for region, mask in regions.items():
        out["regions"][region] = {}
        for case, (a, c) in {"shadows": ("eevee_shadows", "cycles_shadows"), "no_shadows": ("eevee", "cycles")}.items():
            rel, _ = metrics.rel_values(images[a], images[c], mask, lookdev_twin.FLOOR_FRACTION)
            out["regions"][region][case] = lookdev_twin.error_stats(rel)
        log(f"[eevee shadows] {scene_kind}, {region}: with shadows median "
            f"{out['regions'][region]['shadows']['median']:.2%} p90 {out['regions'][region]['shadows']['p90']:.2%}; "
            f"without median {out['regions'][region]['no_shadows']['median']:.2%}")
    # how much the shadows change Cycles' render (the size of what is compared)
    rel, _ = metrics.rel_values(images["cycles_shadows"], images["cycles"], regions["all"],
                                lookdev_twin.FLOOR_FRACTION)
    out["cycles_shadows_vs_cycles"] = lookdev_twin.error_stats(rel)
    log(f"[eevee shadows] F12 seconds {seconds}")
    out["images"] = {k: v.astype(np.float32) for k, v in images.items()}
    return out
