"""RT Lookdev main job: bake the LUTs if needed, validate them, write the report.

    python scripts/run_main.py [--out out/report] [--lut-dir DIR] [--skip-render] [--skip-eevee]
                               [--render-resolution N] [--render-samples S]

``scripts/main.sh`` runs it in the project venv.  Entry point of ``rt_lookdev.validation.main_job``;
``--help`` lists the options."""
import sys

from rt_lookdev.validation import main_job


def main(argv):
    args = main_job.parse_args(argv)
    return 0 if main_job.run(args)["passed"] else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
