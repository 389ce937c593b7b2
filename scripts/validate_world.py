"""Headless validation of the RT Lit World term (issue 6) under Blender's studio HDRIs.

Entry point of ``rt_lookdev.validation.checks.world_suite``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.checks import world_suite


def main(argv):
    if "--" in argv:                      # blender --background --python x.py -- args
        argv = argv[argv.index("--") + 1:]
    args = world_suite.parse_args(argv)
    return 0 if world_suite.run(args)["passed"] else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
