"""Half-precision LUTs measured per table and end to end (LTC light set, furnaces); writes
docs/benchmarks/lut_export.{md,json}.

    python scripts/benchmark_lut_export.py [--quads 120 --disks 60] [--out docs/benchmarks/lut_export.md]

Entry point of ``rt_lookdev.validation.benchmarks.lut_export_benchmark``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import lut_export_benchmark
from rt_lookdev.validation.harness import entry


def main(argv):
    return entry.main(lut_export_benchmark, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
