"""Node-group backend conformance: every traced technique, emitted as a shader node group and
rendered per pixel by Cycles, equals the numpy backend (float32) on a 64x64 grid of inputs."""
from __future__ import annotations

from collections import Counter

import numpy as np
import pytest

from rt_lookdev.core import diffuse
from rt_lookdev.core.ir import trace
from rt_lookdev.core.ir.expr import topological_order
from rt_lookdev.core.ir.numpy_backend import evaluate, node_count
from rt_lookdev.validation.harness.conformance import ATOL, LAST_RENDER_SECONDS, NEAR_ZERO, RTOL, render_group_outputs
from rt_lookdev.validation.harness.conformance import compare as _compare
from rt_lookdev.validation.harness.grids import TECHNIQUES, ir_operation_inputs
from rt_lookdev.validation.harness.grids import technique_inputs as _inputs

pytest.importorskip("OpenEXR")

pytestmark = pytest.mark.blender

SIZE = 64


def _check(name, got, ref):
    assert got.shape == ref.shape
    assert np.all(np.isfinite(ref)), f"{name}: numpy reference is not finite"
    assert np.all(np.isfinite(got)), f"{name}: {np.count_nonzero(~np.isfinite(got))} NaN/Inf pixels"
    rel, absolute = _compare(got, ref)
    print(f"{name}: max rel {rel:.3g}, max abs near zero {absolute:.3g}, render {LAST_RENDER_SECONDS[0]:.3f} s")
    bad = (np.abs(ref) >= NEAR_ZERO) & (np.abs(got - ref) > RTOL * np.abs(ref)) | \
          (np.abs(ref) < NEAR_ZERO) & (np.abs(got - ref) > ATOL)
    assert rel <= RTOL and absolute <= ATOL, (
        f"{name}: {np.count_nonzero(bad)} pixels off, e.g. at {np.argwhere(bad)[:3].tolist()}: "
        f"cycles {got[bad][:3]} numpy {ref[bad][:3]}")


def _expected_node_count(outputs):
    """One node per operation, one Separate XYZ per vector whose three components are read (one Dot Product per
    component of a vector read in part), group input and output, and a second Mix per select whose false branch is
    not the constant 0 (node_emit: exact in EEVEE)."""
    order = topological_order(list(outputs.values()))
    comps = [n for n in order if n.op in ("x", "y", "z")]
    separated = {src for src, reads in Counter(n.args[0].id for n in comps).items() if reads == 3}
    selects = [n for n in order if n.op in ("select", "vselect")
               and not (n.args[2].is_const and not np.any(n.args[2].attr("value")))]
    return (node_count(tuple(outputs.values())) - 3 * len(separated) + len(separated) + 2 + len(selects))


@pytest.mark.parametrize("name", sorted(TECHNIQUES))
def test_technique_renders_like_numpy(empty_scene, name):
    from rt_lookdev.addon.node_emit import build_node_group

    fn, names = TECHNIQUES[name]
    _, out = trace(fn, dict.fromkeys(names, "float"))
    outputs = {"out": out}
    ng = build_node_group(f"RTL_{name}", outputs)
    assert len(ng.nodes) == _expected_node_count(outputs)
    vals = {k: v.astype(np.float32).reshape(SIZE, SIZE) for k, v in _inputs(names, n=SIZE * SIZE).items()}
    got = render_group_outputs(ng, vals, "out")
    ref = evaluate(out, vals)
    print(f"{name}: {len(ng.nodes)} nodes")
    _check(name, got, ref)


