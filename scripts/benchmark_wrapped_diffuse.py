"""The multiscattering wrapped diffuse against brute force: punctual albedo, area lights (the shipped light-image
form and the talk's tilted normal), the World term's SH form.

    python scripts/benchmark_wrapped_diffuse.py [--out docs/benchmarks] [--lights 120] [--quick]

Entry point of ``rt_lookdev.validation.benchmarks.wrapped_diffuse_benchmark``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import wrapped_diffuse_benchmark


def main(argv):
    args = wrapped_diffuse_benchmark.parse_args(argv)
    wrapped_diffuse_benchmark.run(args.out, args.lights, args.quick, args.lut_dir)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
