"""World occlusion and light shadows (the ratio estimator) on the floor study, against the path-traced twin.

    python scripts/benchmark_floor_shadows.py [--out docs/benchmarks] [--quick]

Entry point of ``rt_lookdev.validation.benchmarks.floor_shadows_benchmark``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import floor_shadows_benchmark
from rt_lookdev.validation.harness import entry


def main(argv):
    return entry.main(floor_shadows_benchmark, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
