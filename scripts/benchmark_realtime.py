"""Frame time of the emitted RT Lit material on the machine's OpenGL (llvmpipe here); writes
docs/benchmarks/realtime.{md,json}.

    python scripts/benchmark_realtime.py [--width 1920 --height 1080] [--frames 5] [--lights 1,4,16]
                                         [--quick] [--device-label "GPU name"]

Entry point of ``rt_lookdev.validation.benchmarks.realtime_benchmark``; ``--help`` lists the options."""
import sys

from rt_lookdev.validation.benchmarks import realtime_benchmark
from rt_lookdev.validation.harness import entry


def main(argv):
    return entry.main(realtime_benchmark, argv)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
