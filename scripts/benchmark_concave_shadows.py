"""Light shadows (the ratio estimator) on the asset-like concave scene against its path-traced twin, beside path
tracing's own time-vs-error curve.

    python scripts/benchmark_concave_shadows.py [--out docs/benchmarks] [--quick] [--runs N]

Entry point of ``rt_lookdev.validation.benchmarks.concave_shadows_benchmark``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import concave_shadows_benchmark
from rt_lookdev.validation.harness import entry


def main(argv):
    return entry.main(concave_shadows_benchmark, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
