"""Metal and dielectric shaded apart, against Cycles at Metallic 0.5: the validation suite's metallic-mix cases with
one mixed F0 and with the two F0 apart.

    python scripts/benchmark_metal_split.py [--out docs/benchmarks] [--quick]

Entry point of ``rt_lookdev.validation.benchmarks.metal_split_benchmark``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import metal_split_benchmark
from rt_lookdev.validation.harness import entry


def main(argv):
    return entry.main(metal_split_benchmark, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
