"""RT Lit shadows in EEVEE (its Shadow pass) against RT Lit shadows in Cycles, on the floor study and the concave scene.

    python scripts/benchmark_eevee_shadows.py [--out docs/benchmarks] [--quick]

Entry point of ``rt_lookdev.validation.benchmarks.eevee_shadows_benchmark``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import eevee_shadows_benchmark
from rt_lookdev.validation.harness import entry


def main(argv):
    return entry.main(eevee_shadows_benchmark, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
