"""Build the lookdev preset asset library (``rt_lookdev.addon.preset_assets``): ``assets/rt_lookdev_presets.blend``
and ``assets/blender_assets.cats.txt`` from ``core/materials/presets.py``.

    python scripts/build_presets.py [--out assets]
    blender --background --python scripts/build_presets.py -- [--out DIR]
"""
import argparse
import sys
from pathlib import Path


def main(argv):
    if "--" in argv:                      # blender --background --python x.py -- args
        argv = argv[argv.index("--") + 1:]
    import bpy

    from rt_lookdev.addon import preset_assets as presets
    from rt_lookdev.core.materials import presets as core_presets

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--out", type=Path, default=presets.ASSETS_DIR)
    args = parser.parse_args(argv)
    bpy.ops.wm.read_homefile(use_empty=True)
    path = presets.build_library(args.out)
    print(f"build_presets: {len(core_presets.PRESETS)} presets in {path} "
          f"({path.stat().st_size / 1024:.0f} KiB), catalogs in {path.parent / presets.CATALOG_FILE.name}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
