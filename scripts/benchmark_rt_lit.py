"""RT Lit in Cycles: how many lights fit one material, and what each costs (with and without the World term).

    python scripts/benchmark_rt_lit.py [--out docs/benchmarks] [--repeats 3] [--only LABEL]

Entry point of ``rt_lookdev.validation.benchmarks.rt_lit_benchmark``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import rt_lit_benchmark
from rt_lookdev.validation.harness import entry


def main(argv):
    return entry.main(rt_lit_benchmark, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
