"""Which rough diffuse Cycles renders: a white-furnace render of Diffuse BSDF / Principled spheres against the
candidate models (Lambert, Fujii's Oren-Nayar, EON, Cycles' variant).

    python scripts/validate_rough_diffuse.py [--resolution N] [--samples S] [--out DIR]
    .venvs/blender-4.5/bin/python scripts/validate_rough_diffuse.py [same options]   (Blender 4.5's Cycles; the
                                                     venv is built by bash scripts/test.sh --release 4.5)

Entry point of ``rt_lookdev.validation.rough_diffuse_furnace``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation import rough_diffuse_furnace


def main(argv):
    if "--" in argv:                      # blender --background --python x.py -- args
        argv = argv[argv.index("--") + 1:]
    res = rough_diffuse_furnace.run_args(rough_diffuse_furnace.parse_args(argv))
    return 0 if all("cycles" in c["best"] for c in res["cases"]) else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
