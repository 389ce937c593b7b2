"""The speed-vs-error benchmark's arithmetic (validation/benchmarks/speed_error.py) on made-up ladders: the equal-error
interpolation and its bounds, the noise correction, the decay exponent, the families, the summary table."""
import math

import pytest

from rt_lookdev.validation.benchmarks import speed_error_metrics
from rt_lookdev.validation.benchmarks import speed_error_report
from rt_lookdev.validation.benchmarks import speed_error_scenes


def _ladder(k=1.0, e1=0.5, top=256, fixed=0.1, per_sample=0.01, noise=0.0):
    """Rungs whose error falls as spp^-k exactly, timed fixed + per_sample x spp."""
    rungs = []
    for spp in speed_error_metrics.ladder_spps(top):
        err = e1 * spp ** -k
        rungs.append({"spp": spp, "seconds": fixed + per_sample * spp,
                      "errors": [{"rel_rms": err, "flip": err / 10, "resolved": err > 0.5 * noise}]})
    return rungs


def test_equal_error_interpolates_log_log_between_rungs():
    rungs = _ladder(k=1.0)
    eq = speed_error_metrics.equal_error(rungs, 0, "rel_rms", 0.5 / 24.0, 0.01)       # between 16 and 32 spp
    assert eq["bound"] is None and eq["spp"] == pytest.approx(24.0, rel=1e-9)
    assert eq["render_s"] == pytest.approx(0.24)
    assert 0.1 + 0.16 < eq["total_s"] < 0.1 + 0.32


def test_equal_error_bounds():
    rungs = _ladder(k=1.0, top=64)
    upper = speed_error_metrics.equal_error(rungs, 0, "rel_rms", 0.9, 0.01)           # worse than 1 spp
    lower = speed_error_metrics.equal_error(rungs, 0, "rel_rms", 1e-4, 0.01)          # better than the top rung
    assert upper["bound"] == "upper" and upper["spp"] == 1
    assert lower["bound"] == "lower" and lower["spp"] == 64
    assert speed_error_metrics.equal_error(rungs, 0, "rel_rms", float("nan"), 0.01) is None


def test_equal_error_uses_the_running_minimum():
    rungs = _ladder(k=1.0, top=8)
    rungs[2]["errors"][0]["rel_rms"] = 1.0          # a noisy rung worse than the one before it
    eq = speed_error_metrics.equal_error(rungs, 0, "rel_rms", 0.2, 0.01)
    assert eq["bound"] is None and 2.0 < eq["spp"] < 8.0


def test_speedups_total_and_render_only():
    rungs = _ladder(k=1.0)
    s = speed_error_metrics.speedups(rungs, 0, "rel_rms", 0.5 / 32.0, {"total_s": 0.05, "render_s": 0.001}, 0.01)
    assert s["pt_spp"] == pytest.approx(32.0)
    assert s["total"] == pytest.approx((0.1 + 0.32) / 0.05, rel=1e-6)
    assert s["render"] == pytest.approx(0.32 / 0.001, rel=1e-6)
    assert math.isnan(speed_error_metrics.speedups(rungs, 0, "rel_rms", 0.01, {"total_s": 1.0, "render_s": 0.0}, 0.01)["render"])


def test_noise_correction_in_quadrature():
    assert speed_error_metrics.corrected_rms(0.05, 0.03) == (pytest.approx(0.04), True)
    assert speed_error_metrics.corrected_rms(0.01, 0.03) == (pytest.approx(0.015), False)       # below the noise: half of it


@pytest.mark.parametrize("k", [0.5, 1.0, 1.5])
def test_decay_exponent_recovers_the_slope(k):
    fit = speed_error_metrics.decay_exponent(_ladder(k=k, top=1024), 0)
    assert fit["k"] == pytest.approx(k, rel=1e-9) and fit["points"] == 11


def test_families():
    assert speed_error_scenes.family("suite", "lambert", 0.5, ("quad",)) == "diffuse"
    assert speed_error_scenes.family("suite", "ggx", 0.25, ("disk",)) == "glossy"
    assert speed_error_scenes.family("suite", "turquin", 0.6, ("quad",)) == "rough"
    assert speed_error_scenes.family("suite", "ggx", 0.7, ("point",)) == "punctual"
    assert speed_error_scenes.family("world", "ggx", 0.1) == "world"


def test_summary_table_marks_bounds():
    rungs = _ladder(k=1.0, top=64)
    variants = []
    for err in (0.9, 0.5 / 8, 1e-4):
        backend = {"total_s": 0.05, "render_s": 0.001}
        sp = {m: speed_error_metrics.speedups(rungs, 0, m, err if m == "rel_rms" else err / 10, backend, 0.01) for m in speed_error_scenes.METRICS}
        variants.append({"family": "diffuse", "reference": {"noise_rel_rms": 1e-4},
                         "exponent": speed_error_metrics.decay_exponent(rungs, 0),
                         "backends": {"cycles": {"rel_rms": err, "flip": err / 10, "speedup": sp}}})
    rows = speed_error_report.family_summary([{"variants": variants}])
    assert len(rows) == 1 and rows[0]["rel_rms_speedup"]["total"]["lower"] == 1
    text = speed_error_report.summary_table(rows)
    assert "1 of 3 >=" in text and "1 of 3 <=" in text
