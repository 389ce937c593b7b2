"""Load the published GGX LTC table of selfshadow/ltc_code (for comparisons only; never shipped).

The anchor file (../shared/anchors/ltc_code_ggx_table.txt, a sibling of the repository) holds two
sections of 4096 lines "t a c0 c1 c2 c3" (its header documents the layout; docs/area_lights.md,
"Table layout"): ltc_1 = packed Minv (c0 = Minv_xx, c1 = Minv_zx, c2 = Minv_xz,
c3 = Minv_zz), ltc_2 = (magnitude, fresnel, 0, sphere table on its own axes).  t is the view
axis (sqrt(1 - cos theta)), a the roughness axis.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

DEFAULT_PATH = Path(__file__).resolve().parents[3] / "shared" / "anchors" / "ltc_code_ggx_table.txt"
SIZE = 64


def _section(lines, name):
    start = next(i for i, line in enumerate(lines) if line.startswith(f"# BEGIN {name}"))
    end = next(i for i, line in enumerate(lines) if line.startswith(f"# END {name}"))
    rows = np.array([line.split() for line in lines[start + 1:end]], dtype=np.float64)
    table = np.zeros((SIZE, SIZE, 4))
    table[rows[:, 0].astype(int), rows[:, 1].astype(int)] = rows[:, 2:6]
    return table


def load_anchor(path=None):
    """(ltc1, ltc2), each (64, 64, 4) indexed [t, a]; FileNotFoundError if the file is absent."""
    lines = Path(path or DEFAULT_PATH).read_text().splitlines()
    return _section(lines, "ltc_1"), _section(lines, "ltc_2")
