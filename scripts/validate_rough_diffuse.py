"""Which rough diffuse Cycles renders: a white-furnace render of Diffuse BSDF / Principled spheres against the
candidate models (Lambert, Fujii's Oren-Nayar, EON, Cycles' variant).

    python scripts/validate_rough_diffuse.py [--resolution N] [--samples S] [--out DIR]
    .venvs/blender-4.5/bin/python scripts/validate_rough_diffuse.py [same options]   (Blender 4.5's Cycles; the
                                                     venv is built by bash scripts/test.sh --release 4.5)

Entry point of ``rt_lookdev.validation.checks.rough_diffuse_furnace``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.checks import rough_diffuse_furnace
from rt_lookdev.validation.harness import entry


def main(argv):
    return entry.main(rough_diffuse_furnace, argv, progress=print)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
