"""The validation suite's cases as Dask tasks (validation/harness/distribute.py): the same figures whether the cases
run here one after another, on a LocalCluster of 2 workers, or on a scheduler with 2 `dask worker` processes started
from the command line (what a cluster is), and a task that fails says why."""
from __future__ import annotations

import json
import subprocess
import sys
import time
from pathlib import Path

import pytest

#: Two of the quick cases (a punctual light, and a quad under the brute-force truth), small: the sweep is the point.
SWEEP = ["--quick", "--cases", "point", "quad_brute", "--cell", "32", "--segments", "48", "--samples", "16",
         "--brute-pixels", "24", "--skip-furnace", "--no-brute-check"]
#: What depends on where and when a run happened, not on what it computed.
VOLATILE = ("time_", "timings_s", "ran")


def _figures(value):
    """``value`` without its times and where it ran (recursively)."""
    if isinstance(value, dict):
        return {k: _figures(v) for k, v in value.items() if not any(k.startswith(p) for p in VOLATILE)}
    if isinstance(value, list):
        return [_figures(v) for v in value]
    return value


def _differences(a, b, path=""):
    """The paths where two JSON values differ (for the assertion message)."""
    if isinstance(a, dict) and isinstance(b, dict):
        return [d for k in sorted(set(a) | set(b)) for d in _differences(a.get(k), b.get(k), f"{path}.{k}")]
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        return [d for i, (x, y) in enumerate(zip(a, b)) for d in _differences(x, y, f"{path}[{i}]")]
    return [] if a == b else [f"{path}: {a!r} != {b!r}"]


def _run(suite, out, lut_dir, *where):
    args = suite.parse_args(SWEEP + ["--out", str(out), "--lut-dir", str(lut_dir), *where])
    t = time.perf_counter()
    result = suite.run(args, log=lambda line: None)
    return json.loads(json.dumps(result, default=str)), time.perf_counter() - t


@pytest.fixture(scope="module")
def scheduler(tmp_path_factory):
    """A Dask scheduler and 2 worker processes started from the command line (as on a cluster); its address."""
    folder = tmp_path_factory.mktemp("dask")
    file = folder / "scheduler.json"
    dask = str(Path(sys.executable).parent / "dask")       # the command line the README shows
    procs = [subprocess.Popen([dask, "scheduler", "--scheduler-file", str(file), "--port", "0", "--no-dashboard",
                               "--host", "127.0.0.1"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]
    try:
        for _ in range(600):
            if file.exists() and file.stat().st_size > 0:
                break
            time.sleep(0.1)
        address = json.loads(file.read_text())["address"]
        for _ in range(2):
            procs.append(subprocess.Popen([dask, "worker", address, "--nthreads", "1", "--no-dashboard"],
                                          stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        from distributed import Client
        with Client(address) as client:
            client.wait_for_workers(2, timeout=120)
        yield address
    finally:
        for proc in reversed(procs):
            proc.terminate()
            proc.wait(timeout=30)


def test_same_figures_here_on_a_local_cluster_and_on_a_scheduler(tmp_path, lut_dir, bpy_module, scheduler):
    from rt_lookdev.validation.checks import suite

    here, t_here = _run(suite, tmp_path / "here", lut_dir, "--workers", "0")
    local, t_local = _run(suite, tmp_path / "local", lut_dir, "--workers", "2")
    remote, t_remote = _run(suite, tmp_path / "remote", lut_dir, "--scheduler", scheduler)
    print(f"wall time: here {t_here:.1f} s, LocalCluster (2 workers) {t_local:.1f} s, "
          f"scheduler + 2 workers {t_remote:.1f} s")
    assert here["settings"]["ran"] == "here" and local["settings"]["ran"] == "local 2"
    assert remote["settings"]["ran"] == f"scheduler {scheduler}"
    assert sorted(c["name"] for c in here["cases"]) == ["point", "quad_brute"]
    assert not _differences(_figures(local), _figures(here))
    assert not _differences(_figures(remote), _figures(here))
    for out in ("here", "local", "remote"):         # every case's images written where the run said
        assert all((tmp_path / out / c["name"] / "node_a.exr").exists() for c in here["cases"])


def test_a_failed_task_says_why(tmp_path):
    from rt_lookdev.validation.harness import distribute

    with pytest.raises(distribute.TaskFailed, match="ZeroDivisionError"):
        distribute.run_in_process("operator:truediv", 1, 0)
