"""The one entry signature of every check and benchmark, and the ``main`` of the thin scripts that run them.

A check (validation/checks/) or benchmark (validation/benchmarks/) module defines

    parse_args(argv) -> argparse.Namespace     its options: the script's --help, its defaults;
    run(args, progress=flush_log) -> dict      the measurement, its files written where ``args`` say, and the result:
                                               JSON-able (``json.dumps`` takes it, numpy values converted by
                                               ``outputs.json_default``); a check's has "passed" (its gates), a
                                               benchmark that gates nothing has none;
    to_markdown(result) -> str                 the result as Markdown (what the main job's report and
                                               docs/benchmarks/ show).

``progress`` receives one line of text at a time.  A sweep of independent cases (the suite's cases) also defines

    run_task(task, args) -> record             one case, from the task (data) and the options alone: a picklable
                                               record, so that ``distribute.map_tasks`` can run it anywhere.

``scripts/<name>.py`` is then ``sys.exit(entry.main(module, sys.argv[1:]))``.
"""
from __future__ import annotations

import argparse
from pathlib import Path


def flush_log(line):
    """The default ``progress`` of long runs: print at once (progress shows while a job runs)."""
    print(line, flush=True)


def quiet(line):
    """A ``progress`` that drops every line."""


def script_arguments(argv):
    """The script's own arguments: what follows "--" when Blender runs it (``blender --background --python
    scripts/validate.py -- options``), else ``argv``."""
    argv = list(argv)
    return argv[argv.index("--") + 1:] if "--" in argv else argv


def benchmark_parser(doc, out, quick_help):
    """The parser most benchmarks start from: the module docstring's first paragraph as its description, ``--out``
    (default ``out``), ``--lut-dir`` and ``--quick`` (``quick_help`` says what it cuts)."""
    p = argparse.ArgumentParser(description=doc.split("\n\n")[0])
    p.add_argument("--out", type=Path, default=out)
    p.add_argument("--lut-dir", type=Path, default=None, help="LUT folder (default: the extension's luts/)")
    p.add_argument("--quick", action="store_true", help=quick_help)
    return p


def exit_code(result):
    """0 when the result passed (or gates nothing: a benchmark), 1 otherwise."""
    return 0 if result.get("passed", True) else 1


def main(module, argv, progress=flush_log):
    """A script's main: ``module.run(module.parse_args(argv))``; the exit code of its result."""
    args = module.parse_args(script_arguments(argv))
    return exit_code(module.run(args, progress))

