"""Metal and dielectric shaded apart, against Cycles at Metallic 0.5: the validation suite's metallic-mix cases with
one mixed F0 and with the two F0 apart.

    python scripts/benchmark_metal_split.py [--out docs/benchmarks] [--quick]

Entry point of ``rt_lookdev.validation.benchmarks.metal_split_benchmark``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import metal_split_benchmark


def main(argv):
    args = metal_split_benchmark.parse_args(argv)
    if args.measure:   # the child process of one shading
        metal_split_benchmark.measure(args.measure, args.cases, args.work)
        return 0
    metal_split_benchmark.run(args.out, args.quick)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
