"""What checks and benchmarks write: JSON and Markdown results, EXR images, PNG previews and error maps, CSV, the
pieces of the HTML reports; and where (``REPO``, ``BENCHMARKS``)."""
from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

from . import exr_images, png

#: The checkout's root and the folder of the benchmarks' committed results.
REPO = Path(__file__).resolve().parents[2]
BENCHMARKS = REPO / "docs" / "benchmarks"


def json_default(o):
    """``json.dumps(default=...)`` for numpy scalars and arrays and paths."""
    if isinstance(o, (np.bool_, np.integer, np.floating)):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    if isinstance(o, Path):
        return str(o)
    raise TypeError(f"not JSON serialisable: {type(o)}")


def write_exr(path, rgb):
    """(H, W, 3) float image (row 0 = top) as a 32-bit float RGB EXR; NaN written as 0."""
    return exr_images.write_rgb(path, rgb)


def preview_png(path, rgb, scale_value):
    """Display-referred preview: x / scale_value, clipped, sRGB-ish gamma; NaN shown dark red."""
    rgb = np.asarray(rgb, np.float64)
    nan = ~np.isfinite(rgb).all(axis=-1)
    v = np.clip(np.nan_to_num(rgb) / max(scale_value, 1e-12), 0.0, 1.0) ** (1 / 2.2)
    v[nan] = (0.15, 0.0, 0.0)
    png.write_rgb(path, v)
    return path


def error_png(path, err, vmax):
    """False-colour map of a per-pixel error (H, W) in [0, vmax] with a colour bar (top = vmax);
    pixels without a value (NaN) are white."""
    e = np.asarray(err, np.float64)
    png.heatmap(path, np.flipud(np.nan_to_num(e)), vmax, scale=1, bar_width=10)
    return path


def write_json(path, result, indent=1):
    """``result`` as JSON (numpy values and paths converted: ``json_default``)."""
    Path(path).write_text(json.dumps(result, indent=indent, default=json_default))


def write_results(folder, stem, result, markdown):
    """A benchmark's ``<stem>.md`` and ``<stem>.json`` in ``folder`` (made if needed); nothing when ``folder`` is
    None."""
    if folder is None:
        return
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    (folder / f"{stem}.md").write_text(markdown)
    (folder / f"{stem}.json").write_text(json.dumps(result, indent=1, default=json_default))


def write_csv(path, rows):
    keys = []
    for r in rows:
        for k in r:
            if k not in keys:
                keys.append(k)
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        for r in rows:
            w.writerow({k: _fmt_csv(r.get(k)) for k in keys})


def _fmt_csv(v):
    if isinstance(v, float):
        return f"{v:.6g}"
    return v


def percent(x, digits=2):
    """``x`` as a percentage with ``digits`` decimals; "-" for None."""
    return "-" if x is None else f"{100 * x:.{digits}f}%"


def median_p90(stats, digits=1):
    """"median / p90" of an error summary ({"values", "median", "p90"}) as percentages; "-" when it has no value."""
    if not stats or not stats.get("values"):
        return "-"
    return f"{percent(stats['median'], digits)} / {percent(stats['p90'], digits)}"


def scientific(x):
    """``x`` in scientific notation, 3 significant digits; "-" for None."""
    return "-" if x is None else f"{x:.2e}"


def html_verdict(flag):
    """An HTML "ok" / "FAIL" (nothing for None), styled by ``CSS``."""
    return "" if flag is None else ('<span class="ok">ok</span>' if flag else '<span class="fail">FAIL</span>')


#: The style of the HTML reports.
CSS = """
body{font-family:sans-serif;margin:1.5em;max-width:1400px}
table{border-collapse:collapse;margin:0.5em 0 1em 0;font-size:13px}
td,th{border:1px solid #bbb;padding:2px 6px;text-align:right}
th{background:#eee} td.l{text-align:left}
.ok{color:#070;font-weight:bold}.fail{color:#b00;font-weight:bold}
img{image-rendering:pixelated;border:1px solid #888;margin:2px;vertical-align:top}
figure{display:inline-block;margin:0 8px 8px 0}figcaption{font-size:12px}
"""
