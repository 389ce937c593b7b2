"""Relative errors of a render against its ground truth, and their pooled statistics (the validation suite's,
the world suite's and the lookdev twin's figures)."""
from __future__ import annotations

import numpy as np


def pool(entries):
    """The statistics of pooled comparisons: ``values``, ``mean``, ``median``, ``p90``, ``max`` of every entry's
    ``rel``; ``noise_median`` / ``noise_p90`` of their ``noise``; ``wide_median`` / ``wide_p90`` of ``rel_wide``."""
    rel = np.concatenate([e["rel"] for e in entries]) if entries else np.zeros(0)
    out = {"values": int(rel.size)}
    if rel.size:
        out.update({"mean": float(rel.mean()), "median": float(np.median(rel)),
                    "p90": float(np.percentile(rel, 90)), "max": float(rel.max())})
    noise = [e["noise"] for e in entries if e.get("noise") is not None and e["noise"].size]
    if noise:
        out["noise_median"] = float(np.median(np.concatenate(noise)))
        out["noise_p90"] = float(np.percentile(np.concatenate(noise), 90))
    wide = [e["rel_wide"] for e in entries if e.get("rel_wide") is not None]
    if wide:
        w = np.concatenate(wide)
        out.update({"wide_median": float(np.median(w)), "wide_p90": float(np.percentile(w, 90))})
    return out


def rel_values(a, c, mask, floor_frac, c_pair=None):
    """|a - c| / c over the values (pixel x channel) under ``mask`` where c is finite and above ``floor_frac`` x its
    max; with ``c_pair`` (the truth's two seeds, c their mean) also the noise |c1 - c2| / 2 / c of the same
    values.  (None, None) when no value of c is finite."""
    av, cv = a[mask].astype(np.float64).ravel(), c[mask].astype(np.float64).ravel()
    ok = np.isfinite(cv)
    if not ok.any():
        return None, None
    sel = ok & (cv > floor_frac * cv[ok].max())
    rel = np.abs(av[sel] - cv[sel]) / cv[sel]
    noise = None
    if c_pair is not None:
        c1, c2 = (x[mask].astype(np.float64).ravel()[sel] for x in c_pair)
        noise = np.abs(c1 - c2) / 2.0 / cv[sel]
    return rel, noise


def interior_pixels(index):
    """Pixels whose four neighbours show the same object (silhouettes left out)."""
    keep = index > 0
    for axis in (0, 1):
        for shift in (1, -1):
            keep &= np.roll(index, shift, axis=axis) == index
    keep[0, :] = keep[-1, :] = keep[:, 0] = keep[:, -1] = False
    return keep
