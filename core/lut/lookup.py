"""Reading the baked tables: a ``LutSet`` (name -> ``Table``) from a folder the caller names, and the
lookups shading code makes in it (GGX energy, split sum, LTC matrices, the sphere table).

Texture coordinates follow Cycles' Image Texture (``core.ir.semantics.sample_bilinear``): texel i has
its centre at u = (i + 0.5)/W and EXTEND clamps to the edge texels (docs/blender.md, "Tables as
images").  ``lut_coordinate`` maps a table parameter in [0, 1] onto the texel centres, so node values
are returned exactly and a table is reconstructed as a piecewise-linear function of its parameters.

There is no process-wide folder.  Code that evaluates reads from the ``LutSet`` it is given
(``LutSet.from_folder(path)``); code that traces reads ``REFERENCES``, the same tables without data
(names and sizes are fixed by the layout in ``catalog``), so a traced function serves every folder.
Every lookup below works on numpy arrays (the set must hold data) and on IR expressions.
"""
from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from .. import shading_ops as op
from ..ir.expr import is_expr
from ..ir.semantics import sample_bilinear
from ..ir.tables import Table
from . import catalog, exr_io


def lut_coordinate(x, size):
    """Texture coordinate of table parameter x in [0, 1]: (x (N - 1) + 0.5) / N."""
    return (op.saturate(x) * (size - 1) + 0.5) / size


def energy_lut_uv(mu, roughness, size=catalog.ENERGY_SIZE):
    """(u, v) of the energy tables: u from roughness, v from mu."""
    return lut_coordinate(roughness, size), lut_coordinate(mu, size)


def ltc_lut_uv(mu, roughness, size=catalog.LTC_SIZE):
    """(u, v) of the LTC tables: u from roughness, v from sqrt(1 - mu) (docs/luts.md)."""
    return lut_coordinate(roughness, size), lut_coordinate(op.sqrt(1.0 - op.saturate(mu)), size)


class _FolderTables(Mapping):
    """The catalog's tables in one folder, each read (and verified) on first use."""

    def __init__(self, lut_dir, names):
        self.lut_dir = Path(lut_dir)
        self._names = tuple(names)
        self._loaded = {}

    def __getitem__(self, name):
        table = self._loaded.get(name)
        if table is None:
            if name not in self._names:
                raise KeyError(name)
            spec = catalog.TABLES[name]
            path = self.lut_dir / spec.filename
            data, _ = exr_io.read_table(path, spec.name, spec.shape)
            table = self._loaded[name] = Table(name, spec.height, spec.width, data, path)
        return table

    def __iter__(self):
        return iter(self._names)

    def __len__(self):
        return len(self._names)


