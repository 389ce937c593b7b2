"""Area-light spread (issue 27): RT Lit's rule, the LTC's shape under the spread's weight and the LTC without spread,
each against dense integrals of the true BRDF.

    python scripts/benchmark_spread.py [--out docs/benchmarks] [--quick]

Entry point of ``rt_lookdev.validation.benchmarks.spread_benchmark``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import spread_benchmark
from rt_lookdev.validation.harness import entry


def main(argv):
    return entry.main(spread_benchmark, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
