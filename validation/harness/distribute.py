"""Where a sweep's independent tasks run: here one after another, on a Dask ``LocalCluster`` sized to the machine, or
on a running Dask scheduler whose workers have this checkout and its environment (issue 28).

A sweep (the validation suite's cases, ...) gives ``map_tasks`` a task function named by its import path
("package.module:function"), called as ``function(task, args)`` and returning a picklable record, and its tasks (data:
dataclasses of numbers and strings).  The records come back in the tasks' order, so what a sweep computes from them
does not depend on where or in which order its tasks ran: a task must take everything it depends on from the task
and ``args`` (its own random generator seeded from both, its own LUT set).

Blender cannot run off its main thread (``bpy`` in a thread of a Dask worker crashes the process: measured on
bpy 5.2.3), and a Dask worker runs its tasks in threads.  So on Dask each task runs in a Python process of its own
(``python -m rt_lookdev.validation.harness.task_process``, started by the worker with the worker's Python): the task and
``args`` go in pickled, the record comes back pickled through a file (Blender writes to stdout), and a task that fails
raises ``TaskFailed`` with the end of its output.  Here (``--workers 0``) the tasks run in this process, in order.

Options (``add_arguments``): ``--scheduler ADDRESS`` (or the environment variable ``RTL_DASK_SCHEDULER``) sends the
tasks to a running scheduler; ``--workers N`` sizes the LocalCluster (default: one worker per core; 0 runs here).
Progress is one line per finished task; Ctrl+C cancels the tasks still queued or running.
"""
from __future__ import annotations

import importlib
import os
import pickle
import subprocess
import sys
import tempfile
from pathlib import Path

from .entry import flush_log

#: The environment variable that names a running scheduler when ``--scheduler`` is not given.
SCHEDULER_ENV = "RTL_DASK_SCHEDULER"
#: The module each task runs in on Dask (``task_process.main``).
TASK_PROCESS = "rt_lookdev.validation.harness.task_process"
#: Lines of a failed task's output kept in ``TaskFailed``.
TAIL_LINES = 40


class TaskFailed(RuntimeError):
    """A task's process exited with an error; the message ends with its output."""


def add_arguments(parser):
    """The options of where a sweep's tasks run, in their own group of ``parser``."""
    group = parser.add_argument_group("where the tasks run (Dask)")
    group.add_argument("--scheduler", default=os.environ.get(SCHEDULER_ENV) or None, metavar="ADDRESS",
                       help="a running Dask scheduler (e.g. tcp://10.0.0.5:8786) whose workers have this checkout and "
                            f"its environment; default: ${SCHEDULER_ENV}, else a LocalCluster on this machine")
    group.add_argument("--workers", type=int, default=None,
                       help="worker processes of the LocalCluster (default: one per core); 0 runs the tasks in this "
                            "process, one after another")
    return group


def resolve(function_path):
    """The function that ``function_path`` ("package.module:function") names."""
    module, _, name = function_path.partition(":")
    return getattr(importlib.import_module(module), name)


def where(args):
    """"here", "local N" or "scheduler ADDRESS": where ``map_tasks`` runs tasks for ``args`` (for the report)."""
    scheduler = getattr(args, "scheduler", None)
    if scheduler:
        return f"scheduler {scheduler}"
    workers = _local_workers(args)
    return "here" if workers == 0 else f"local {workers}"


def _local_workers(args):
    workers = getattr(args, "workers", 0)
    return max(os.cpu_count() or 1, 1) if workers is None else max(int(workers), 0)


def map_tasks(function_path, tasks, args, progress=flush_log, label=str, on_record=None):
    """``function(task, args)`` for every task (``resolve(function_path)``), where ``args`` say (``where``): the
    records, in the tasks' order.  ``label(task)`` names a task in the progress lines; ``on_record(task, record)``,
    when given, is called as each record arrives (in the order the tasks finish)."""
    tasks = list(tasks)
    if not tasks:
        return []
    if not getattr(args, "scheduler", None) and _local_workers(args) == 0:
        function, records = resolve(function_path), []
        for task in tasks:
            records.append(function(task, args))
            if on_record is not None:
                on_record(task, records[-1])
        return records
    return _on_dask(function_path, tasks, args, progress, label, on_record)


def _on_dask(function_path, tasks, args, progress, label, on_record):
    from distributed import Client, LocalCluster, as_completed

    scheduler = getattr(args, "scheduler", None)
    if scheduler:
        client, cluster = Client(scheduler), None
    else:
        cluster = LocalCluster(n_workers=_local_workers(args), threads_per_worker=1, processes=True,
                               dashboard_address=None)
        client = Client(cluster)
    try:
        futures = [client.submit(run_in_process, function_path, task, args, pure=False) for task in tasks]
        order = {future.key: i for i, future in enumerate(futures)}
        records = [None] * len(tasks)
        try:
            for done, future in enumerate(as_completed(futures), 1):
                i = order[future.key]
                records[i] = future.result()
                progress(f"[dask] {done}/{len(tasks)} done: {label(tasks[i])}")
                if on_record is not None:
                    on_record(tasks[i], records[i])
        except BaseException:
            client.cancel(futures)
            raise
        return records
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def run_in_process(function_path, task, args):
    """``function(task, args)`` in a Python process of its own (what a Dask worker runs: Blender needs the main
    thread); its record."""
    with tempfile.TemporaryDirectory(prefix="rtl-task-") as folder:
        payload, record = Path(folder) / "task.pickle", Path(folder) / "record.pickle"
        payload.write_bytes(pickle.dumps((function_path, task, args)))
        proc = subprocess.run([sys.executable, "-m", TASK_PROCESS, str(payload), str(record)],
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, errors="replace")
        if proc.returncode != 0 or not record.exists():
            tail = "\n".join(proc.stdout.splitlines()[-TAIL_LINES:])
            raise TaskFailed(f"{function_path} failed (exit code {proc.returncode}) on {task!r}:\n{tail}")
        return pickle.loads(record.read_bytes())
