"""World occlusion (ambient occlusion on the World term, specular occlusion from it) on the floor study, against the
path-traced twin, for every occlusion model.

    python scripts/benchmark_world_occlusion.py [--out docs/benchmarks] [--quick]

Entry point of ``rt_lookdev.validation.benchmarks.world_occlusion_benchmark``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import world_occlusion_benchmark
from rt_lookdev.validation.harness import entry


def main(argv):
    return entry.main(world_occlusion_benchmark, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
