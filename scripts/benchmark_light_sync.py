"""The automatic light sync's cost per depsgraph update; writes docs/benchmarks/light_sync.{md,json}.

    python scripts/benchmark_light_sync.py [--objects 100] [--lights 10] [--repeats 200]

Entry point of ``rt_lookdev.validation.benchmarks.light_sync_benchmark``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import light_sync_benchmark
from rt_lookdev.validation.harness import entry


def main(argv):
    return entry.main(light_sync_benchmark, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
