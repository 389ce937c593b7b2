"""The speed-vs-error benchmark's metrics: relative RMS and FLIP against the reference, the path-tracing
ladder, its cost model, the equal-error samples and speed-ups."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .speed_error_backends import median, render
from .speed_error_scenes import CHEAP_SECONDS, FLOOR, LADDER_SEED, TIMING_REPEATS
from ..checks import world_cases as vw
from ..checks.suite_metrics import truth_metrics


# --- metrics -----------------------------------------------------------------------------------------

LUMINANCE = np.array([0.2126, 0.7152, 0.0722])
EXPOSURE_PERCENTILE = 99.0


def flip_exposure(reference, composite):
    """The case's fixed exposure: the ``EXPOSURE_PERCENTILE``th percentile of the reference's luminance over the
    spheres' pixels maps to 1."""
    y = (np.nan_to_num(reference) @ LUMINANCE)[composite]
    level = float(np.percentile(y, EXPOSURE_PERCENTILE)) if y.size else 1.0
    return 1.0 / level if level > 0 else 1.0


def display(rgb, exposure):
    """Linear radiance to the display: x exposure, ACES filmic (Narkowicz's fit, the curve HDR-FLIP uses),
    clipped to [0, 1], sRGB encoded; negative values clamp to 0."""
    x = np.clip(np.nan_to_num(np.asarray(rgb, np.float64)) * exposure, 0.0, None)
    y = np.clip(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0)
    return np.where(y <= 0.0031308, 12.92 * y, 1.055 * y ** (1 / 2.4) - 0.055).astype(np.float32)


def flip_map(reference, test, composite, exposure):
    """The LDR FLIP error map (``flip_evaluator``, default 67 pixels per degree) of ``test`` against
    ``reference``, both through ``display`` with the case's ``exposure``; ``test`` is taken only where
    ``composite`` (the spheres' pixels) and is the reference elsewhere.

    Not HDR-FLIP: its exposure range runs from the brightest value to the median, and these frames are mostly
    black (background, the spheres' unlit halves), so it spans 10-18 stops and measures little but values far
    below the relative metric's floor (tried: RT Lit's GGX spheres then scored worse than 1-spp path tracing
    on the strength of their near-black tails)."""
    import flip_evaluator as flip

    tst = np.where(composite[..., None], test, reference)
    err, _, _ = flip.evaluate(display(reference, exposure), display(tst, exposure), "LDR", applyMagma=False)
    return np.asarray(err, np.float64).reshape(np.shape(reference)[:2])


def corrected_rms(rms_rel, noise_rms_rel):
    """The relative RMS error with the reference's noise removed in quadrature (the test's error and the
    reference's are independent: E(x - c)^2 = E(x - truth)^2 + var(c), var(c) estimated by ((c1 - c2) / 2)^2);
    below half the noise it is not resolved and reported as half the noise.  Returns (error, resolved)."""
    own = math.sqrt(max(rms_rel ** 2 - noise_rms_rel ** 2, 0.0))
    floor = 0.5 * noise_rms_rel
    return (own, True) if own > floor else (floor, False)


@dataclass
class Reference:
    image: np.ndarray
    pair: list
    masks: list
    floors: list
    composite: np.ndarray
    noise: list                  # per sphere: noise_rms_rel
    flip_noise: list             # per sphere: mean FLIP between the two seeds
    exposure: float = 1.0        # FLIP's fixed exposure (flip_exposure)


def errors(test, ref):
    """Per sphere: {"rel_rms" (noise-corrected), "rel_rms_raw", "resolved", "rel_median", "flip"} of ``test``."""
    fmap = flip_map(ref.image, test, ref.composite, ref.exposure)
    out = []
    for mask, floor, noise in zip(ref.masks, ref.floors, ref.noise):
        m = truth_metrics(test, ref.image, mask, floor)
        raw = m["rms_rel"] if m else float("nan")
        err, resolved = corrected_rms(raw, noise) if m else (float("nan"), False)
        out.append({"rel_rms": err, "rel_rms_raw": raw, "resolved": resolved,
                    "rel_median": m["median"] if m else float("nan"),
                    "flip": float(fmap[mask].mean()) if mask.any() else float("nan")})
    return out


def make_reference(prep, renders, masks, composite):
    """The mean of the two seeds, the floors (FLOOR x the sphere's max; under a world FLOOR x its median,
    ``world_cases.max_fraction``) and the reference's own noise per sphere."""
    pair = [r["rgb"] for r in renders]
    c = 0.5 * (pair[0] + pair[1])
    floors = [vw.max_fraction(c, m, FLOOR) if prep.floor_mode == "median" else FLOOR for m in masks]
    noise = []
    for m, f in zip(masks, floors):
        tm = truth_metrics(c, c, m, f, pair)
        noise.append(tm["noise_rms_rel"] if tm else float("nan"))
    exposure = flip_exposure(c, composite)
    fmap = flip_map(pair[0], pair[1], composite, exposure)
    flip_noise = [float(fmap[m].mean()) if m.any() else float("nan") for m in masks]
    return Reference(c, pair, masks, floors, composite, noise, flip_noise, exposure)


