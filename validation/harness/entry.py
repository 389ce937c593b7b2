"""The one entry signature of every check and benchmark, and the ``main`` of the thin scripts that run them.

A check (validation/checks/) or benchmark (validation/benchmarks/) module defines

    parse_args(argv) -> argparse.Namespace     its options: the script's --help, its defaults;
    run(args, progress=flush_log) -> dict      the measurement, its files written where ``args`` say, and the result:
                                               JSON-able (``json.dumps`` takes it, numpy values converted by
                                               ``outputs.json_default``); a check's has "passed" (its gates), a
                                               benchmark that gates nothing has none;
    to_markdown(result) -> str                 the result as Markdown (what the main job's report and
                                               docs/benchmarks/ show).

``progress`` receives one line of text at a time.  A sweep of independent cases (the suite's cases, the world
suite's worlds) also exposes them, so that they can run anywhere (``run_tasks``):

    tasks(args) -> list                        the cases, as data (dataclasses of numbers and strings);
    run_task(task, args, ...) -> dict          one case: a JSON-able record, from the task and the options alone;
    combine(args, records) -> dict             the records pooled and gated: ``run``'s result.

``scripts/<name>.py`` is then ``sys.exit(entry.main(module, sys.argv[1:]))``.
"""
from __future__ import annotations


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


def exit_code(result):
    """0 when the result passed (or gates nothing: a benchmark), 1 otherwise."""
    return 0 if result.get("passed", True) else 1


def main(module, argv, progress=flush_log):
    """A script's main: ``module.run(module.parse_args(argv))``; the exit code of its result."""
    args = module.parse_args(script_arguments(argv))
    return exit_code(module.run(args, progress))


def run_tasks(run_task, tasks, args, progress=flush_log, **shared):
    """``run_task(task, args, **shared)`` for every task, in order, here: the records.  The one place a sweep's
    cases are mapped; running them elsewhere (worker processes, a cluster) replaces this map."""
    return [run_task(task, args, progress=progress, **shared) for task in tasks]
