"""The GGX LTC's error against brute force on a suite-like set, per roughness and light kind, this checkout's
tables against those of an earlier revision.

    python scripts/benchmark_ltc_suite_like.py [--out docs/benchmarks] [--before REV] [--lut-dir DIR]

Entry point of ``rt_lookdev.validation.benchmarks.ltc_suite_like``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import ltc_suite_like
from rt_lookdev.validation.harness import entry


def main(argv):
    return entry.main(ltc_suite_like, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
