"""Benchmark the energy LUT bake: time, error against sample count, table axis, E_avg fits.

    python scripts/benchmark_luts.py [--out docs/benchmarks] [--repeats 3] [--quick]

Entry point of ``rt_lookdev.validation.benchmarks.lut_benchmark``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import lut_benchmark


def main(argv):
    args = lut_benchmark.parse_args(argv)
    lut_benchmark.run(args)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
