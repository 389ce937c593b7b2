"""The export's ltc_code tables as a drop-in for three.js, rendered in headless Chromium against a brute-force truth
of three's BRDF; writes docs/benchmarks/three_ltc.{md,json}.

    python scripts/benchmark_three_ltc.py [--configs 12] [--size 10] [--out docs/benchmarks/three_ltc.md]

Entry point of ``rt_lookdev.validation.benchmarks.three_ltc_benchmark``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import three_ltc_benchmark
from rt_lookdev.validation.harness import entry


def main(argv):
    return entry.main(three_ltc_benchmark, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
