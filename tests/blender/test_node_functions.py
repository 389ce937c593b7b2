"""Node functions as nested node groups: conformance with numpy, stamps, reuse, interface."""
from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("OpenEXR")

_HERE = Path(__file__).resolve().parent
if str(_HERE) not in sys.path:
    sys.path.insert(0, str(_HERE))

from function_conformance import check_function, unit_vectors  # noqa: E402

pytestmark = pytest.mark.blender

SIZE = 48


def _punctual_inputs(seed=3):
    rng = np.random.default_rng(seed)
    shape = (SIZE, SIZE)
    z = [0.0, 0.0, 1.0]
    n = unit_vectors(rng, shape, special=[z] * 8)
    v = unit_vectors(rng, shape, special=[z, z, [1, 0, 0], [0, 0, -1], z, [0.6, 0, 0.8], z, z])
    l = unit_vectors(rng, shape, special=[z, [0, 0, -1], z, z, [1, 0, 0], [-0.6, 0, 0.8], [0, 0, -1], z])
    # view above the normal in most texels (the material sees front faces), some below
    flip = np.einsum("...i,...i->...", n, v) < 0
    v[flip[..., None].repeat(3, -1) & (rng.random(shape) < 0.8)[..., None].repeat(3, -1)] *= -1
    r = rng.random(shape).astype(np.float32)
    r.reshape(-1)[:8] = [0.0, 1.0, 0.0, 1.0, 0.5, 0.0, 1e-3, 1.0]
    wrap = rng.random(shape).astype(np.float32)
    wrap.reshape(-1)[:3] = [0.0, 1.0, 1.0]
    return {"N": n, "V": v, "L": l, "Roughness": r, "Wrap": wrap}


@pytest.mark.parametrize("lobe", ["ggx", "kulla_conty", "lambert", "cod", "wrapped", "cloth", "sheen"])
def test_punctual_lobe_groups_match_numpy(empty_scene, lut_dir, lobe):
    from rt_lookdev.core.lut import lookup
    from rt_lookdev.core.materials import lobes

    with lookup.use_lut_dir(lut_dir):
        fn = lobes.PUNCTUAL_LOBES[lobe]
        vals = _punctual_inputs()
        check_function(fn, {k: vals[k] for k in fn.input_sockets}, lut_dir)


def test_groups_are_stamped_reused_and_rebuilt_in_place(empty_scene, lut_dir):
    import bpy

    from rt_lookdev.addon.node_emit import MAX_GROUP_NODES, ensure_function_group, tree_node_counts
    from rt_lookdev.core.lut import lookup
    from rt_lookdev.core.materials import lobes

    with lookup.use_lut_dir(lut_dir):
        fn = lobes.PUNCTUAL_LOBES["ggx"]
        ng = ensure_function_group(fn, lut_dir)
        assert ng.name == "RTL Punctual GGX" and ng["rtl_stamp"].endswith(fn.function.key)
        ng.nodes[0]["marker"] = 1                       # survives only if the group is not rebuilt
        groups_before = len(bpy.data.node_groups)
        assert ensure_function_group(fn, lut_dir) == ng
        assert ng.nodes[0].get("marker") == 1 and len(bpy.data.node_groups) == groups_before
        ng["rtl_stamp"] = "stale"                       # as if the source had changed
        assert ensure_function_group(fn, lut_dir) == ng                     # same datablock...
        assert all(n.get("marker") is None for n in ng.nodes)              # ...rebuilt
        assert ng["rtl_stamp"].endswith(fn.function.key)
        assert max(tree_node_counts(ng).values()) <= MAX_GROUP_NODES
        # the same table image serves every lookup
        assert len([i for i in bpy.data.images if i.name == "RTL_ggx_one_minus_E"]) == 1


