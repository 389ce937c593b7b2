"""The exported ltc_code GGX pair (f32, f16) against the published ltc_code table over random quads per roughness;
writes docs/benchmarks/ltc_code_export.{md,json}.

    python scripts/benchmark_ltc_code_export.py [--quads 400] [--anchor ../shared/anchors/ltc_code_ggx_table.txt] [--out docs/benchmarks/ltc_code_export.md]

Entry point of ``rt_lookdev.validation.benchmarks.ltc_code_export_benchmark``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import ltc_code_export_benchmark
from rt_lookdev.validation.harness import entry


def main(argv):
    return entry.main(ltc_code_export_benchmark, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
