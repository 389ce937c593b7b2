"""The talk's quad-to-spot fallback against the full quad light for its three angle pairs, and what the light
controls (range, cone, fallback) cost per light.

    python scripts/benchmark_light_fallback.py [--out docs/benchmarks] [--quick]

Entry point of ``rt_lookdev.validation.benchmarks.light_fallback_benchmark``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import light_fallback_benchmark


def main(argv):
    args = light_fallback_benchmark.parse_args(argv)
    light_fallback_benchmark.run(args.out, args.quick, args.lut_dir)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
