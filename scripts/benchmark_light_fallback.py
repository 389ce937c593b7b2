"""The talk's quad-to-spot fallback against the full quad light for its three angle pairs, and what the light
controls (range, cone, fallback) cost per light.

    python scripts/benchmark_light_fallback.py [--out docs/benchmarks] [--quick]

Entry point of ``rt_lookdev.validation.benchmarks.light_fallback_benchmark``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import light_fallback_benchmark
from rt_lookdev.validation.harness import entry


def main(argv):
    return entry.main(light_fallback_benchmark, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
