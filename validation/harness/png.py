"""Minimal PNG output for reports (stdlib zlib only): heat maps with a colour bar.

PNG format: W3C "Portable Network Graphics (PNG) Specification", chunks IHDR/IDAT/IEND,
8-bit RGB, filter type 0 per scanline.
"""
from __future__ import annotations

import struct
import zlib

import numpy as np

# A perceptually ordered ramp (dark blue -> teal -> yellow), piecewise linear in 5 stops.
_STOPS = np.array([[0.05, 0.03, 0.30], [0.13, 0.35, 0.60], [0.13, 0.60, 0.55], [0.55, 0.80, 0.30],
                   [0.99, 0.91, 0.15]])


def colormap(x):
    """Map values in [0, 1] to RGB in [0, 1]."""
    x = np.clip(np.nan_to_num(np.asarray(x, dtype=np.float64)), 0.0, 1.0) * (len(_STOPS) - 1)
    i = np.minimum(np.floor(x).astype(int), len(_STOPS) - 2)
    f = (x - i)[..., None]
    return _STOPS[i] * (1 - f) + _STOPS[i + 1] * f


def write_rgb(path, rgb):
    """Write an (H, W, 3) float image in [0, 1] as an 8-bit PNG (row 0 at the top)."""
    img = (np.clip(rgb, 0, 1) * 255 + 0.5).astype(np.uint8)
    h, w, _ = img.shape
    raw = b"".join(b"\x00" + img[y].tobytes() for y in range(h))

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n")
        f.write(chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0)))
        f.write(chunk(b"IDAT", zlib.compress(raw, 9)))
        f.write(chunk(b"IEND", b""))


def heatmap(path, values, vmax, scale=6, bar_width=12):
    """Write values (H, W) (row 0 = bottom, as tables are indexed) scaled to [0, vmax], with a
    vertical colour bar on the right (bottom = 0, top = vmax).  Returns the path."""
    v = np.flipud(np.asarray(values, dtype=np.float64)) / vmax
    img = np.repeat(np.repeat(colormap(v), scale, axis=0), scale, axis=1)
    h = img.shape[0]
    bar = colormap(np.linspace(1, 0, h))[:, None, :].repeat(bar_width, axis=1)
    gap = np.ones((h, 4, 3))
    write_rgb(path, np.concatenate([img, gap, bar], axis=1))
    return path