def test_wrapped_normal_vectors_render_like_numpy(empty_scene):
    from rt_lookdev.addon.node_emit import build_node_group

    _, out = trace(diffuse.wrapped_normal, {"n": "vector", "l": "vector", "wrap": "float"})
    outputs = {"normal": out}
    ng = build_node_group("RTL_wrapped_normal", outputs)
    assert len(ng.nodes) == _expected_node_count(outputs)
    count = SIZE * SIZE
    rng = np.random.default_rng(4)
    n = rng.normal(size=(count, 3))
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    n[: count // 2] = [0.0, 0.0, 1.0]
    l = rng.normal(size=(count, 3))
    l /= np.linalg.norm(l, axis=-1, keepdims=True)
    l[0] = [0.0, 0.0, -1.0]
    w = rng.random(count)
    w[:3] = [1.0, 0.0, 0.5]
    vals = {"n": n.reshape(SIZE, SIZE, 3).astype(np.float32), "l": l.reshape(SIZE, SIZE, 3).astype(np.float32),
            "wrap": w.reshape(SIZE, SIZE).astype(np.float32)}
    got = render_group_outputs(ng, vals, "normal")
    ref = evaluate(out, vals)
    print(f"wrapped_normal: {len(ng.nodes)} nodes")
    _check("wrapped_normal", got, ref)


def test_group_is_deterministic_and_one_node_per_operation(empty_scene):
    from rt_lookdev.addon.node_emit import build_node_group, node_group_stats

    for name in ("ggx_brdf", "cone_falloff"):
        fn, names = TECHNIQUES[name]
        _, out = trace(fn, dict.fromkeys(names, "float"))
        a = build_node_group(f"RTL_a_{name}", {"out": out})
        b = build_node_group(f"RTL_b_{name}", {"out": out})
        assert node_group_stats(a) == node_group_stats(b)
        assert len(a.nodes) == len(b.nodes) == _expected_node_count({"out": out})
        assert [s.name for s in a.interface.items_tree] == [s.name for s in b.interface.items_tree]
        math = [n for n in a.nodes if n.bl_idname == "ShaderNodeMath"]
        assert math and not any(n.use_clamp for n in math)
        assert all(n.label for n in a.nodes)
    _, vec = trace(diffuse.wrapped_normal, {"n": "vector", "l": "vector", "wrap": "float"})
    g = build_node_group("RTL_wn", {"normal": vec})
    assert len(g.nodes) == _expected_node_count({"normal": vec})
    assert not any(n.bl_idname == "ShaderNodeValue" for n in g.nodes)


def test_every_ir_operation_renders_like_numpy(empty_scene):
    """One output per IR operation (every entry of OPS), out-of-domain arguments included."""
    from rt_lookdev.addon.node_emit import build_node_group
    from rt_lookdev.validation.harness.grids import ir_operation_graph

    outputs = ir_operation_graph()
    ng = build_node_group("RTL_all_ops", outputs, input_order=["a", "b", "u", "v"])
    assert len(ng.nodes) == _expected_node_count(outputs)
    vals = ir_operation_inputs(SIZE)
    failures = []
    for name, expr in outputs.items():
        got = render_group_outputs(ng, vals, name)
        ref = evaluate(expr, vals)
        try:
            _check(name, got, ref)
        except AssertionError as exc:
            failures.append(str(exc))
    assert not failures, "\n".join(failures)


def test_power_of_zero_with_negative_exponent(empty_scene):
    """Cycles' Power gives 0 for a zero base (+0 or -0) with a negative exponent (plain numpy: +-inf)
    from Blender 5.0, and the numpy backend reproduces it; before 5.0 Cycles gives +inf (clamped to 1e6
    here).  The shading code never feeds Power a base that can be zero (tests/core/test_ir.py), so the
    difference reaches no pixel (addon/compat.py)."""
    from rt_lookdev.addon import compat
    from rt_lookdev.addon.node_emit import build_node_group
    from rt_lookdev.core.ir import Graph

    g = Graph()
    a, b = g.input("a"), g.input("b")
    # clamp to 1e6 so that an infinite result survives the film (Cycles writes non-finite samples as 0)
    out = g.make("minimum", (g.make("power", (a, b)), g.const(1e6)))
    ng = build_node_group("RTL_pow0", {"out": out})
    vals = {"a": np.array([[0.0, 0.0, -0.0, 0.0]] * 4, np.float32),
            "b": np.array([[-0.5, -1.0, -1.0, -2.0]] * 4, np.float32)}
    got = render_group_outputs(ng, vals, "out")
    ref = evaluate(out, vals)
    assert np.all(ref == 0.0)
    if compat.power_of_zero_is_zero():
        np.testing.assert_array_equal(got, ref)
    else:
        # +0 ** negative = +inf (clamped to 1e6); -0 ** odd negative = -inf, written as 0 by the film
        np.testing.assert_array_equal(got, np.where(np.signbit(vals["a"]), 0.0, 1e6))


def test_lut_lookup_matches(empty_scene, tables):
    """Table lookups in nodes, every channel, coordinates inside and outside the texel-centre range:
    the raw Image Texture ops ("lut": Linear; "texel": Closest) and the bilinear node function that
    shading code uses (four Closest fetches), all against core.ir.semantics.sample_bilinear."""
    from rt_lookdev.addon.node_emit import build_node_group, node_group_stats, tree_node_counts
    from rt_lookdev.core import shading_ops as op
    from rt_lookdev.core.ir import trace
    from rt_lookdev.core.ir.semantics import sample_bilinear

    lut = tables["ltc_ggx_inv"]
    table = lut.require_data()

    def lookups(u, v):
        g = u.graph
        raw = tuple(g.read_table(lut, u, v, c, op=kind) for kind in ("lut", "texel") for c in range(4))
        return raw + tuple(op.lut_sample(lut, u, v, c) for c in range(4))

    _, outs = trace(lookups, {"u": "float", "v": "float"})
    names = [f"{kind}{c}" for kind in ("linear", "closest", "bilinear") for c in range(4)]
    ng = build_node_group("RTL_lut", dict(zip(names, outs)), input_order=["u", "v"], tables=tables)
    assert node_group_stats(ng)["ShaderNodeTexImage"] == 2       # one Linear, one Closest texture
    inner = [n.node_tree for n in ng.nodes if n.bl_idname == "ShaderNodeGroup"]
    assert len(inner) == 1 and inner[0].name == "RTL LUT ltc_ggx_inv"
    assert node_group_stats(inner[0])["ShaderNodeTexImage"] == 4
    assert all(n.interpolation == "Closest" for n in inner[0].nodes if n.bl_idname == "ShaderNodeTexImage")
    assert max(tree_node_counts(ng).values()) <= 150
    assert len([i for i in bpy_images() if i.name.startswith("RTL_")]) == 1
    rng = np.random.default_rng(11)
    vals = {n: rng.uniform(-0.05, 1.05, (64, 64)).astype(np.float32) for n in ("u", "v")}
    vals["u"][0, :4] = [0.5 / 64, 63.5 / 64, 0.0, 1.0]            # texel centres and the edges
    exact = sample_bilinear(table, vals["u"], vals["v"])
    for name, o in zip(names, outs):
        got = render_group_outputs(ng, vals, name)
        _check(f"lut {name}", got, evaluate(o, vals, tables=tables))
        if name.startswith("bilinear"):
            np.testing.assert_allclose(got, exact[..., int(name[-1])], rtol=2e-6, atol=2e-6)


def test_lut_driven_kulla_conty_lobe_matches(empty_scene, tables):
    """A technique that reads tables: the Kulla-Conty lobe from the energy LUTs, in nodes."""
    from rt_lookdev.addon.node_emit import build_node_group
    from rt_lookdev.core import multiscatter
    from rt_lookdev.core import shading_ops as op
    from rt_lookdev.core.ir import trace
    from rt_lookdev.core.lut import catalog
    from rt_lookdev.core.lut.lookup import lut_coordinate

    luts = tables

    def lobe(mu_o, mu_i, r, f0):
        u = lut_coordinate(r, catalog.ENERGY_SIZE)
        one_minus_e_o = op.lut_sample(luts["ggx_one_minus_E"], u, lut_coordinate(mu_o, catalog.ENERGY_SIZE), 0)
        one_minus_e_i = op.lut_sample(luts["ggx_one_minus_E"], u, lut_coordinate(mu_i, catalog.ENERGY_SIZE), 0)
        one_minus_e_avg = op.lut_sample(luts["ggx_one_minus_E_avg"], u, 0.5, 0)
        return multiscatter.kulla_conty_brdf(one_minus_e_o, one_minus_e_i, one_minus_e_avg, f0)

    names = ["mu_o", "mu_i", "r", "f0"]
    _, out = trace(lobe, dict.fromkeys(names, "float"))
    ng = build_node_group("RTL_kc_lut", {"out": out}, input_order=names, tables=tables)
    lut_calls = [n.node_tree.name for n in ng.nodes if n.bl_idname == "ShaderNodeGroup"]
    assert sorted(lut_calls) == ["RTL LUT ggx_one_minus_E"] * 2 + ["RTL LUT ggx_one_minus_E_avg"]
    rng = np.random.default_rng(11)
    vals = {n: rng.random((64, 64)).astype(np.float32) for n in names}
    vals["r"][0, :6] = [0.0, 1.0, 1 / 63, 0.5, 1e-4, 1 - 1e-4]
    got = render_group_outputs(ng, vals, "out")
    direct = lobe(**{k: v.astype(np.float64) for k, v in vals.items()})   # numpy, no IR
    assert np.allclose(evaluate(out, vals, dtype=np.float64, tables=tables), direct, rtol=1e-6, atol=1e-12)
    _check("kulla_conty_lut", got, evaluate(out, vals, tables=tables))
    # with 1 - E_avg stored, float32 (Cycles) also agrees with float64 numpy
    assert np.allclose(got, direct, rtol=1e-4, atol=1e-7)


def bpy_images():
    import bpy

    return list(bpy.data.images)


def test_renders_are_independent_of_the_current_scene(empty_scene):
    """render_group_outputs renders a scene of its own: a plane in front of everything, another camera and
    world and a 50% resolution in the current scene change no pixel, and that scene is left as it was (the
    main job's robustness step ran after the world validation's scene and read its spheres)."""
    import bpy

    from rt_lookdev.core import shading_ops as op
    from rt_lookdev.core.ir import trace
    from rt_lookdev.addon.node_emit import build_node_group

    _, out = trace(lambda a, b: op.sqrt(a * a + b), {"a": "float", "b": "float"})
    ng = build_node_group("RTL_scene_independent", {"out": out}, input_order=["a", "b"])
    rng = np.random.default_rng(3)
    vals = {n: rng.uniform(0.0, 2.0, (8, 8)).astype(np.float32) for n in ("a", "b")}
    clean = render_group_outputs(ng, vals, "out")
    scene = empty_scene
    mesh = bpy.data.meshes.new("blocker")
    mesh.from_pydata([(-50, -50, 0.5), (50, -50, 0.5), (50, 50, 0.5), (-50, 50, 0.5)], [], [(0, 1, 2, 3)])
    blocker = bpy.data.objects.new("blocker", mesh)
    scene.collection.objects.link(blocker)
    scene.render.resolution_percentage = 50
    before = (sorted(o.name for o in scene.objects), scene.camera, scene.world, len(bpy.data.scenes))
    cluttered = render_group_outputs(ng, vals, "out")
    assert np.array_equal(clean, cluttered)
    assert (sorted(o.name for o in scene.objects), scene.camera, scene.world, len(bpy.data.scenes)) == before
    assert scene.render.resolution_percentage == 50
