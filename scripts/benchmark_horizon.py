"""Every LTC lobe under area lights that cross the receiver's horizon, against lights wholly above it (issue 30):
RT Lit's shading end to end against brute-force integrals.

    python scripts/benchmark_horizon.py [--out docs/benchmarks] [--quick]

Entry point of ``rt_lookdev.validation.benchmarks.horizon_benchmark``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import horizon_benchmark
from rt_lookdev.validation.harness import entry


def main(argv):
    return entry.main(horizon_benchmark, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
