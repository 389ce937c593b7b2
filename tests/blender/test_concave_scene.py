"""The asset-like concave scene of issue 29 (``lookdev_scene.new_concave_scene``): it builds, its twin copies every
RT Lit object, and the shadows (world occlusion and the lights' ratio estimator) bring RT Lit nearer the path-traced
twin on it (``shadow_studies.concave_study``, at a test's size)."""
from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("OpenEXR")

pytestmark = pytest.mark.blender

RESOLUTION = (64, 48)


def test_concave_scene_builds_and_its_twin_copies_every_rt_lit_object(empty_scene, lut_dir):
    import bpy

    from rt_lookdev.addon import convert, lookdev_scene
    from rt_lookdev.validation.checks import lookdev_twin

    scene = lookdev_scene.new_concave_scene("Concave", lut_dir=lut_dir, resolution=RESOLUTION)
    rt_lit = lookdev_scene.lookdev_spheres(scene)
    assert {o.name for o in rt_lit} == {f"Concave {label}" for label, _ in lookdev_scene.CONCAVE_MATERIALS}
    assert scene.camera is not None and scene.camera.data.type == "PERSP"
    assert scene.world is not None and any(o.type == "LIGHT" for o in scene.objects)
    suzanne = bpy.data.objects["Concave Suzanne"]
    assert all(p.use_smooth for p in suzanne.data.polygons)
    twin = lookdev_scene.add_path_traced_twin(scene)
    copies = lookdev_twin.twin_copies(twin)
    assert set(copies) == {o.name for o in rt_lit}
    for copy in copies.values():
        assert copy.material_slots and not any(convert.is_rt_lit_material(s.material) for s in copy.material_slots)


def test_shadows_lower_the_error_on_the_concave_scene(bpy_module, lut_dir):
    """Unshadowed RT Lit against the default shadows (the lights' and the World term's, 4 probe samples with OIDN),
    both measured against one twin reference over every RT Lit object's pixels."""
    from rt_lookdev.validation.benchmarks import concave_shadows_benchmark as benchmark
    from rt_lookdev.validation.checks import shadow_studies

    study = shadow_studies.concave_study(benchmark.QUICK_ROWS, lut_dir, RESOLUTION, samples=8, curve_spps=(2,),
                                         log=print)
    without, with_shadows = (row["errors"]["all"] for row in study["rows"])
    print(without, with_shadows)
    assert with_shadows["values"] > 1000 and with_shadows["values"] == without["values"]
    assert with_shadows["median"] < without["median"] and with_shadows["p90"] < without["p90"]
    assert np.isfinite(study["rows"][1]["images"]["rt_lit"]).all()
    point = study["path_tracing"][0]
    assert point["spp"] == 2 and point["errors"]["all"]["values"] > 1000 and point["seconds"] > 0.0
