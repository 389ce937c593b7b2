"""Lights out of range left out of each material's tree: nodes and Cycles render time, culled against every light,
on the demo scene and a 16-light scene.

    python scripts/benchmark_light_culling.py [--out docs/benchmarks] [--repeats 3] [--quick] [--scenes demo,grid]

Entry point of ``rt_lookdev.validation.benchmarks.light_culling_benchmark``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import light_culling_benchmark
from rt_lookdev.validation.harness import entry


def main(argv):
    return entry.main(light_culling_benchmark, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
