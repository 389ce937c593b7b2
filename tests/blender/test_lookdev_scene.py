"""New Lookdev Scene and its path-traced twin (addon/lookdev_scene.py, addon/lookdev_operators.py), run
headless as an artist would from the Add menu, and measured with the validation's metrics
(validation/checks/lookdev_twin.py)."""

import numpy as np
import pytest

pytestmark = pytest.mark.blender


@pytest.fixture
def lookdev(registered, empty_scene):
    bpy = registered
    before = set(bpy.data.scenes.keys())
    assert bpy.ops.rtl.new_lookdev_scene('EXEC_DEFAULT', hdri="studio", view_transform="Standard") == {'FINISHED'}
    (name,) = set(bpy.data.scenes.keys()) - before
    scene = bpy.data.scenes[name]
    with bpy.context.temp_override(scene=scene):
        assert bpy.ops.rtl.add_path_traced_twin('EXEC_DEFAULT', samples=64) == {'FINISHED'}
    return bpy, scene, bpy.data.scenes[name + " Path Traced"]


def test_new_lookdev_scene_is_a_studio_setup(lookdev):
    from rt_lookdev.addon import light_model, lookdev_scene, materials
    from rt_lookdev.addon.common import WORLD_GROUP

    bpy, scene, _ = lookdev
    spheres = lookdev_scene.lookdev_spheres(scene)
    assert len(spheres) == len(lookdev_scene.ROWS) * len(lookdev_scene.ROUGHNESS)
    assert sorted(kind for _, kind in materials.scene_lights(scene)) == ["disk", "quad", "spot"]
    assert all(not light_model.unshaded_settings(obj, kind) for obj, kind in materials.scene_lights(scene))
    assert scene.camera is not None and scene.camera.data.type == "ORTHO"
    assert scene.render.engine == "CYCLES" and scene.cycles.max_bounces == 0
    assert scene.view_settings.view_transform == "Standard"
    assert WORLD_GROUP in bpy.data.node_groups        # the studio HDRI was baked: the World term is on
    metals = [o for o in spheres if "Gold" in o.name]
    assert {round(m.active_material.node_tree.nodes["RT Lit"].inputs["Metallic"].default_value) for m in metals} == {1}
    # the operator added a scene and touched nothing of the one that was there
    assert len(bpy.data.scenes) == 3


def test_twin_shares_lights_and_follows_the_spheres(lookdev):
    from rt_lookdev.addon import lookdev_scene

    bpy, scene, twin = lookdev
    assert lookdev_scene.twin_of(twin) == scene
    assert {o.name for o in scene.objects if o.type in ("LIGHT", "CAMERA")} == \
        {o.name for o in twin.objects if o.type in ("LIGHT", "CAMERA")}
    assert twin.world == scene.world and twin.cycles.max_bounces == 0
    copies = {o[lookdev_scene.TWIN_SOURCE_KEY]: o for o in twin.objects if lookdev_scene.TWIN_SOURCE_KEY in o.keys()}
    assert set(copies) == {o.name for o in lookdev_scene.lookdev_spheres(scene)}
    for name, copy in copies.items():
        original = bpy.data.objects[name]
        principled = copy.active_material.node_tree.nodes
        bsdf = next(n for n in principled if n.bl_idname == "ShaderNodeBsdfPrincipled")
        rt = original.active_material.node_tree.nodes["RT Lit"]
        for key in ("Roughness", "Metallic"):
            assert bsdf.inputs[key].default_value == pytest.approx(rt.inputs[key].default_value)
        assert copy.data == original.data            # same mesh, its own material
    moved = bpy.data.objects[next(iter(copies))]
    moved.location.z += 0.25
    bpy.context.view_layer.update()
    twin.view_layers[0].update()
    assert np.allclose(np.array(copies[moved.name].matrix_world), np.array(moved.matrix_world), atol=1e-6)
    # switching to the twin keeps the RT Lit groups' lights: it shades the same light objects
    from rt_lookdev.addon import materials

    signature = list(bpy.data.node_groups["RTL Scene Lights"]["rtl_light_signature"])
    bpy.context.window.scene = twin
    bpy.context.view_layer.update()
    assert not materials.lights_out_of_sync(twin)
    assert list(bpy.data.node_groups["RTL Scene Lights"]["rtl_light_signature"]) == signature
    bpy.context.window.scene = scene
    # adding the twin again rebuilds it; removing it leaves the lookdev scene whole
    with bpy.context.temp_override(scene=scene):
        assert bpy.ops.rtl.add_path_traced_twin('EXEC_DEFAULT') == {'FINISHED'}
    lookdev_scene.remove_twin(bpy.data.scenes[scene.name + " Path Traced"])     # the old twin is gone
    assert scene.name + " Path Traced" not in bpy.data.scenes
    assert len(lookdev_scene.lookdev_spheres(scene)) == 10
    with bpy.context.temp_override(scene=scene):
        assert bpy.ops.rtl.add_path_traced_twin.poll()


def test_twin_operator_refuses_a_scene_without_rt_lit(registered, empty_scene):
    assert not registered.ops.rtl.add_path_traced_twin.poll()


def test_rt_lit_against_the_path_traced_twin(lookdev):
    """The acceptance measurement at a test's size: RT Lit within the gates of the main job's comparison
    of the path-traced twin (EEVEE's render of the same scene: the next test)."""
    from rt_lookdev.validation.checks import lookdev_twin

    _, scene, twin = lookdev
    result = lookdev_twin.compare(scene, twin, resolution=(200, 100), samples=64, eevee=False, log=print)
    print(lookdev_twin.format_markdown(result))
    checks = lookdev_twin.checks(result)
    assert all(checks.values()), checks
    pooled = result["with_shadows"]["all"]
    assert pooled["values"] > 5000
    # the twin is a measurement, not a copy: the reference has its own noise and RT Lit differs by more
    assert 0.0 < pooled["noise_median"] < pooled["median"]
    # the spheres stand apart: a few percent of their pixels see a neighbour (3.7% at 320 x 160, 256 spp)
    assert 0.0 <= result["shadowed_fraction"] < 0.10
    images = result["images"]
    assert np.isfinite(images["rt_lit"]).all() and images["rt_lit"].max() > 0.05


@pytest.mark.development_release_only
def test_eevee_renders_the_lookdev_scene_as_cycles(lookdev, tmp_path):
    """EEVEE's render of the lookdev scene within its half-precision film of Cycles' RT Lit render (the main job's
    gate, ``lookdev_twin.EEVEE_MEDIAN_MAX``).  In the development release only: Blender 4.5's EEVEE compiles these
    materials for 91 s on llvmpipe, and test_engine_trees and test_shadows render RT Lit in EEVEE there."""
    from rt_lookdev.validation.checks import lookdev_twin

    _, scene, twin = lookdev
    resolution = (200, 100)
    lookdev_twin.number_objects(scene, twin)           # the object index pass the comparison's mask reads
    cycles, index, _ = lookdev_twin.render_rt_lit(scene, resolution, 1, str(tmp_path))
    stats = lookdev_twin.eevee_against_cycles(scene, resolution, cycles, index, str(tmp_path), print)
    if "skipped" in stats:
        pytest.skip(stats["skipped"])
    assert stats["count"] > 5000 and 0.0 < stats["median"] <= lookdev_twin.EEVEE_MEDIAN_MAX, stats
