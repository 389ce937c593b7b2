"""Headless validation of the RT Lit material (issue 5): node render vs numpy vs ground truth.

Entry point of ``rt_lookdev.validation.checks.suite``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.checks import suite


def main(argv):
    if "--" in argv:                      # blender --background --python x.py -- args
        argv = argv[argv.index("--") + 1:]
    args = suite.parse_args(argv)
    return 0 if suite.run(args)["passed"] else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
