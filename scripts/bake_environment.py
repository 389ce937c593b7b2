"""Bake one World HDRI: L2 SH coefficients and the GGX-prefiltered levels (cached by content hash).

    python scripts/bake_environment.py --hdri forest [--out out/environment] [--force]
    python scripts/bake_environment.py --list
    python scripts/bake_environment.py --hdri /path/to/image.exr --out DIR [--width 128 --height 64]

--hdri takes one of Blender's studio HDRIs (city, courtyard, forest, interior, night, studio,
sunrise, sunset; read from the bpy wheel) or a path to an equirectangular EXR.  Writes
<name>_sh.exr, <name>_sh.json and <name>_ggx_prefiltered.exr (core/environment/prefilter.py
describes the layout) and prints timings; a re-run with the same inputs does no work.
"""
from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from rt_lookdev.core.environment import equirect, prefilter

DEFAULT_OUT = Path(__file__).resolve().parents[1] / "out" / "environment"


def _args(argv):
    if "--" in argv:
        argv = argv[argv.index("--") + 1:]
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--hdri", help="studio HDRI name or EXR path (required unless --list)")
    p.add_argument("--out", type=Path, default=DEFAULT_OUT, help="output folder (default: out/environment)")
    p.add_argument("--width", type=int, default=prefilter.PrefilterSettings.width)
    p.add_argument("--height", type=int, default=prefilter.PrefilterSettings.height)
    p.add_argument("--method", choices=("fft", "importance"), default="fft")
    p.add_argument("--samples", type=int, default=prefilter.PrefilterSettings.samples,
                   help="samples per texel (importance method only)")
    p.add_argument("--force", action="store_true", help="bake even if the files are current")
    p.add_argument("--list", action="store_true", help="list the studio HDRIs and exit")
    args = p.parse_args(argv)
    if not args.list and not args.hdri:
        p.error("--hdri is required (a studio HDRI name from --list, or an EXR path)")
    return args


def main(argv=None):
    args = _args(sys.argv[1:] if argv is None else argv)
    if args.list:
        for name, path in equirect.studio_hdris().items():
            print(f"{name}: {path}")
        return 0
    settings = prefilter.PrefilterSettings(width=args.width, height=args.height, method=args.method,
                                           samples=args.samples)
    start = time.perf_counter()

    def progress(stage, done, total):
        print(f"  [{time.perf_counter() - start:6.2f} s] {stage}: {done}/{total}", flush=True)

    result = prefilter.bake_environment(args.hdri, args.out, settings, progress=progress, force=args.force)
    s = result.seconds
    print(f"[environment] {result.name} ({result.source}, content {result.source_hash[:12]})")
    print(f"  SH: {result.states['sh']} in {s['sh']:.3f} s -> {result.sh_path}, {result.sh_json_path}")
    print(f"  prefiltered ({len(settings.roughness)} levels of {settings.width}x{settings.height}, "
          f"{settings.method}): {result.states['prefiltered']} in {s['prefiltered']:.2f} s -> {result.prefiltered_path}")
    print(f"  total {s['total']:.2f} s (reading the source {s['read']:.3f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
