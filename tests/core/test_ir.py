"""The expression IR: sharing, folding, Blender semantics, and one source for every technique."""
import numpy as np
import pytest

from rt_lookdev.core import cloth, diffuse
from rt_lookdev.core import shading_ops as op
from rt_lookdev.core.ir import Graph, trace
from rt_lookdev.core.ir.numpy_backend import evaluate, node_count
from rt_lookdev.validation.harness.grids import TECHNIQUES
from rt_lookdev.validation.harness.grids import technique_inputs as _inputs


def test_common_subexpressions_are_shared():
    g = Graph()
    x, y = g.input("x"), g.input("y")
    a = (x * y + 1.0) * (x * y + 1.0)
    assert (x * y) is (x * y)
    assert node_count(a) == 3          # multiply, add, multiply


def test_constant_folding_and_identities():
    g = Graph()
    x = g.input("x")
    assert (g.const(2.0) + 3.0).is_const and (g.const(2.0) + 3.0).attr("value") == 5.0
    assert (x * 1.0) is x and (x + 0.0) is x and (x / 1.0) is x
    zero = x * 0.0
    assert zero.is_const and zero.attr("value") == 0.0
    assert op.select(g.const(1.0), x, x * x) is x and op.select(g.const(0.0), x, x * x) is (x * x)
    assert op.sqrt(g.const(-4.0)).attr("value") == 0.0        # folded with Blender semantics


def test_dead_branch_removal_drops_a_disabled_lobe():
    def material(mu_l, mu_v, n_dot_h, l_dot_h, alpha, sheen):
        base = diffuse.cod_multiscatter_diffuse(0.8, mu_l, mu_v, n_dot_h, l_dot_h, alpha)
        return base + sheen * cloth.disney_sheen(l_dot_h)

    names = dict.fromkeys(["mu_l", "mu_v", "n_dot_h", "l_dot_h", "alpha"], "float")
    _, with_sheen = trace(material, dict(names, sheen="float"))
    g = Graph()
    no_sheen = material(**{n: g.input(n) for n in names}, sheen=0.0)
    assert node_count(no_sheen) < node_count(with_sheen)
    assert node_count(no_sheen) == node_count(trace(
        lambda **k: diffuse.cod_multiscatter_diffuse(0.8, **dict(zip(["mu_l", "mu_v", "n_dot_h", "l_dot_h", "alpha"],
                                                                          k.values()))), names)[1])


def test_type_errors_and_no_truth_value():
    g = Graph()
    x, v = g.input("x"), g.input("v", "vector")
    with pytest.raises(TypeError):
        g.make("sqrt", (v,))
    with pytest.raises(TypeError):
        bool(x > 0.0)
    with pytest.raises(ValueError):
        x + Graph().input("y")


def test_numpy_backend_has_blender_semantics():
    g = Graph()
    a, b = g.input("a"), g.input("b")
    vals = {"a": np.array([1.0, -1.0, 0.0, 2.0, -2.0]), "b": np.array([0.0, 2.0, 0.0, 0.5, 0.5])}
    out = evaluate((a / b, op.sqrt(a), g.make("inverse_sqrt", (a,)), g.make("arccosine", (a,)),
                    op.log2(a), g.make("power", (a, b))), vals)
    div, sq, isq, acos, lg, pw = out
    assert list(div) == [0.0, -0.5, 0.0, 4.0, -4.0]             # x / 0 = 0
    assert list(sq[[1, 4]]) == [0.0, 0.0]                         # sqrt of a negative = 0
    assert isq[2] == 0.0 and isq[1] == 0.0                        # inverse sqrt of <= 0 = 0
    assert acos[3] == 0.0 and acos[4] == pytest.approx(np.pi)     # arccos input clamped
    assert lg[1] == 0.0 and lg[2] == 0.0                          # log of <= 0 = 0
    assert pw[4] == 0.0 and pw[3] == pytest.approx(np.sqrt(2))    # negative base, fractional exp
    v = g.input("v", "vector")
    n = evaluate(op.normalize(v), {"v": np.array([[0.0, 0.0, 0.0], [3.0, 0.0, 4.0]])})
    assert np.array_equal(n[0], [0, 0, 0]) and np.allclose(n[1], [0.6, 0, 0.8])
    assert evaluate(a, vals).dtype == np.float32                  # Cycles computes in float32


