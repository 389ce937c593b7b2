"""Gated comparisons with a truth (each result has "passed"): the validation suite, the world suite, energy, the
rough-diffuse furnace, the lookdev twin, robustness, the demo.  Import the harness, not benchmarks or tools."""
