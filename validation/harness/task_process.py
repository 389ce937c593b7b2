"""One task of a sweep in a process of its own (``distribute.run_in_process``):

    python -m rt_lookdev.validation.harness.task_process TASK.pickle RECORD.pickle

reads (function path, task, args) from TASK.pickle, runs the function on the main thread and writes its record to
RECORD.pickle; an exception exits with status 1 after printing its traceback."""
from __future__ import annotations

import pickle
import sys
import traceback
from pathlib import Path

from .distribute import resolve


def main(argv):
    payload, record = (Path(a) for a in argv)
    function_path, task, args = pickle.loads(payload.read_bytes())
    try:
        result = resolve(function_path)(task, args)
    except Exception:
        traceback.print_exc()
        sys.stdout.flush()
        return 1
    record.write_bytes(pickle.dumps(result))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
