"""The validation suite's metrics: (a) vs (b) with the float32 conditioning, (a) vs (c) with the truth's
noise, and the Cycles error exponents behind 'spp to match'."""
from __future__ import annotations

import math

import numpy as np


# --- metrics ------------------------------------------------------------------------------------

#: A value may differ from (b) by this many times its float32 conditioning.
CONDITIONING_FACTOR = 4.0


def ab_metrics(a, b, mask, near_zero=1e-2, conditioning=None, tol=1e-4, atol=1e-6):
    """(a) vs (b): max relative difference where |b| >= near_zero, max abs difference below.

    With ``conditioning`` (per value: how much float32 rounding of the inputs and of the
    evaluation moves it, see validate.py), values whose difference exceeds ``tol`` x |b| but stays
    within CONDITIONING_FACTOR x conditioning are allowed (e.g. the edge of a spot light's cone,
    where the blend ramp amplifies the rounding of the cosine): ``max_rel_beyond_float32`` is the
    max relative difference over the other values; ``conditioned`` counts the allowed ones."""
    av, bv = a[mask].astype(np.float64), b[mask].astype(np.float64)
    err = np.abs(av - bv)
    big = np.abs(bv) >= near_zero
    out = {"max_rel": float((err[big] / np.abs(bv[big])).max()) if big.any() else 0.0,
           "max_abs_near_zero": float(err[~big].max()) if (~big).any() else 0.0,
           "values": int(av.size), "values_rel": int(big.sum()),
           "finite": bool(np.all(np.isfinite(a[mask])) and np.all(np.isfinite(b[mask])))}
    if conditioning is not None:
        cond = CONDITIONING_FACTOR * conditioning[mask].astype(np.float64)
        rel_fail = big & (err > tol * np.abs(bv))
        allowed = rel_fail & (err <= cond)
        beyond = big & ~allowed
        out["max_rel_beyond_float32"] = float((err[beyond] / np.abs(bv[beyond])).max()) if beyond.any() else 0.0
        abs_fail = ~big & (err > atol)
        abs_allowed = abs_fail & (err <= cond)
        small_beyond = ~big & ~abs_allowed
        out["max_abs_near_zero_beyond_float32"] = float(err[small_beyond].max()) if small_beyond.any() else 0.0
        out["conditioned"] = int(allowed.sum() + abs_allowed.sum())
    return out


#: Cycles' path-tracing error falls as spp^-k in these scenes (spheres seen by camera rays only, direct light),
#: not as 1/sqrt(spp) (k = 0.5): its stratified, scrambled sample sequences integrate the smooth direct-lighting
#: integrand faster.  Measured by validation/benchmarks/speed_error.py (docs/benchmarks/speed_error.md, "Path tracing's
#: error decay": relative RMS error of 1 ... 4096 spp ladders against 4096 spp x 2 references, median per family
#: under quad and disk lights; full run 2026-12-02): diffuse (Lambert) 1.09 (0.91-1.13, 5 spheres), glossy (GGX
#: r <= 0.3) 0.77 (0.74-0.86, 5), rough (GGX and Multiscatter GGX r > 0.3) 0.99 (0.81-1.07, 10).
CYCLES_ERROR_EXPONENTS = {"diffuse": 1.09, "glossy": 0.77, "rough": 0.99}
#: A variant without a family of its own (the suite's other closures) takes the pooled median.
CYCLES_ERROR_EXPONENT = 0.99
#: The same under a studio HDRI (the world validation): 0.66 median (0.62-0.70, forest and sunrise, 8 spheres).
CYCLES_WORLD_ERROR_EXPONENT = 0.66
#: Largest roughness of the "glossy" family (as validation/benchmarks/speed_error.py).
GLOSSY_MAX_ROUGHNESS = 0.3


def cycles_error_exponent(variant):
    """k of Cycles' error ~ spp^-k for a suite variant (``CYCLES_ERROR_EXPONENTS`` by its family)."""
    if variant.technique == "lambert":
        return CYCLES_ERROR_EXPONENTS["diffuse"]
    if variant.technique in ("ggx", "turquin", "fdez_aguera", "dielectric", "metal", "kulla_conty_white") \
            or variant.technique.startswith("mix_"):
        return CYCLES_ERROR_EXPONENTS["glossy" if variant.roughness <= GLOSSY_MAX_ROUGHNESS else "rough"]
    return CYCLES_ERROR_EXPONENT


def truth_metrics(a, c, mask, floor_frac, c_pair=None, samples_total=None, qerr=None,
                  error_exponent=CYCLES_ERROR_EXPONENT):
    """(a) vs (c) over the values (pixels x channels) of ``mask`` where c > floor_frac * max(c).

    ``c_pair``: the two seed images (c is their mean) for the Monte Carlo noise: per value
    sigma_c = |c1 - c2| / 2, an unbiased one-sample estimate of the noise of c (so the
    "noise_*" figures are what the error statistics would be if the node render were exact).
    ``error_exponent``: k of Cycles' error ~ spp^-k, for ``cycles_spp_to_match``.
    """
    av, cv = a[mask].astype(np.float64).ravel(), c[mask].astype(np.float64).ravel()
    ok = np.isfinite(cv)
    if not ok.any():
        return None
    cmax = float(np.max(cv[ok]))
    floor = floor_frac * cmax
    sel = ok & (cv > floor)
    if not sel.any():
        return None
    rel = np.abs(av[sel] - cv[sel]) / cv[sel]
    out = {"values": int(sel.sum()), "floor": floor, "c_max": cmax,
           "mean": float(rel.mean()), "median": float(np.median(rel)), "p90": float(np.percentile(rel, 90)),
           "max": float(rel.max()), "rmse": float(np.sqrt(np.mean((av[sel] - cv[sel]) ** 2))),
           "rms_rel": float(np.sqrt(np.mean(rel ** 2))),
           "bias_rel": float(np.mean((av[sel] - cv[sel]) / cv[sel]))}
    if c_pair is not None:
        c1, c2 = (x[mask].astype(np.float64).ravel()[sel] for x in c_pair)
        sig = np.abs(c1 - c2) / 2.0
        nrel = sig / cv[sel]
        out.update({"noise_mean": float(nrel.mean()), "noise_median": float(np.median(nrel)),
                    "noise_p90": float(np.percentile(nrel, 90)), "noise_rms_rel": float(np.sqrt(np.mean(nrel ** 2))),
                    "noise_rmse": float(np.sqrt(np.mean(sig ** 2)))})
        # Node render's own (systematic) error: the RMS relative error with the noise's share removed.
        own = math.sqrt(max(out["rms_rel"] ** 2 - out["noise_rms_rel"] ** 2, 0.0))
        out["node_rms_rel_excess"] = own
        if samples_total:
            # Cycles noise ~ spp^-k (``error_exponent``, measured: CYCLES_ERROR_EXPONENT): samples for Cycles' own
            # RMS relative noise to equal the node render's error (the two seeds' samples counted as one render's).
            # Below the noise floor of this comparison the figure is a lower bound.
            resolved = own > 0.5 * out["noise_rms_rel"]
            eff = own if resolved else 0.5 * out["noise_rms_rel"]
            out["cycles_spp_to_match"] = (float(samples_total * (out["noise_rms_rel"] / eff) ** (1.0 / error_exponent))
                                          if eff > 0 else None)
            out["cycles_spp_to_match_is_lower_bound"] = not resolved
    if qerr is not None:
        qv = qerr[mask].astype(np.float64).reshape(-1)[sel] / cv[sel]
        out.update({"quadrature_rel_median": float(np.median(qv)), "quadrature_rel_max": float(qv.max())})
    return out
