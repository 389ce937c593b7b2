"""Render check of the GGX energy tables against Cycles (white furnace on spheres).

    python scripts/validate_energy.py [--resolution N] [--samples S] [--roughness 0.25 0.5 ...]
                                      [--out DIR] [--lut-dir DIR]
    blender --background --python scripts/validate_energy.py -- [same options]

Entry point of ``rt_lookdev.validation.checks.energy_render``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.checks import energy_render
from rt_lookdev.validation.harness import entry


def main(argv):
    return entry.main(energy_render, argv, progress=print)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
