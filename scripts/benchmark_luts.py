"""Benchmark the energy LUT bake: time, error against sample count, table axis, E_avg fits.

    python scripts/benchmark_luts.py [--out docs/benchmarks] [--repeats 3] [--quick]

Entry point of ``rt_lookdev.validation.benchmarks.lut_benchmark``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import lut_benchmark
from rt_lookdev.validation.harness import entry


def main(argv):
    return entry.main(lut_benchmark, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
