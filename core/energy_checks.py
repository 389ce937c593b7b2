"""Energy checks shared by the tests and the main job's report (numpy only).

Reference data: Cycles' own GGX albedo table, ``table_ggx_E`` / ``table_ggx_Eavg`` of
blender/cycles ``src/scene/shader.tables`` (unchanged v4.0 - v5.x), nodes copied from
docs/multiscattering.md, "Cycles' GGX albedo table".  Axes there: r = sqrt(alpha) at i/31, mu at j/31.
"""
from __future__ import annotations

import numpy as np

from . import energy, multiscatter

CYCLES_R = np.array([8, 16, 24, 31]) / 31
CYCLES_MU = np.array([4, 8, 16, 31]) / 31
#: rows: mu = CYCLES_MU, columns: r = CYCLES_R
CYCLES_E = np.array([[0.9074, 0.8732, 0.8140, 0.7201],
                     [0.9592, 0.8342, 0.7277, 0.5912],
                     [0.9873, 0.8474, 0.6394, 0.4438],
                     [0.9951, 0.9039, 0.5921, 0.3069]])
CYCLES_E_AVG = np.array([0.98581, 0.87087, 0.63107, 0.40914])


def kulla_conty_ms_albedo(tables, mu_o, roughness, f0=1.0, n=8192):
    """int f_ms(mu_o, mu_i) mu_i dw_i for the LUT-driven Kulla-Conty lobe.

    Midpoint rule in mu_i with n points (the lobe is piecewise linear in mu_i between table
    nodes, so the rule's error is O(n^-2) ~ 1e-8 at the default).  ``tables`` is a
    core.lut.lookup.EnergyTables.
    """
    mu_i = (np.arange(n) + 0.5) / n
    r = np.full(n, float(roughness))
    f_ms = multiscatter.kulla_conty_brdf(tables.one_minus_e(np.array([mu_o]), r[:1]),
                                         tables.one_minus_e(mu_i, r), tables.one_minus_e_avg(r[:1]), f0)
    return 2.0 * np.pi * float(np.mean(f_ms * mu_i))


def kulla_conty_furnace(tables, roughness, mu, n_samples=1 << 15):
    """E_ss (true integral) + E_ms (LUT lobe) - 1 for every (r, mu); shape (len(r), len(mu))."""
    e_ss = energy.directional_albedo(mu, roughness, n_samples)
    e_ms = np.array([[kulla_conty_ms_albedo(tables, m, r) for m in mu] for r in roughness])
    return e_ss + e_ms - 1.0


def cycles_table_comparison(tables):
    """Our E (integrator and LUT) and E_avg (LUT) against Cycles' table nodes."""
    R, M = np.meshgrid(CYCLES_R, CYCLES_MU)
    integrated = energy.directional_albedo(CYCLES_MU, CYCLES_R, 1 << 14).T
    return {
        "max_abs_diff_E_integrated": float(np.max(np.abs(integrated - CYCLES_E))),
        "max_abs_diff_E_lut": float(np.max(np.abs(tables.e(M, R) - CYCLES_E))),
        "max_abs_diff_E_avg_lut": float(np.max(np.abs(tables.e_avg(CYCLES_R) - CYCLES_E_AVG))),
        "E_avg_r1_lut": float(tables.e_avg(np.array([1.0]))[0]),
    }


def talk_polynomial_furnace(raw_tables):
    """The talk's AverageEnergy(smoothness) fit against the table's E_avg, and its furnace error.

    ``raw_tables``: table name -> (H, W, 4) array (as read or baked).  The furnace uses E from
    the table and E_avg from the fit: E + (1 - E)(1 - E_avg_table)/(1 - E_avg_fit) - 1.
    """
    size = raw_tables["ggx_one_minus_E_avg"].shape[1]
    nodes = np.arange(size) / (size - 1)
    e_avg = 1.0 - raw_tables["ggx_one_minus_E_avg"][0, :, 0].astype(np.float64)
    poly = multiscatter.average_energy_polynomial_talk(1.0 - nodes)
    diff = poly - e_avg
    worst = int(np.argmax(np.abs(diff)))
    one_minus_e = raw_tables["ggx_one_minus_E"][..., 0].astype(np.float64)          # (mu, r)
    mu = nodes
    furnace = (1.0 - one_minus_e) + one_minus_e * (1.0 - e_avg) / (1.0 - poly)   # E + E_ms with the fit
    furnace_err = furnace - 1.0
    per_r = []
    for i in range(0, size, 4):
        sel = mu >= 0.1
        per_r.append({"r": float(nodes[i]), "max_err_mu_ge_0.1": float(np.max(np.abs(furnace_err[sel, i]))),
                      "grazing_mu": float(mu[2]), "err_at_grazing_mu": float(furnace_err[2, i])})
    return {"max_abs_err_vs_table": float(np.abs(diff[worst])), "at_r": float(nodes[worst]),
            "clamped_below_r": float(nodes[poly >= 0.999].max()) if np.any(poly >= 0.999) else None,
            "furnace_with_polynomial": per_r,
            "furnace_max_err_mu_ge_0.1": float(np.max(np.abs(furnace_err[mu >= 0.1]))),
            "furnace_with_table_e_avg": "exact to rounding (tests/core/test_multiscatter.py)"}