def test_interface_has_descriptions_ranges_and_panels(empty_scene, lut_dir):
    from rt_lookdev.addon.node_emit import ensure_function_group
    from rt_lookdev.core.lut import lookup
    from rt_lookdev.core.materials import rt_lit

    with lookup.use_lut_dir(lut_dir):
        ng = ensure_function_group(rt_lit.SURFACE, lut_dir)
    items = {i.name: i for i in ng.interface.items_tree}
    rough = items["Roughness"]
    assert rough.subtype == "FACTOR" and rough.min_value == 0.0 and rough.max_value == 1.0
    assert rough.default_value == pytest.approx(0.5) and "roughness" in rough.description.lower()
    assert items["Base Color"].socket_type == "NodeSocketColor"
    assert items["Normal"].hide_value
    panels = {i.name for i in ng.interface.items_tree if i.item_type == "PANEL"}
    assert {"Surface", "Specular", "Sheen", "Cloth"} <= panels
    assert items["Metallic"].parent.name == "Surface"


def _area_inputs(kind, seed=5):
    """Shading points on the unit sphere seen from outside; lights of many sizes, tilts and
    positions, some below the horizon, in the tangent plane, or degenerate."""
    rng = np.random.default_rng(seed)
    shape = (SIZE, SIZE)
    count = SIZE * SIZE
    n = unit_vectors(rng, shape).reshape(-1, 3)
    p = n.copy()
    v = n + rng.normal(size=(count, 3)) * 0.6
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    center = p + rng.normal(size=(count, 3)) * 2.0
    center[:8] = p[:8] + n[:8] * np.array([2.0, -1.0, 0.0, 1e-3, 5.0, 0.5, 1.0, 2.0])[:, None]   # above, below,
    u = rng.normal(size=(count, 3)) * rng.uniform(0.01, 1.5, (count, 1))                        # in plane, ...
    w = rng.normal(size=(count, 3))
    w -= u * (np.sum(u * w, -1) / np.maximum(np.sum(u * u, -1), 1e-12))[:, None]
    w *= rng.uniform(0.01, 1.5, (count, 1)) / np.maximum(np.linalg.norm(w, axis=-1, keepdims=True), 1e-12)
    u[8], w[8] = 0.0, 0.0                        # degenerate: zero size
    u[9], w[9] = [1e-4, 0, 0], [0, 1e-4, 0]      # tiny
    r = rng.random(count)
    r[:6] = [0.0, 1.0, 0.0, 1.0, 0.5, 1e-3]
    vals = {"Position": p, "N": n, "V": v, "Roughness": r, "Wrap": rng.random(count)}
    if kind == "quad":
        corners = [center - u - w, center + u - w, center + u + w, center - u + w]
        vals.update({f"p{i}": c for i, c in enumerate(corners)})
    else:
        vals.update({"Center": center, "Axis U": u, "Axis V": w})
    return {k: np.asarray(a, np.float32).reshape(shape + np.shape(a)[1:]) for k, a in vals.items()}


@pytest.mark.parametrize("kind", ["quad", "disk"])
@pytest.mark.parametrize("lobe", ["ggx", "kulla_conty", "lambert", "cod", "wrapped", "cloth", "sheen"])
def test_area_lobe_groups_match_numpy(empty_scene, lut_dir, kind, lobe):
    from rt_lookdev.addon.node_emit import MAX_GROUP_NODES, ensure_function_group, tree_node_counts
    from rt_lookdev.core.lut import lookup
    from rt_lookdev.core.materials import lobes

    with lookup.use_lut_dir(lut_dir):
        fn = lobes.area_lobes(kind)[lobe]
        vals = _area_inputs(kind)
        check_function(fn, {k: vals[k] for k in fn.input_sockets}, lut_dir)
        counts = tree_node_counts(ensure_function_group(fn, lut_dir))
    print(counts)
    assert max(counts.values()) <= MAX_GROUP_NODES


