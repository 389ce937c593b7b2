"""Validate and build the RT Lookdev extension zip with Blender's own extension tool.

    python scripts/build_extension.py                 # -> dist/rt_lookdev-<version>.zip
    python scripts/build_extension.py --output-dir /tmp/out

Entry point of ``rt_lookdev.validation.tools.extension_zip``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.tools import extension_zip


def main(argv):
    args = extension_zip.parse_args(argv)
    return 0 if extension_zip.run(args)["passed"] else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
