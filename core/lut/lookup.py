"""Sampling LUTs the way Blender's Image Texture node does, and the energy tables as functions.

``sample_bilinear`` reproduces Cycles' Linear interpolation with EXTEND: texel i has its
centre at u = (i + 0.5)/W, and coordinates outside the centres clamp to the edge texels
(../shared/reference/blender_addon.md §3.2).  ``lut_coordinate`` maps a table parameter in
[0, 1] onto the texel centres, so node values are returned exactly and the table is
reconstructed as a piecewise-linear function of its parameters.

``LtcTables.lookup`` works on numpy arrays and on IR expressions (``op.lut_sample`` with
``op.Lut`` objects named by catalog table names).  Traced functions that cannot receive a tables
object (node functions) read the process-wide default: ``default_ltc_tables()`` /
``default_energy_tables()``, loaded once from ``active_lut_dir()``: ``catalog.default_lut_dir()``
or the folder given to ``use_lut_dir`` (a plain call, or ``with use_lut_dir(path):``).
"""
from __future__ import annotations

import threading
from pathlib import Path

import numpy as np

from .. import shading_ops as op
from ..ir.expr import is_expr
from . import catalog, exr_io


def lut_coordinate(x, size):
    """Texture coordinate of table parameter x in [0, 1]: (x (N - 1) + 0.5) / N."""
    return (op.saturate(x) * (size - 1) + 0.5) / size


def energy_lut_uv(mu, roughness, size=catalog.ENERGY_SIZE):
    """(u, v) of the energy tables: u from roughness, v from mu."""
    return lut_coordinate(roughness, size), lut_coordinate(mu, size)


def sample_bilinear(table, u, v):
    """Bilinear lookup of a (H, W, C) table at texture coordinates (u, v), EXTEND at the edges."""
    table = np.asarray(table)
    h, w = table.shape[:2]
    x = np.clip(np.asarray(u, dtype=np.float64) * w - 0.5, 0.0, w - 1)
    y = np.clip(np.asarray(v, dtype=np.float64) * h - 0.5, 0.0, h - 1)
    x0 = np.minimum(np.floor(x).astype(np.int64), w - 2) if w > 1 else np.zeros(x.shape, np.int64)
    y0 = np.minimum(np.floor(y).astype(np.int64), h - 2) if h > 1 else np.zeros(y.shape, np.int64)
    fx = (x - x0)[..., None]
    fy = (y - y0)[..., None]
    x1 = np.minimum(x0 + 1, w - 1)
    y1 = np.minimum(y0 + 1, h - 1)
    top = table[y0, x0] * (1.0 - fx) + table[y0, x1] * fx
    bottom = table[y1, x0] * (1.0 - fx) + table[y1, x1] * fx
    return top * (1.0 - fy) + bottom * fy


class EnergyTables:
    """The GGX energy tables of one LUT folder, sampled as Blender samples them."""

    def __init__(self, lut_dir=None):
        lut_dir = Path(lut_dir) if lut_dir is not None else catalog.default_lut_dir()
        self.tables = {}
        for name in ("ggx_one_minus_E", "ggx_one_minus_E_avg", "ggx_split_sum"):
            spec = catalog.TABLES[name]
            self.tables[name], _ = exr_io.read_table(lut_dir / spec.filename, spec.name, spec.shape)

    def one_minus_e(self, mu, roughness):
        u, v = energy_lut_uv(mu, roughness)
        return sample_bilinear(self.tables["ggx_one_minus_E"], u, v)[..., 0]

    def e(self, mu, roughness):
        return 1.0 - self.one_minus_e(mu, roughness)

    def one_minus_e_avg(self, roughness):
        u = lut_coordinate(roughness, catalog.ENERGY_SIZE)
        return sample_bilinear(self.tables["ggx_one_minus_E_avg"], u, np.full(np.shape(u), 0.5))[..., 0]

    def e_avg(self, roughness):
        return 1.0 - self.one_minus_e_avg(roughness)

    def split_sum(self, mu, roughness):
        """(scale, bias) at (mu, r)."""
        u, v = energy_lut_uv(mu, roughness)
        rg = sample_bilinear(self.tables["ggx_split_sum"], u, v)
        return rg[..., 0], rg[..., 1]


