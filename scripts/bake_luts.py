"""Bake RT Lookdev's lookup tables into EXR files (cached: unchanged inputs do no work).

    python scripts/bake_luts.py [--lut-dir DIR] [--force] [--status]

Also runs inside Blender: blender --background --python scripts/bake_luts.py -- --status
"""
from __future__ import annotations

import argparse
import sys
from pathlib import Path

from rt_lookdev.core import lut_bake as bake
from rt_lookdev.core.lut import catalog, exr_io


def _args(argv):
    if "--" in argv:                      # blender --background --python x.py -- args
        argv = argv[argv.index("--") + 1:]
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--lut-dir", type=Path, default=catalog.default_lut_dir(),
                   help="output folder (default: the shipped luts/ folder)")
    p.add_argument("--force", action="store_true", help="re-bake even if the files are current")
    p.add_argument("--status", action="store_true", help="only print the status of every table")
    return p.parse_args(argv)


def _progress(group, done, total):
    if done == total or done % max(1, total // 8) == 0:
        print(f"  {group}: {done}/{total} rows ({100 * done // total}%)", flush=True)


def main(argv=None):
    args = _args(sys.argv[1:] if argv is None else argv)
    if not args.status:
        try:
            bake.bake(args.lut_dir, force=args.force, progress=_progress)
            catalog.keep_measured(args.lut_dir)      # measured tables: kept or copied, never baked
        except exr_io.LutError as ex:          # e.g. a read-only folder: the message says what to do
            print(f"bake_luts.py: error: {ex}", file=sys.stderr)
            return 2
    status = catalog.lut_status(args.lut_dir)
    for s in status:
        print(f"  {s.state:8s} {s.message}")
    return 0 if all(s.state == "ok" for s in status) else 1


if __name__ == "__main__":
    sys.exit(main())
