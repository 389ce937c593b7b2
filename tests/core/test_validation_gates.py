"""The validation suite's gates (issue 17, item 6): every technique under every light kind of the full suite has a
ground truth and a gate, set from the measured figures, noise-aware, applied to full runs only."""
from __future__ import annotations

import argparse

from rt_lookdev.validation.checks import suite
from rt_lookdev.validation.checks import suite_cases as cases


def test_every_technique_under_every_light_kind_has_a_gate():
    pairs = set()
    for case in cases.build_cases():
        for variant in case.variants:
            for kind in case.light_kinds:
                pairs.add((variant.technique, kind))
    own = {"lambert", "ggx"}                     # their gates are the suite's DEFAULTS
    missing = sorted(p for p in pairs if p[0] not in own and p not in suite.GATES)
    assert not missing, missing
    assert all(m >= suite.GATE_FLOOR and q >= m for m, q in suite.GATES.values())


def _pooled(median, p90, noise=None):
    g = {"technique": "turquin", "light": "quad", "truth": "cycles", "values": 100, "median": median, "p90": p90}
    if noise is not None:
        g.update({"noise_median": noise, "noise_p90": noise})
    return [g]


def test_a_gate_fails_beyond_its_threshold_unless_within_the_noise():
    gates = {("turquin", "quad"): (0.02, 0.10)}
    assert suite.gate_checks(_pooled(0.019, 0.09), gates)[0]["ok"]
    assert not suite.gate_checks(_pooled(0.021, 0.09), gates)[0]["ok"]
    assert not suite.gate_checks(_pooled(0.01, 0.11), gates)[0]["ok"]
    # an error the reference's noise cannot resolve passes (the quick run's 8x fewer samples)
    assert suite.gate_checks(_pooled(0.05, 0.11, noise=0.04), gates)[0]["ok"]
    assert not suite.gate_checks(_pooled(0.05, 0.11, noise=0.02), gates)[0]["ok"]
    assert suite.gate_checks(_pooled(0.05, 0.11), {}) == []


def test_gates_are_margin_times_the_measurement_and_apply_to_full_runs_only():
    pooled = _pooled(0.0123, 0.0456) + [dict(_pooled(1e-8, 2e-8)[0], technique="cod", truth="brute")]
    gates = suite.measured_gates(pooled)
    assert gates[("turquin", "quad")] == (0.019, 0.069)           # 1.5 x, rounded up to two digits
    assert gates[("cod", "quad")] == (suite.GATE_FLOOR, suite.GATE_FLOOR)
    failing = _pooled(1.0, 1.0)
    args = argparse.Namespace(quick=True, cases=None, lambert_median=0.005, ggx_quad_median=0.02, ggx_quad_p90=0.12,
                              furnace_tol=0.005, ab_tol=1e-4, ab_atol=1e-6)
    assert suite._checks(args, [], failing, None) == []
    args.quick = False
    assert any(not c["ok"] for c in suite._checks(args, [], failing, None))
