"""The robustness sweep: NaN / Inf / negative / over-bound counts per technique family, light kind and
backend (numpy float32, GLSL, Cycles node groups); writes docs/benchmarks/robustness.{md,json}.

    python scripts/robustness_sweep.py [--points 200000] [--image-points N] [--backends numpy,glsl,cycles]

Entry point of ``rt_lookdev.validation.checks.robustness``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.checks import robustness


def main(argv):
    result = robustness.run(robustness.parse_args(argv))
    return 1 if result["failures"] else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
