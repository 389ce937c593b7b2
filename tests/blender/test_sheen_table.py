"""The shipped Zeltner sheen table (luts/zeltner_sheen.exr) against Cycles, re-measured.

A few cells are rendered again in Cycles (validation/benchmarks/sheen_table.py: Sheen BSDF "Microfiber", one sun of
angle 0 at a time, 1 sample, direct light: each pixel is f cos exactly) and compared with RT Lit's punctual
Zeltner lobe (core/sheen.py with the shipped table's bilinear lookup) at the same directions:
- cells at table nodes: the refitted (a, b, albedo) equal the stored ones (measured: <= 1e-6 relative; the
  fit's residual 1.3e-7 to 2.1e-7, 2.5e-5 at mu = 1, where Cycles' tangent frame is arbitrary and b ~ 5e-5);
- cells between nodes (bilinear interpolation, Cycles' ``lookup_table_read_2D``) and next to the r = 0
  column (solved from r = 0.5/31): f cos per direction agrees (measured: median 2e-7, max 4e-6 relative
  where f cos is above 1e-3 of the cell's peak, 8.1e-5 at mu = 0.999, 5.2e-5 at mu = 1), we allow 2e-4;
- the table file states its provenance (the Blender version it was measured with).
~1 s of renders (16 cells x 30 suns, 4 x 4 pixels).
"""
from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("OpenEXR")

from rt_lookdev.core import sheen  # noqa: E402
from rt_lookdev.core.lut import catalog, exr_io  # noqa: E402
from rt_lookdev.core.lut.lookup import LutSet  # noqa: E402
from rt_lookdev.validation.benchmarks import sheen_table  # noqa: E402

pytestmark = pytest.mark.blender

# (mu, r): nodes (i/31) in the first row, then points between nodes and next to r = 0
CELLS = np.array([[[5 / 31, 10 / 31], [0.0, 16 / 31], [20 / 31, 31 / 31], [1.0, 25 / 31]],
                  [[0.123, 0.456], [0.7, 0.21], [0.05, 0.93], [0.9, 0.77]],
                  [[0.31, 0.6], [0.02, 0.015], [0.4, 0.03], [0.15, 0.0]],
                  [[0.999, 0.5], [0.5, 0.999], [0.66, 0.33], [0.01, 0.99]]])


@pytest.fixture(scope="module")
def rendered():
    return sheen_table.render_lobe(CELLS, sheen_table.sun_directions())


def _ours(cells, directions):
    tables = LutSet.from_folder(names=["zeltner_sheen"])
    mu, r = cells[..., 0], cells[..., 1]
    a, b, albedo = tables.zeltner_sheen(mu, sheen.zeltner_roughness(r))
    local = sheen_table.local_directions(sheen_table.cell_normals(mu)[..., None, :], directions)
    value = sheen.zeltner_density(local[..., 0], local[..., 1], local[..., 2], a[..., None], b[..., None])
    keep = sheen.zeltner_active(a, albedo)[..., None]
    return np.where(keep, value * albedo[..., None], 0.0)


def test_table_matches_cycles(rendered):
    values, directions, seconds = rendered
    ours = _ours(CELLS, directions)
    peak = values.max(axis=-1, keepdims=True)
    lit = values > 1e-3 * peak
    rel = np.abs(ours - values)[lit] / values[lit]
    print(f"\n[sheen table] {int(lit.sum())} lit samples of {values.size}: max relative difference of f cos "
          f"{rel.max():.2e}, median {np.median(rel):.2e}; renders {seconds:.2f} s")
    assert lit.sum() > 250
    assert rel.max() < 2e-4
    # where Cycles drops the lobe (albedo < 1e-5) ours is 0 or negligible too
    assert np.all(np.abs(ours - values)[~lit] <= 1e-3 * np.maximum(peak, 1e-6).repeat(values.shape[-1], -1)[~lit])


def test_nodes_refit(rendered):
    values, directions, _ = rendered
    table = LutSet.from_folder(names=["zeltner_sheen"]).array("zeltner_sheen")
    for i, (mu, r) in enumerate(CELLS[0]):
        local = sheen_table.local_directions(sheen_table.cell_normals(mu)[None], directions)
        a, b, albedo, residual, used = sheen_table.fit_cell(local, values[0, i])
        stored = table[int(round(mu * 31)), int(round(r * 31))]
        assert used >= 3 and residual < 1e-4
        np.testing.assert_allclose([a, b, albedo], stored[:3], rtol=2e-5, atol=2e-6)


def test_provenance():
    spec = catalog.TABLES["zeltner_sheen"]
    meta = exr_io.read_header(catalog.default_lut_dir() / spec.filename)
    assert meta["blender_version"].startswith(catalog.MEASURED_GROUPS["zeltner_sheen"].params["source"].split()[-1])
    assert "Zeltner" in meta["provenance"]


def test_ashikhmin_velvet_formula_matches_cycles():
    """validation/harness/velvet.py's reading of Cycles' Sheen BSDF "Ashikhmin" (the velvet RT Lit's cloth is compared
    with in docs/sheen.md) against renders of it (measured: max 1.7e-5 relative where f cos > 1e-3 of the cell's
    peak)."""
    from rt_lookdev.validation.harness import velvet

    cells = np.array([[[0.3, 0.3], [0.6, 0.5], [0.9, 0.8], [0.15, 0.65]]])
    values, directions, _ = sheen_table.render_lobe(cells, sheen_table.sun_directions(), distribution="ASHIKHMIN")
    mu, sigma = cells[..., 0], cells[..., 1]
    local = sheen_table.local_directions(sheen_table.cell_normals(mu)[..., None, :], directions)
    view = np.stack([np.sqrt(1 - mu * mu), 0 * mu, mu], -1)[..., None, :]
    ours = velvet.cycles_velvet_f_cos(local, np.broadcast_to(view, local.shape), sigma[..., None])
    lit = values > 1e-3 * values.max(axis=-1, keepdims=True)
    rel = np.abs(ours - values)[lit] / values[lit]
    print(f"\n[velvet] {int(lit.sum())} lit samples: max relative difference {rel.max():.2e}")
    assert lit.sum() > 40 and rel.max() < 1e-4
