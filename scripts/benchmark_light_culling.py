"""Lights out of range left out of each material's tree: nodes and Cycles render time, culled against every light,
on the demo scene and a 16-light scene.

    python scripts/benchmark_light_culling.py [--out docs/benchmarks] [--repeats 3] [--quick] [--scenes demo,grid]

Entry point of ``rt_lookdev.validation.benchmarks.light_culling_benchmark``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import light_culling_benchmark


def main(argv):
    args = light_culling_benchmark.parse_args(argv)
    light_culling_benchmark.run(args.out, args.repeats, args.quick, args.lut_dir,
                                tuple(s for s in args.scenes.split(",") if s))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
