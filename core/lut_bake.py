"""Bake the lookup tables (``core.lut.catalog``) into EXR files, skipping groups whose files are already current.

A group is current when every one of its files reads back intact (content hash) and was
baked from the same inputs (``catalog.inputs_hash``: layout version, parameters and the
source code of the modules that compute it).  Baking is deterministic: the estimators use
fixed low-discrepancy point sets, so the same inputs give the same tables.
"""
from __future__ import annotations

import json
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import energy
from .lut import catalog, exr_io

GENERATOR = "rt_lookdev.core.lut_bake"


@dataclass(frozen=True)
class BakeRecord:
    group: str
    state: str          # "baked" or "cached"
    seconds: float
    files: tuple


def table_nodes(size):
    """Parameter values of the table nodes on [0, 1]: i / (size - 1)."""
    return np.arange(size, dtype=np.float64) / (size - 1)


def compute_energy_tables(size, n_samples, progress=None):
    """The three GGX energy tables as (H, W, 4) float32 arrays, keyed by table name."""
    r = table_nodes(size)
    mu = table_nodes(size)
    scale, bias = energy.split_sum_terms(mu, r, n_samples, progress=progress)   # (r, mu)
    one_minus_e = (1.0 - (scale + bias)).T.astype(np.float32)                    # (mu, r)
    # 1 - E_avg of exactly the function the stored table reconstructs (float32 values, piecewise
    # linear in mu), so that the Kulla-Conty furnace identity holds to rounding.  Since
    # 2 int mu dmu = 1, 1 - E_avg = 2 int (1 - E) mu dmu: integrated directly, no cancellation.
    one_minus_e_avg = energy.average_of_piecewise_linear(one_minus_e.astype(np.float64).T, mu)   # (r,)
    ones = np.ones((size, size), np.float32)
    zeros = np.zeros((size, size), np.float32)
    return {
        "ggx_one_minus_E": np.stack([one_minus_e, one_minus_e, one_minus_e, ones], axis=-1),
        "ggx_one_minus_E_avg": np.stack([one_minus_e_avg] * 3 + [np.ones(size)], axis=-1)[None].astype(np.float32),
        "ggx_split_sum": np.stack([scale.T.astype(np.float32), bias.T.astype(np.float32), zeros, ones],
                                  axis=-1),
    }


def compute_ltc_tables(prefix, params, progress=None):
    """The two LTC tables of one lobe (core/ltc/fit.py), sphere table in the spare channel."""
    from .ltc import fit, sphere_table

    n_lobe, n_ltc, n_sphere = params["fit_samples"]
    band = fit.Band(**params["band"]) if "band" in params else None
    result = fit.fit_table(params["lobe"], size=params["size"], n_moments=params["moment_samples"],
                           n_lobe=n_lobe, n_ltc=n_ltc, n_sphere=n_sphere, exponent=params["exponent"],
                           max_iter=params["max_iter"], progress=progress, band=band)
    sphere = sphere_table.sphere_horizon_table(params["size"])
    weight = result.get("weight", np.zeros_like(result["magnitude"]))     # channel B: the band's weight, or 0
    return {
        prefix + "_inv": result["packed"].astype(np.float32),
        prefix + "_mag": np.stack([result["magnitude"], result["fresnel"], weight, sphere], axis=-1).astype(np.float32),
    }


def _compute(name, progress=None):
    params = catalog.GROUPS[name].params
    if name == "ggx_energy":
        return compute_energy_tables(params["size"], params["samples"], progress)
    return compute_ltc_tables(name, params, progress)


