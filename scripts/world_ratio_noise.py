"""Noise of the World ratio on the floor: each composite (npz of world_ratio_study.py) against a reference composite
(the same setup at many probe samples), per floor pixel |a / ref - 1|, median / p90.

    .venv/bin/python scripts/world_ratio_noise.py out/wr_big RES REF ROW [ROW ...]
"""
import sys

import numpy as np


def main(prefix, res, ref, rows):
    r = np.load(f"{prefix}_{ref}_{res}.npz")
    mask = r["mask"] & (r["rt_lit"].mean(-1) > 1e-3)
    for row in rows:
        a = np.load(f"{prefix}_{row}_{res}.npz")
        m = mask & a["mask"]
        rel = np.abs(a["rt_lit"][m].mean(-1) / r["rt_lit"][m].mean(-1) - 1.0)
        print(f"{row} vs {ref} @ {res}: median {np.median(rel):.1%}, p90 {np.percentile(rel, 90):.1%} ({m.sum()} px)")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4:])
