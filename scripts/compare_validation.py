"""Two runs of scripts/validate.py side by side: median, p90 and RMS of the (a) vs (c) relative error per
technique, light kind and roughness, pooled over the cases both rendered.

    python scripts/compare_validation.py BEFORE_DIR AFTER_DIR [--techniques ggx turquin ...] [--out FILE.md]

Entry point of ``rt_lookdev.validation.checks.suite_compare``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.checks import suite_compare


def main(argv):
    suite_compare.run(suite_compare.parse_args(argv))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