@pytest.mark.parametrize("kind", ["quad", "disk", "point", "spot", "sun"])
def test_shade_groups_match_numpy(empty_scene, lut_dir, kind):
    """A whole light on the material (all lobes of two feature sets), nested groups included."""
    from rt_lookdev.core.lut import lookup
    from rt_lookdev.core.materials import rt_lit
    from rt_lookdev.core.materials.rt_lit_interface import Features

    rng = np.random.default_rng(9)
    base = _area_inputs("quad" if kind != "disk" else "disk")
    shape = (SIZE, SIZE)
    vals = dict(base)
    vals.update({"F0": rng.random(shape + (3,)), "Albedo": rng.random(shape + (3,)),
                 "Sheen Color": rng.random(shape + (3,)), "Cloth Color": rng.random(shape + (3,)),
                 "Cloth Weight": rng.random(shape), "Radiance": rng.random(shape + (3,)) * 10,
                 "Irradiance": rng.random(shape + (3,)) * 10})
    l = base["Position"] * 0 + unit_vectors(rng, shape)
    vals["L"] = l
    with lookup.use_lut_dir(lut_dir):
        for features in (Features("kulla_conty", "wrapped", sheen=True, cloth=True), Features("turquin", "cod")):
            fn = rt_lit.shade_function(kind, features)
            check_function(fn, {k: np.asarray(vals[k], np.float32) for k in fn.input_sockets}, lut_dir)


def test_surface_group_matches_numpy(empty_scene, lut_dir):
    from rt_lookdev.core.materials import rt_lit

    rng = np.random.default_rng(2)
    shape = (SIZE, SIZE)
    vals = {}
    for name, sock in rt_lit.SURFACE.input_sockets.items():
        if sock.kind == "float":
            vals[name] = rng.uniform(-0.2, 1.2, shape)
        else:
            vals[name] = rng.normal(size=shape + (3,))
    vals["IOR"] = rng.uniform(0.5, 3.0, shape)
    vals["Normal"][:8] = 0.0                        # unlinked normal: the geometry's
    check_function(rt_lit.SURFACE, {k: np.asarray(v, np.float32) for k, v in vals.items()}, lut_dir)


def test_every_catalog_group_builds_small_and_the_technique_groups_match_numpy(empty_scene, lut_dir):
    import bpy

    from rt_lookdev.addon.node_emit import MAX_GROUP_NODES, ensure_function_group, tree_node_counts
    from rt_lookdev.addon.operators import RTL_OT_add_node_groups
    from rt_lookdev.addon.preferences import classes as pref_classes  # noqa: F401
    from rt_lookdev.core.lut import lookup
    from rt_lookdev.node_groups import catalog

    with lookup.use_lut_dir(lut_dir):
        counts = {}
        for fn in catalog.all_functions():
            counts.update(tree_node_counts(ensure_function_group(fn, lut_dir)))
        assert all(fn.name in bpy.data.node_groups for fn in catalog.all_functions())
        assert max(counts.values()) <= MAX_GROUP_NODES, max(counts.items(), key=lambda kv: kv[1])
        assert all(bpy.data.node_groups[fn.name].description for fn in catalog.all_functions())
        rng = np.random.default_rng(12)
        shape = (SIZE, SIZE)
        vals = {"F0": rng.random(shape + (3,)), "E": rng.uniform(0.0, 1.0, shape), "N.V": rng.random(shape),
                "Roughness": rng.random(shape), "Distance": rng.uniform(0.0, 3.0, shape),
                "Radius": rng.uniform(-0.5, 3.0, shape), "Cos To Axis": rng.uniform(-1, 1, shape),
                "Inner Angle": rng.uniform(0, 3, shape), "Outer Angle": rng.uniform(0, 3, shape),
                "Diameter": rng.uniform(0, 2, shape)}
        vals["E"].reshape(-1)[:3] = [0.0, 1.0, 1e-3]
        for fn in catalog.TECHNIQUES:
            check_function(fn, {k: np.asarray(vals[k], np.float32) for k in fn.input_sockets}, lut_dir)
    # the operator builds the same set, reusing what exists
    bpy.utils.register_class(RTL_OT_add_node_groups)
    try:
        before = len(bpy.data.node_groups)
        assert bpy.ops.rtl.add_node_groups() == {"FINISHED"}
        assert len(bpy.data.node_groups) == before
    finally:
        bpy.utils.unregister_class(RTL_OT_add_node_groups)
