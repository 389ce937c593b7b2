"""Speed against error: RT Lit's backends (Cycles node group, EEVEE, GLSL, numpy) against Cycles path tracing.

    python scripts/benchmark_speed_error.py [--quick] [--out docs/benchmarks] [--cases NAME ...]

Entry point of ``rt_lookdev.validation.benchmarks.speed_error``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import speed_error


def main(argv):
    args = speed_error.parse_args(argv)
    result = speed_error.run_args(args)
    return 0 if result["passed"] else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
