"""Environment baking measured over Blender's 8 studio HDRIs; writes docs/benchmarks/environment.md.

    python scripts/benchmark_environment.py [--normals 500] [--dirs 128] [--out docs/benchmarks/environment.md]

Entry point of ``rt_lookdev.validation.benchmarks.environment_benchmark``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import environment_benchmark
from rt_lookdev.validation.harness import entry


def main(argv):
    return entry.main(environment_benchmark, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
