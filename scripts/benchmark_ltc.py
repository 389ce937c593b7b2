"""LTC fit and accuracy report: bake time, per-cell lobe error, magnitude error, end-to-end
error on random quad and disk lights, with the published GGX table through the same code.

    python scripts/benchmark_ltc.py [--out docs/benchmarks] [--repeats 3] [--quick]
                                    [--lut-dir DIR] [--skip-bake]

Entry point of ``rt_lookdev.validation.benchmarks.ltc_benchmark``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import ltc_benchmark


def main(argv):
    args = ltc_benchmark.parse_args(argv)
    ltc_benchmark.run(args)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