@pytest.mark.parametrize("name", sorted(TECHNIQUES))
def test_one_source_numpy_and_ir_agree(name):
    fn, names = TECHNIQUES[name]
    _, out = trace(fn, dict.fromkeys(names, "float"))
    vals = _inputs(names)
    direct = np.asarray(fn(**vals), dtype=np.float64)
    via_ir64 = evaluate(out, vals, dtype=np.float64)
    # constants are stored as float32 (as Blender's sockets store them): agreement to ~1e-7
    assert np.allclose(via_ir64, direct, rtol=1e-6, atol=1e-12)
    via_ir32 = evaluate(out, vals)                              # what Cycles computes
    assert np.all(np.isfinite(via_ir32))
    assert np.allclose(via_ir32, direct, rtol=1e-4, atol=1e-6 * max(1.0, np.abs(direct).max() * 1e-3))


def test_wrapped_normal_traces_to_the_same_vectors():
    _, out = trace(diffuse.wrapped_normal, {"n": "vector", "l": "vector", "wrap": "float"})
    rng = np.random.default_rng(4)
    n = np.tile([0.0, 0.0, 1.0], (500, 1))
    l = rng.normal(size=(500, 3))
    l /= np.linalg.norm(l, axis=-1, keepdims=True)
    l[0] = [0.0, 0.0, -1.0]
    w = rng.random(500)
    w[0] = 1.0
    direct = diffuse.wrapped_normal(n, l, w)
    assert np.allclose(evaluate(out, {"n": n, "l": l, "wrap": w}, dtype=np.float64), direct, atol=1e-12)


def test_node_counts_are_reported():
    counts = {name: node_count(trace(fn, dict.fromkeys(names, "float"))[1]) for name, (fn, names) in TECHNIQUES.items()}
    assert all(c > 0 for c in counts.values())
    assert counts["disney_sheen"] <= 6 and counts["ggx_brdf"] < 60


def test_power_nodes_have_positive_constant_bases():
    """Every Power node of every traced function has a positive constant base: Power(0, negative)
    differs between Blender releases (addon/compat.py), and no shading code can reach it."""
    from rt_lookdev.core.ir.expr import topological_order
    from rt_lookdev.core.materials import rt_lit
    from rt_lookdev.core.materials.rt_lit_interface import LIGHT_KINDS, Features
    from rt_lookdev.node_groups import library

    roots = [fn.function for fn in library.all_functions()]
    roots += [rt_lit.build_rt_lit(Features(s, d, sheen=True, cloth=True), LIGHT_KINDS).function
              for s in ("single", "turquin", "fdez_aguera", "kulla_conty") for d in ("lambert", "cod", "wrapped")]
    seen, powers = set(), []
    stack = list(roots)
    while stack:
        fn = stack.pop()
        if fn.key in seen:
            continue
        seen.add(fn.key)
        for node in topological_order(list(fn.outputs.values())):
            if node.op == "power":
                powers.append((fn.name, node.args[0]))
            elif node.op == "call":
                stack.append(node.graph.functions[node.attr("function")])
    assert powers, "no Power node found: the walk is broken"
    bad = [name for name, base in powers if not (base.is_const and base.attr("value") > 0.0)]
    assert not bad, bad


def test_lights_in_blocks_compute_exactly_what_the_flat_sum_computes(monkeypatch, tables):
    """A material of more lights than ``rt_lit.LIGHT_BLOCK`` shades them in nested "RTL Lights" functions (small node
    trees, fast to build); its every output is bit for bit the flat material's, in float32."""
    from rt_lookdev.core.ir.expr import folding_enabled, table_filter_mode, topological_order
    from rt_lookdev.core.materials import rt_lit
    from rt_lookdev.core.materials.rt_lit_interface import LIGHT_KINDS, Features

    features = Features("turquin", "cod", sheen=True)
    kinds = LIGHT_KINDS + ("quad+range", "point+range", "disk+cone", "sphere+range")
    blocked = rt_lit.build_rt_lit(features, kinds)
    monkeypatch.setattr(rt_lit, "LIGHT_BLOCK", len(kinds))
    flat = rt_lit._build.__wrapped__(features, kinds, None, folding_enabled(), table_filter_mode())

    def called(material):
        return {node.graph.functions[node.attr("function")].name for node in
                topological_order(list(material.function.outputs.values())) if node.op == "call"}
    assert sum(name.startswith("RTL Lights") for name in called(blocked)) == 2      # 8 lights, then 5
    assert not any(name.startswith("RTL Lights") for name in called(flat))
    rng = np.random.default_rng(7)
    values = {name: rng.uniform(0.05, 1.0, (256, 3) if kind == "vector" else (256,)).astype(np.float32)
              for name, kind in blocked.function.inputs}
    outputs = blocked.part_outputs + ("Radiance",)
    a = blocked.evaluate(values, tables, outputs=outputs)
    b = flat.evaluate(values, tables, outputs=outputs)
    for name in outputs:
        assert a[name].dtype == np.float32 and np.isfinite(a[name]).all()
        np.testing.assert_array_equal(a[name], b[name], err_msg=name)
    assert np.abs(a["Radiance"]).max() > 0.1