def ltc_lut_uv(mu, roughness, size=catalog.LTC_SIZE):
    """(u, v) of the LTC tables: u from roughness, v from sqrt(1 - mu) (ltc.md §5.2)."""
    return lut_coordinate(roughness, size), lut_coordinate(op.sqrt(1.0 - op.saturate(mu)), size)


class LtcTables:
    """The LTC tables of one LUT folder (``catalog.LTC_LOBES``), sampled as Blender samples them."""

    def __init__(self, lut_dir=None, prefixes=None):
        lut_dir = Path(lut_dir) if lut_dir is not None else catalog.default_lut_dir()
        self.lut_dir = lut_dir
        self.tables = {}
        for prefix in prefixes or catalog.LTC_LOBES:
            for suffix in ("_inv", "_mag"):
                spec = catalog.TABLES[prefix + suffix]
                self.tables[spec.name], _ = exr_io.read_table(lut_dir / spec.filename, spec.name, spec.shape)
        #: table name -> op.Lut (one Image Texture per table in nodes)
        self.luts = {name: op.Lut(name, table) for name, table in self.tables.items()}

    def lookup(self, prefix, mu, roughness):
        """((c0, c1, c2, c3), magnitude, fresnel) at (mu, r): the packed Minv entries (``matrix``)
        and the lobe's magnitude and Fresnel channels.  Arrays or Exprs (one ``lut`` node per channel)."""
        u, v = ltc_lut_uv(mu, roughness)
        inv, mag = self.luts[prefix + "_inv"], self.luts[prefix + "_mag"]
        if is_expr(u, v):
            return (tuple(op.lut_sample(inv, u, v, i) for i in range(4)),
                    op.lut_sample(mag, u, v, 0), op.lut_sample(mag, u, v, 1))
        packed = sample_bilinear(inv.table, u, v)
        m = sample_bilinear(mag.table, u, v)
        return tuple(packed[..., i] for i in range(4)), m[..., 0], m[..., 1]

    def sphere_table(self, prefix="ltc_ggx"):
        """The horizon-clipped sphere table: the ``op.Lut`` of the ``prefix_mag`` table, whose channel A
        (``core.ltc.sphere_table.SPHERE_CHANNEL``) holds it on its own axes; every ``*_mag`` table
        carries the same one, so shader code reads ``ltc_ggx_mag``'s and one image serves all lobes."""
        return self.luts[prefix + "_mag"]


# --- process-wide defaults (for node functions, which cannot receive a tables object) ---------------

_lock = threading.Lock()
_state = {"dir": None, "ltc": None, "energy": None}
_hooks = []


def active_lut_dir():
    """The folder the defaults read: the one given to ``use_lut_dir``, else the shipped ``luts/``."""
    return Path(_state["dir"]) if _state["dir"] is not None else catalog.default_lut_dir()


current_lut_dir = active_lut_dir


def _set_lut_dir(path):
    with _lock:
        _state.update(dir=None if path is None else Path(path), ltc=None, energy=None)
    from ..ir.functions import invalidate_all

    invalidate_all()          # traced node-function bodies hold the tables they were traced with
    for hook in list(_hooks):
        hook()


class _LutDirChange:
    """Returned by ``use_lut_dir``: the change is already made; as a context manager it is undone
    (the previous folder restored) on exit."""

    def __init__(self, previous):
        self.previous = previous

    def __enter__(self):
        return active_lut_dir()

    def __exit__(self, *exc):
        _set_lut_dir(self.previous)
        return False


def use_lut_dir(path):
    """Point the default tables at ``path`` (None: back to the shipped folder), now; cached tables are
    dropped and the registered hooks run (node functions forget bodies traced with the old tables).
    ``with use_lut_dir(path): ...`` restores the previous folder afterwards."""
    previous = _state["dir"]
    _set_lut_dir(path)
    return _LutDirChange(previous)


def on_lut_dir_change(hook):
    """Register ``hook()`` to run whenever ``use_lut_dir`` is called; returns ``hook`` (a decorator)."""
    _hooks.append(hook)
    return hook


def default_ltc_tables():
    """``LtcTables`` of ``active_lut_dir()``, loaded once and shared."""
    with _lock:
        if _state["ltc"] is None:
            _state["ltc"] = LtcTables(active_lut_dir())
        return _state["ltc"]


def default_energy_tables():
    """``EnergyTables`` of ``active_lut_dir()``, loaded once and shared."""
    with _lock:
        if _state["energy"] is None:
            _state["energy"] = EnergyTables(active_lut_dir())
        return _state["energy"]
