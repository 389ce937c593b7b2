"""Specular occlusion from ambient occlusion against the integral it stands for: Lagarde & de Rousiers 2014, the
cones of Jimenez et al. 2016 (GTSO), and the cones clipped by the horizon.

    python scripts/benchmark_specular_occlusion.py [--out docs/benchmarks] [--samples 16384] [--quick]

Entry point of ``rt_lookdev.validation.benchmarks.specular_occlusion_benchmark``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import specular_occlusion_benchmark
from rt_lookdev.validation.harness import entry


def main(argv):
    return entry.main(specular_occlusion_benchmark, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
