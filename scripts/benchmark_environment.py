"""Environment baking measured over Blender's 8 studio HDRIs; writes docs/benchmarks/environment.md.

    python scripts/benchmark_environment.py [--normals 500] [--dirs 128] [--out docs/benchmarks/environment.md]

Entry point of ``rt_lookdev.validation.benchmarks.environment_benchmark``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import environment_benchmark


def main(argv):
    args = environment_benchmark.parse_args(argv)
    environment_benchmark.run(args)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