def _print_progress(name, done, total):
    if done == total or done % max(1, total // 4) == 0:
        print(f"[bake]   {name}: {done}/{total}", flush=True)


def _compute_in_worker(name):
    """Process-pool entry: compute one group, printing coarse progress itself."""
    start = time.perf_counter()
    tables = _compute(name, lambda d, t: _print_progress(name, d, t))
    return name, tables, time.perf_counter() - start


def _metadata(spec, group, digest):
    return {
        "table": spec.name,
        "description": spec.description,
        "channels": spec.channels,
        "axis_u": spec.axis_u,
        "axis_v": spec.axis_v,
        "layout_version": catalog.LAYOUT_VERSION,
        "generator": GENERATOR,
        "generator_version": group.generator_version,
        "samples": int(group.params.get("samples", group.params.get("moment_samples", 0))),
        "sampler": str(group.params.get("sampler", "hammersley-2d")),
        "params": json.dumps(group.params, sort_keys=True),
        "inputs_hash": digest,
    }


def group_is_current(group_name, lut_dir, expected_hash=None):
    expected_hash = expected_hash or catalog.inputs_hash(group_name)
    specs = [s for s in catalog.TABLES.values() if s.group == group_name]
    return all(catalog.table_status(s, lut_dir, expected_hash).state == "ok" for s in specs)


#: Relative cost of each group (measured: docs/benchmarks/ltc.md); longest first in the pool.
_COST = {"ltc_ggx": 3.0, "ltc_cloth": 1.2, "ltc_cod_diffuse": 1.1, "ggx_energy": 1.0}


def _parallel_results(names, workers):
    """Compute groups in forked worker processes (POSIX only); yields (name, tables, seconds)."""
    import multiprocessing

    order = sorted(names, key=lambda n: -_COST.get(n, 1.0))
    with multiprocessing.get_context("fork").Pool(min(workers, len(order))) as pool:
        yield from pool.imap_unordered(_compute_in_worker, order)


def bake(lut_dir=None, force=False, progress=None, groups=None, log=print, workers=None):
    """Bake every group (or ``groups``) into ``lut_dir``; returns a list of BakeRecord.

    Groups whose files are current are skipped ("nothing to do").  The others are computed in
    ``workers`` processes (default: one per core, at most one per group).  Forking needs POSIX,
    so elsewhere they run in turn; a caller inside Blender should pass workers=1.
    ``progress(group, done, total)`` reports long work in the serial case; workers print their
    own progress lines.  ``log`` receives one line per group.
    """
    import os

    lut_dir = Path(lut_dir) if lut_dir is not None else catalog.default_lut_dir()
    records, todo = {}, []
    for name in groups or catalog.GROUPS:
        specs = [s for s in catalog.TABLES.values() if s.group == name]
        files = tuple(lut_dir / s.filename for s in specs)
        if not force and group_is_current(name, lut_dir):
            log(f"[bake] {name}: up to date ({', '.join(f.name for f in files)}), nothing to do")
            records[name] = BakeRecord(name, "cached", 0.0, files)
        else:
            log(f"[bake] {name}: baking {len(specs)} tables ({catalog.GROUPS[name].params})")
            todo.append(name)
    if workers is None:
        workers = os.cpu_count() or 1
    if len(todo) > 1 and workers > 1 and os.name == "posix":
        results = _parallel_results(todo, workers)
    else:
        results = ((n, *_timed(n, (lambda d, t, n=n: progress(n, d, t)) if progress else None)) for n in todo)
    for name, tables, seconds in results:
        group = catalog.GROUPS[name]
        digest = catalog.inputs_hash(name)
        specs = [s for s in catalog.TABLES.values() if s.group == name]
        # a group's tables are written together or not at all (the previous files stay on failure)
        exr_io.write_tables([(lut_dir / spec.filename, tables[spec.name], _metadata(spec, group, digest))
                             for spec in specs])
        log(f"[bake] {name}: wrote {', '.join(s.filename for s in specs)} in {seconds:.1f} s")
        records[name] = BakeRecord(name, "baked", seconds, tuple(lut_dir / s.filename for s in specs))
    return [records[name] for name in (groups or catalog.GROUPS)]


def _timed(name, progress):
    start = time.perf_counter()
    tables = _compute(name, progress)
    return tables, time.perf_counter() - start
