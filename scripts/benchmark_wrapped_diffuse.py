"""The multiscattering wrapped diffuse against brute force: punctual albedo, area lights (the shipped light-image
form and the talk's tilted normal), the World term's SH form.

    python scripts/benchmark_wrapped_diffuse.py [--out docs/benchmarks] [--lights 120] [--quick]

Entry point of ``rt_lookdev.validation.benchmarks.wrapped_diffuse_benchmark``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import wrapped_diffuse_benchmark
from rt_lookdev.validation.harness import entry


def main(argv):
    return entry.main(wrapped_diffuse_benchmark, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