class LutSet(Mapping):
    """A table set (name -> ``core.ir.tables.Table``) with the lookups of the baked LUTs.

    ``LutSet.from_folder(path)`` reads the catalog's tables from a folder on first use;
    ``LutSet.references()`` (``REFERENCES``) gives them without data, for tracing;
    ``with_tables(...)`` adds other tables (a baked environment) to a copy."""

    def __init__(self, tables, lut_dir=None):
        self._tables = tables
        self.lut_dir = Path(lut_dir) if lut_dir is not None else None

    @classmethod
    def from_folder(cls, lut_dir=None, names=None):
        """The catalog's tables (or ``names``) in ``lut_dir`` (default: the shipped ``luts/``)."""
        lut_dir = Path(lut_dir) if lut_dir is not None else catalog.default_lut_dir()
        return cls(_FolderTables(lut_dir, names or catalog.TABLES), lut_dir)

    @classmethod
    def references(cls):
        return cls({name: Table(name, spec.height, spec.width) for name, spec in catalog.TABLES.items()})

    def with_tables(self, *tables):
        extra = {t.name: t for t in tables}
        return LutSet(_Chain(extra, self._tables), self.lut_dir)

    def __getitem__(self, name):
        return self._tables[name]

    def __iter__(self):
        return iter(self._tables)

    def __len__(self):
        return len(self._tables)

    def array(self, name):
        """The data of table ``name``, (H, W, 4) float32."""
        return self[name].require_data()

    # -- GGX energy (Kulla & Conty 2017; Karis 2013) ----------------------------------------------
    def one_minus_e(self, mu, roughness):
        """1 - E(mu, r) of single-scattering GGX with F = 1 (table ggx_one_minus_E, channel R)."""
        u, v = energy_lut_uv(mu, roughness)
        return op.lut_sample(self["ggx_one_minus_E"], u, v, 0)

    def e(self, mu, roughness):
        return 1.0 - self.one_minus_e(mu, roughness)

    def one_minus_e_avg(self, roughness):
        """1 - E_avg(r) (table ggx_one_minus_E_avg, one row read at v = 0.5)."""
        u = lut_coordinate(roughness, catalog.ENERGY_SIZE)
        return op.lut_sample(self["ggx_one_minus_E_avg"], u, 0.5 + 0.0 * u, 0)

    def e_avg(self, roughness):
        return 1.0 - self.one_minus_e_avg(roughness)

    def split_sum(self, mu, roughness):
        """(scale A, bias B) of the split-sum environment BRDF at (mu, r) (table ggx_split_sum)."""
        u, v = energy_lut_uv(mu, roughness)
        table = self["ggx_split_sum"]
        return op.lut_sample(table, u, v, 0), op.lut_sample(table, u, v, 1)

    # -- LTC (Heitz et al. 2016; Hill 2016) --------------------------------------------------------
    def ltc(self, prefix, mu, roughness, band_weight=False):
        """((c0, c1, c2, c3), magnitude, fresnel) of the LTC tables ``prefix`` at (mu, r): the packed
        Minv entries (``core.ltc.matrix``) and the lobe's magnitude and Fresnel channels; with
        ``band_weight`` a fourth value, the band's weight (channel B of the ``_mag`` table; 0 for a lobe
        without a band, ``catalog.LTC_BANDS``)."""
        u, v = ltc_lut_uv(mu, roughness)
        inv, mag = self[prefix + "_inv"], self[prefix + "_mag"]
        if not is_expr(u, v):                   # numpy: one bilinear read per table
            packed = sample_bilinear(inv.require_data(), u, v)
            m = sample_bilinear(mag.require_data(), u, v)
            return (tuple(packed[..., i] for i in range(4)), m[..., 0], m[..., 1]) + ((m[..., 2],) if band_weight else ())
        return ((tuple(op.lut_sample(inv, u, v, i) for i in range(4)), op.lut_sample(mag, u, v, 0),
                 op.lut_sample(mag, u, v, 1)) + ((op.lut_sample(mag, u, v, 2),) if band_weight else ()))

    # -- Zeltner 2022 sheen, as Cycles shades it (core/sheen.py) ------------------------------------
    def zeltner_sheen(self, mu, roughness):
        """(a, b, albedo) of the sheen LTC at (mu, r) (table zeltner_sheen; r is the caller's, clamped as
        Cycles does by ``core.sheen.zeltner_roughness``); nodes at i/31 on both axes, as Cycles' table."""
        size = catalog.ZELTNER_SHEEN_SIZE
        u, v = lut_coordinate(roughness, size), lut_coordinate(mu, size)
        table = self["zeltner_sheen"]
        if not is_expr(u, v):
            m = sample_bilinear(table.require_data(), u, v)
            return m[..., 0], m[..., 1], m[..., 2]
        return tuple(op.lut_sample(table, u, v, i) for i in range(3))

    def zeltner_sheen_moments(self, mu, roughness):
        """((E[x], E[z], E[x z]), (E[x^2], E[y^2], E[z^2])) of the sheen LTC at (mu, r) in the local frame
        (tables zeltner_sheen_sh1, zeltner_sheen_sh2; r clamped by the caller as for ``zeltner_sheen``)."""
        size = catalog.ZELTNER_SHEEN_SIZE
        u, v = lut_coordinate(roughness, size), lut_coordinate(mu, size)
        out = []
        for name in ("zeltner_sheen_sh1", "zeltner_sheen_sh2"):
            table = self[name]
            if not is_expr(u, v):
                m = sample_bilinear(table.require_data(), u, v)
                out.append((m[..., 0], m[..., 1], m[..., 2]))
            else:
                out.append(tuple(op.lut_sample(table, u, v, i) for i in range(3)))
        return tuple(out)

    def sphere_table(self, prefix="ltc_ggx"):
        """The horizon-clipped sphere table: the ``prefix_mag`` table, whose channel A
        (``core.ltc.sphere_table.SPHERE_CHANNEL``) holds it on its own axes; every ``*_mag`` table
        carries the same one, so shader code reads ``ltc_ggx_mag``'s and one image serves all lobes."""
        return self[prefix + "_mag"]


class _Chain(Mapping):
    def __init__(self, *maps):
        self._maps = maps

    def __getitem__(self, name):
        for m in self._maps:
            if name in m:
                return m[name]
        raise KeyError(name)

    def __iter__(self):
        seen = []
        for m in self._maps:
            seen += [k for k in m if k not in seen]
        return iter(seen)

    def __len__(self):
        return len(list(iter(self)))


#: The catalog's tables without data: what traced shading code reads (``NodeFunction(tables=...)``).
REFERENCES = LutSet.references()
