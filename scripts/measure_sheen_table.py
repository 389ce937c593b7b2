"""Measure Cycles' sheen table (Zeltner et al. 2022) from Cycles renders into luts/zeltner_sheen.exr.

    python scripts/measure_sheen_table.py [--lut-dir DIR] [--derive-only]

``--derive-only`` keeps the measured (a, b, albedo) of the shipped table and only recomputes what is derived from
them (the moments of each cell's LTC for the world term), without Cycles' renders.

The table cannot be baked by numpy (it is the paper's fit, as Cycles ships it); scripts/bake_luts.py keeps
it.  validation/benchmarks/sheen_table.py says how it is measured.
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from rt_lookdev.core.lut import catalog, exr_io
from rt_lookdev.validation.benchmarks import sheen_table


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--lut-dir", type=Path, default=catalog.default_lut_dir())
    p.add_argument("--derive-only", action="store_true", help="recompute the derived tables from the shipped one")
    args = p.parse_args(argv)
    if args.derive_only:
        measured = exr_io.read_table(catalog.default_lut_dir() / "zeltner_sheen.exr", "zeltner_sheen")[0]
        path, _ = sheen_table.write_measured(args.lut_dir, measured[..., :3].astype(np.float64), {})
        print(f"wrote the derived tables beside {path}")
        return 0
    path, report = sheen_table.write_measured(args.lut_dir)
    res = report["residual"]
    print(f"wrote {path}: {report['seconds']:.1f} s of renders; fit residual (relative rms of f cos) median "
          f"{np.nanmedian(res):.2e}, max {np.nanmax(res):.2e}; {report['filled']} cells below Cycles' albedo "
          "cut-off filled")
    return 0


if __name__ == "__main__":
    sys.exit(main())
