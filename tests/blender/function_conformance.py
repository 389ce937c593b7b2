"""Render any NodeFunction's group with Cycles and compare every output with the numpy backend."""
from __future__ import annotations

import numpy as np

from conformance import LAST_RENDER_SECONDS, render_group_outputs

RTOL = 1e-4
ATOL = 1e-6
NEAR_ZERO = 1e-2


def compare(got, ref):
    """(max relative error where |ref| >= NEAR_ZERO, max absolute error elsewhere)."""
    got, ref = np.asarray(got, np.float64), np.asarray(ref, np.float64)
    err = np.abs(got - ref)
    big = np.abs(ref) >= NEAR_ZERO
    rel = float((err[big] / np.abs(ref[big])).max()) if big.any() else 0.0
    absolute = float(err[~big].max()) if (~big).any() else 0.0
    return rel, absolute


def check_function(function, values, lut_dir=None, rtol=RTOL, atol=ATOL):
    """Emit ``function`` (a NodeFunction), render each output for ``values`` (input name ->
    (H, W) or (H, W, 3) float32) and compare with its traced graph in numpy (float32).
    Returns {output: (max rel, max abs near zero, seconds)}; asserts finiteness and tolerances."""
    from rt_lookdev.addon.node_emit import ensure_function_group
    from rt_lookdev.core.ir.numpy_backend import evaluate

    fn = function.function
    ng = ensure_function_group(function, lut_dir)
    vals = {k: np.asarray(v, np.float32) for k, v in values.items()}
    refs = evaluate(tuple(fn.outputs.values()), vals)
    report, failures = {}, []
    for (name, expr), ref in zip(fn.outputs.items(), refs):
        if expr.is_const:
            continue
        ref = np.broadcast_to(ref, next(iter(vals.values())).shape[:2] + ref.shape[2:])
        got = render_group_outputs(ng, vals, name)
        assert np.all(np.isfinite(ref)), f"{function.name}.{name}: numpy reference not finite"
        assert np.all(np.isfinite(got)), f"{function.name}.{name}: non-finite pixels"
        rel, absolute = compare(got, ref)
        report[name] = (rel, absolute, LAST_RENDER_SECONDS[0])
        print(f"{function.name}.{name}: max rel {rel:.3g}, max abs near 0 {absolute:.3g}")
        if rel > rtol or absolute > atol:
            failures.append(f"{function.name}.{name}: rel {rel:.3g} abs {absolute:.3g}")
    assert not failures, "\n".join(failures)
    return report


def unit_vectors(rng, shape, special=()):
    v = rng.normal(size=shape + (3,))
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    flat = v.reshape(-1, 3)
    for i, s in enumerate(special):
        flat[i] = s
    return v.astype(np.float32)
