"""The demo lookdev scene, measured: node counts, Cycles and EEVEE renders, their agreement.

    python scripts/demo_report.py [--out out/report/demo] [--lut-dir DIR] [--resolution 256]
                                  [--repeats 3] [--skip-eevee]

Entry point of ``rt_lookdev.validation.checks.demo_measure``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.checks import demo_measure


def main(argv):
    args = demo_measure.parse_args(argv)
    return 0 if demo_measure.run_args(args)["passed"] else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
