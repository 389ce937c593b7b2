"""A light sync is all or nothing (issue 27, item 3): one that cannot complete (here a LUT file deleted) leaves every
group, interface, driver and material link, and so the render, as they were; the user is told in the RT Lookdev panels
and by Sync Lights' report, with the way out the extension offers (Bake LUTs); once the table is back, the next sync
succeeds and the message goes.  Automatic (addon/light_sync.py) and by hand (Sync Lights)."""
from __future__ import annotations

import shutil

import numpy as np
import pytest

pytest.importorskip("OpenEXR")

pytestmark = pytest.mark.blender

#: Read by a quad light's GGX lobe and by nothing a point light needs: deleted, the sync for a new quad light fails.
MISSING = "ltc_ggx_inv.exr"


@pytest.fixture
def own_luts(tmp_path, lut_dir, monkeypatch):
    """A copy of the LUT folder, the add-on's LUT directory for the test."""
    from rt_lookdev.addon import preferences

    folder = tmp_path / "luts"
    shutil.copytree(lut_dir, folder)
    monkeypatch.setattr(preferences, "lut_directory", lambda context=None: folder)
    return folder


def _scene(bpy, luts):
    """A sphere with an RT Lit material under a point light, an orthographic camera, synced by the automatic sync."""
    from rt_lookdev.addon import compat, materials
    from rt_lookdev.core.materials.rt_lit_interface import Features
    from rt_lookdev.validation.harness import scene_render

    scene = bpy.context.scene
    mat = compat.new_material("Ball")
    materials.assign_rt_lit(mat, Features("turquin", "cod"), scene, luts)
    ball = bpy.data.objects.new("Ball", scene_render.uv_sphere_mesh("ball", 24, 12))
    ball.data.materials.append(mat)
    scene.collection.objects.link(ball)
    key = bpy.data.objects.new("A Key", bpy.data.lights.new("A Key", "POINT"))
    key.location, key.data.energy, key.data.shadow_soft_size = (1.0, -2.0, 2.0), 200.0, 0.0
    scene.collection.objects.link(key)
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.data.type, cam.data.ortho_scale = "ORTHO", 3.0
    cam.location, cam.rotation_euler = (0.0, -10.0, 0.0), (np.pi / 2, 0.0, 0.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    bpy.context.view_layer.update()
    return scene, ball


def _add_panel(bpy, scene):
    """A quad light in front of the sphere (its sync needs MISSING)."""
    panel = bpy.data.objects.new("B Panel", bpy.data.lights.new("B Panel", "AREA"))
    panel.location, panel.rotation_euler, panel.data.energy = (-1.0, -2.0, 1.0), (np.pi / 2, 0.0, 0.0), 100.0
    scene.collection.objects.link(panel)
    return panel


def _plain(value):
    return value.to_dict() if hasattr(value, "to_dict") else value.to_list() if hasattr(value, "to_list") else value


def _links(tree):
    return sorted((l.from_node.name, l.from_socket.identifier, l.to_node.name, l.to_socket.identifier)
                  for l in tree.links)


def _file_state(bpy):
    """Everything a sync could change: each node group's interface (with socket identifiers), nodes, links, drivers
    and custom properties; each material's nodes, their groups and unlinked inputs, and links; the images."""
    state = {}
    for ng in bpy.data.node_groups:
        drivers = ng.animation_data.drivers if ng.animation_data is not None else []
        state[f"group {ng.name}"] = (
            [(it.item_type, it.name, getattr(it, "in_out", None), getattr(it, "identifier", None),
              getattr(it, "socket_type", None), it.parent.name if it.parent else None) for it in ng.interface.items_tree],
            sorted((n.name, n.bl_idname, n.node_tree.name if getattr(n, "node_tree", None) else None) for n in ng.nodes),
            _links(ng),
            sorted((fc.data_path, fc.driver.expression, fc.driver.is_valid,
                    tuple((v.type, v.targets[0].id.name if v.targets[0].id else None, v.targets[0].data_path,
                           v.targets[0].transform_type, v.targets[0].transform_space) for v in fc.driver.variables))
                   for fc in drivers),
            {k: repr(_plain(ng[k])) for k in ng.keys()})
    for mat in bpy.data.materials:
        nodes = sorted((n.name, n.node_tree.name if getattr(n, "node_tree", None) else None,
                        tuple(repr(_plain(getattr(s, "default_value", None))) for s in n.inputs if not s.is_linked))
                       for n in mat.node_tree.nodes)
        state[f"material {mat.name}"] = (nodes, _links(mat.node_tree))
    state["images"] = sorted(image.name for image in bpy.data.images)
    return state


def _render(scene):
    from rt_lookdev.validation.harness.engines import render_cycles_passes

    return render_cycles_passes(scene, (8, 8))["Combined"]


class _Layout:
    """Stands in for bpy.types.UILayout (none can be made headless): records labels and operators."""

    def __init__(self, calls):
        self.calls = calls

    def __getattr__(self, name):          # box, column, row, separator, ...: the same recorder
        return lambda *args, **kwargs: self

    def label(self, text="", icon='NONE'):
        self.calls.append(("label", text, icon))

    def operator(self, idname, **kwargs):
        self.calls.append(("operator", idname))

    def prop(self, data, name, **kwargs):
        self.calls.append(("prop", name))


def _panel_text(bpy, scene):
    """What the material's RT Lookdev panel shows: its labels joined, and its operators."""
    from types import SimpleNamespace

    from rt_lookdev.addon import ui

    calls = []
    context = SimpleNamespace(material=bpy.data.materials["Ball"], scene=scene)
    ui.RTL_PT_material.draw(SimpleNamespace(layout=_Layout(calls)), context)
    return " ".join(c[1] for c in calls if c[0] == "label"), [c[1] for c in calls if c[0] == "operator"]


def test_a_sync_that_cannot_complete_changes_nothing_and_says_what_to_do(registered, empty_scene, lut_dir, own_luts,
                                                                          monkeypatch):
    from rt_lookdev.addon import light_sync, materials
    from rt_lookdev.addon.common import STAMP_KEY

    bpy = registered
    scene, ball = _scene(bpy, own_luts)
    assert materials.synced_light_kinds() == [("A Key", "point")]
    # a nested group from older code (another stamp, another interface): the sync rebuilds it in place
    stale = bpy.data.node_groups["RTL Surface"]
    stale[STAMP_KEY] = "stale"
    stale.interface.new_socket("From older code", in_out="INPUT", socket_type="NodeSocketFloat")
    bpy.context.view_layer.update()
    image = _render(scene)
    before = _file_state(bpy)
    assert image.max() > 0.05

    (own_luts / MISSING).unlink()
    _add_panel(bpy, scene)
    bpy.context.view_layer.update()                  # the automatic sync runs, and fails
    assert _file_state(bpy) == before
    assert np.array_equal(_render(scene), image)
    failed = light_sync.failure(scene)
    assert failed is not None and failed.luts
    label = bpy.ops.rtl.bake_luts.get_rna_type().name
    assert label == "Bake LUTs" and label in failed.message and "Preferences" in failed.message
    assert "missing: ltc_ggx_inv" in failed.message and "scripts/" not in failed.message
    text, operators = _panel_text(bpy, scene)
    assert "".join(failed.message.split()) in "".join(text.split()) and "rtl.bake_luts" in operators

    # while nothing it depends on changes, an update does not try the same sync again
    calls = []
    rebuild = materials.rebuild_rt_lit_groups
    monkeypatch.setattr(materials, "rebuild_rt_lit_groups", lambda *a, **k: calls.append(a) or rebuild(*a, **k))
    ball.select_set(True)
    bpy.context.view_layer.update()
    assert calls == [] and light_sync.failure(scene) == failed

    # by hand: Sync Lights reports the error, and changes nothing either
    with pytest.raises(RuntimeError, match="Bake LUTs") as info:
        bpy.ops.rtl.sync_lights()
    assert "missing: ltc_ggx_inv" in str(info.value) and "scripts/" not in str(info.value)
    assert _file_state(bpy) == before and len(calls) == 1

    # the table back: the next update syncs, and the message goes
    monkeypatch.setattr(materials, "rebuild_rt_lit_groups", rebuild)
    shutil.copyfile(lut_dir / MISSING, own_luts / MISSING)
    ball.select_set(False)
    bpy.context.view_layer.update()
    assert materials.synced_light_kinds() == [("A Key", "point"), ("B Panel", "quad")]
    assert light_sync.failure(scene) is None and "not synced" not in _panel_text(bpy, scene)[0]
    assert not np.array_equal(_render(scene), image)           # the panel light shades the sphere now


def test_bake_luts_after_a_failed_sync_syncs_the_lights(registered, empty_scene, lut_dir, own_luts, monkeypatch,
                                                        capfd):
    """Bake LUTs, the way out the message names, syncs the lights once it has baked the tables (the bake is stood in
    for by copying the table back: tests/blender/test_from_blender.py runs the real one)."""
    from types import SimpleNamespace

    from rt_lookdev.addon import light_sync, materials
    from rt_lookdev.core import lut_bake

    bpy = registered
    scene, _ = _scene(bpy, own_luts)
    (own_luts / MISSING).unlink()
    _add_panel(bpy, scene)
    bpy.context.view_layer.update()
    assert light_sync.failure(scene) is not None and materials.synced_light_kinds() == [("A Key", "point")]

    def bake(folder, groups=(), **kwargs):
        shutil.copyfile(lut_dir / MISSING, folder / MISSING)
        return [SimpleNamespace(state="baked", group=group, seconds=0.5) for group in groups]

    monkeypatch.setattr(lut_bake, "bake", bake)
    capfd.readouterr()
    assert bpy.ops.rtl.bake_luts() == {'FINISHED'}
    assert "the lights are synced with them" in capfd.readouterr().out
    assert materials.synced_light_kinds() == [("A Key", "point"), ("B Panel", "quad")]
    assert light_sync.failure(scene) is None


def test_the_automatic_syncs_failure_is_reported_as_a_warning(registered, capfd):
    """A handler cannot report: after a failed sync the handler has ``rtl.light_sync_report`` report the message (from
    a timer, in a window) as a warning in the status bar."""
    bpy = registered
    capfd.readouterr()
    assert bpy.ops.rtl.light_sync_report(message="Lights not synced: a test") == {'FINISHED'}
    assert "Warning: Lights not synced: a test" in capfd.readouterr().out
