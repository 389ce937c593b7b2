"""Specular occlusion from ambient occlusion (core/occlusion.py): the reference integral's limits, every estimate
bounded, finite and float32 at the edges, the traced form equal to the direct one, and the benchmark's report."""
from __future__ import annotations

import numpy as np
import pytest

from rt_lookdev.core import occlusion
from rt_lookdev.core.ir import trace
from rt_lookdev.core.ir.numpy_backend import evaluate

ESTIMATES = {
    "lagarde": lambda mu, ao, r: occlusion.specular_occlusion_lagarde(mu, ao, r),
    "cones": lambda mu, ao, r: occlusion.specular_occlusion_cones(mu, ao, r),
    "cones_clipped": lambda mu, ao, r: occlusion.specular_occlusion_cones_clipped(mu, ao, r),
}


@pytest.mark.parametrize("roughness", [0.05, 0.4, 1.0])
@pytest.mark.parametrize("mu", [0.05, 0.5, 1.0])
def test_reference_sees_everything_at_ao_1_nothing_at_0_and_more_as_ao_grows(mu, roughness):
    shares = [occlusion.specular_occlusion_reference(mu, roughness, ao, 1 << 12) for ao in (0.0, 0.3, 0.6, 0.9, 1.0)]
    assert shares[-1] == pytest.approx(1.0, abs=1e-12)
    assert shares[0] <= 1e-3
    assert all(a <= b + 1e-12 for a, b in zip(shares, shares[1:]))


def test_estimates_are_bounded_finite_and_float32_at_the_edges():
    edges = np.array([0.0, 1e-7, 0.5, 1.0 - 1e-7, 1.0], dtype=np.float32)
    mu, ao, r = np.meshgrid(edges, edges, edges, indexing="ij")
    for name, fn in ESTIMATES.items():
        so = np.asarray(fn(mu, ao, r))
        assert so.dtype == np.float32, name
        assert np.isfinite(so).all() and (so >= 0.0).all() and (so <= 1.0).all(), name


def test_float32_equals_float64_down_to_mirror_like_lobes():
    """The cones' solid angles are computed without 1 - cos: as 1 - 10^(-alpha^2) the lobe of r < 0.015 had no solid
    angle in float32 and a mirror-like surface with its reflection in plain view came out fully occluded (SO = 0)."""
    r = np.array([0.0, 1e-3, 0.003, 0.01, 0.015, 0.03, 0.1, 0.5, 1.0])
    mu, ao = np.meshgrid(np.linspace(0.0, 1.0, 11), np.linspace(0.0, 1.0, 11), indexing="ij")
    for name, fn in ESTIMATES.items():
        for rr in r:
            so64 = np.asarray(fn(mu, ao, np.full_like(mu, rr)))
            so32 = np.asarray(fn(mu.astype(np.float32), ao.astype(np.float32), np.full(mu.shape, rr, np.float32)))
            assert so32.dtype == np.float32
            np.testing.assert_allclose(so32, so64, atol=2e-4, err_msg=f"{name} r={rr}")
    # a mirror at normal view under a half-open sky sees its reflection: nothing occluded
    assert float(ESTIMATES["cones_clipped"](np.float32(1.0), np.float32(0.5), np.float32(0.0))) == 1.0


def test_no_occlusion_at_ao_1_for_lagarde_and_the_clipped_cones_and_the_plain_cones_darken_grazing_rough_lobes():
    mu = np.linspace(0.02, 1.0, 20)
    for name in ("lagarde", "cones_clipped"):
        for r in (0.1, 0.5, 1.0):
            np.testing.assert_allclose(ESTIMATES[name](mu, 1.0, r), 1.0, atol=1e-6, err_msg=name)
    # the plain ratio counts the part of the lobe cone below the horizon as occluded (why the clipped form exists)
    assert float(ESTIMATES["cones"](0.1, 1.0, 1.0)) < 0.7


@pytest.mark.parametrize("name", sorted(ESTIMATES))
def test_traced_estimate_computes_what_the_direct_one_computes(name):
    graph, out = trace(lambda mu, ao, r: {"so": ESTIMATES[name](mu, ao, r)}, {"mu": "float", "ao": "float", "r": "float"})
    rng = np.random.default_rng(3)
    values = {k: rng.uniform(0.0, 1.0, 500).astype(np.float32) for k in ("mu", "ao", "r")}
    traced = evaluate(out["so"], values, np.float32)
    direct = ESTIMATES[name](values["mu"], values["ao"], values["r"])
    np.testing.assert_allclose(traced, direct, rtol=0, atol=2e-6)


def test_benchmark_writes_its_report(tmp_path):
    from rt_lookdev.validation.benchmarks import specular_occlusion_benchmark as bench

    result = bench.run(bench.parse_args(["--quick", "--samples", "1024", "--out", str(tmp_path)]), lambda line: None)
    text = (tmp_path / "specular_occlusion.md").read_text()
    assert (tmp_path / "specular_occlusion.json").is_file() and text.startswith("# Specular occlusion")
    assert result["points"] == 18 and result["best"] in result["summary"]
    assert all(f"| {name} |" in text for name in bench.ESTIMATES)
