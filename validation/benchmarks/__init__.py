"""Measurements that write docs/benchmarks/<name>.{md,json}; they may use checks and the harness, not tools."""