# --- the path-tracing ladder and equal error -----------------------------------------------------------

def ladder_spps(top):
    out, s = [], 1
    while s <= top:
        out.append(s)
        s *= 2
    return out


def run_ladder(prep, top, ref, folder, threads, log):
    """Path tracing at 1, 2, 4, ... ``top`` spp (seed ``LADDER_SEED``): per rung the time (the median of
    ``TIMING_REPEATS`` renders when one takes less than ``CHEAP_SECONDS``, else one render) and the errors per
    sphere."""
    prep.use_pt()
    rungs = []
    for spp in ladder_spps(top):
        first = render(prep.pt_scene, spp, LADDER_SEED, folder, threads)
        times = [first["seconds"]]
        if first["seconds"] < CHEAP_SECONDS:
            times += [render(prep.pt_scene, spp, LADDER_SEED, folder, threads)["seconds"]
                      for _ in range(TIMING_REPEATS - 1)]
        outs = [first]
        rungs.append({"spp": spp, "seconds": median(times), "seconds_all": times, "errors": errors(outs[0]["rgb"], ref)})
    log(f"      ladder 1-{top} spp: " + ", ".join(f"{r['spp']}: {r['seconds']:.2f} s" for r in rungs))
    return rungs


def pt_cost_model(rungs):
    """(fixed, per-sample) seconds of the ladder: the slope between its 1-spp and top rungs (the longest lever,
    least moved by the timing noise of a shared machine), the fixed part the 1-spp time less one sample."""
    t1, top = rungs[0], rungs[-1]
    slope = max((top["seconds"] - t1["seconds"]) / max(top["spp"] - t1["spp"], 1), 1e-9)
    return max(t1["seconds"] - slope, 0.0), slope


def equal_error(rungs, i, metric, err, pt_per_sample):
    """Where the ladder reaches ``err`` (sphere i, ``metric``): {"spp", "total_s", "render_s", "bound"}.  The
    ladder's errors are made monotone by a running minimum, then log(spp) is interpolated linearly in log(error)
    between the two rungs around ``err``, and the total time log-log in spp between them.  "bound": None; "upper"
    when 1 spp already does better (path tracing needs at most its 1-spp time); "lower" when no rung does."""
    if not np.isfinite(err):
        return None
    spp = np.array([r["spp"] for r in rungs], np.float64)
    t = np.array([r["seconds"] for r in rungs])
    e = np.minimum.accumulate(np.array([max(r["errors"][i][metric], 1e-12) for r in rungs]))
    err = max(err, 1e-12)
    if err >= e[0]:
        s, bound = spp[0], "upper"
    elif err < e[-1]:
        s, bound = spp[-1], "lower"
    else:
        k = int(np.argmax(e <= err))
        if e[k - 1] == e[k]:
            s = spp[k]
        else:
            f = (math.log(err) - math.log(e[k - 1])) / (math.log(e[k]) - math.log(e[k - 1]))
            s = math.exp(math.log(spp[k - 1]) + f * (math.log(spp[k]) - math.log(spp[k - 1])))
        bound = None
    total = math.exp(np.interp(math.log(s), np.log(spp), np.log(t)))
    return {"spp": float(s), "total_s": float(total), "render_s": float(pt_per_sample * s), "bound": bound}


def speedups(rungs, i, metric, err, backend, pt_per_sample):
    """{"total": {...}, "render": {...}}: the equal-error path-tracing time over the backend's, total (both with
    their fixed costs) and render only (both without)."""
    eq = equal_error(rungs, i, metric, err, pt_per_sample)
    if eq is None:
        return None
    out = {"pt_spp": eq["spp"], "bound": eq["bound"]}
    for key, pt, b in (("total", eq["total_s"], backend["total_s"]), ("render", eq["render_s"], backend["render_s"])):
        out[key] = pt / b if b > 0 else float("nan")      # a per-sample time lost in the timing noise: none
    return out


def decay_exponent(rungs, i):
    """k of rel RMS error ~ spp^-k for sphere i: least squares in log-log over the rungs whose (noise-corrected)
    error is resolved, at least 3; None otherwise."""
    pts = [(r["spp"], r["errors"][i]["rel_rms"]) for r in rungs if r["errors"][i]["resolved"]
           and r["errors"][i]["rel_rms"] > 0]
    if len(pts) < 3:
        return None
    x, y = np.log([p[0] for p in pts]), np.log([p[1] for p in pts])
    return {"k": float(-np.polyfit(x, y, 1)[0]), "points": len(pts), "spp": [p[0] for p in pts]}
