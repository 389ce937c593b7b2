"""Float images as EXR files: what the validation writes (previews of passes, constant worlds) and reads
(Cycles / EEVEE renders).  One reader and one writer for the whole package.

With the OpenEXR package (the development environment pins it) files are read and written with it;
without it (Blender's bundled Python) the project's own pure-numpy reader and writer serve
(``core.lut.exr_reader`` / ``exr_writer``: single-part scanline, NO / ZIP, 32-bit float), which cover
what Blender writes for the measurement settings (``engines.output_settings``: ZIP, 32-bit).
Arrays are (H, W[, C]) with row 0 at the top, as the files store them.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np


def _openexr():
    try:
        import OpenEXR
    except ImportError:
        return None
    return OpenEXR


def read_channels(path):
    """{channel name: (H, W) float32} of every part of an EXR file (multilayer names kept, e.g.
    "ViewLayer.Combined.R")."""
    exr = _openexr()
    if exr is None:
        from ...core.lut import exr_reader

        _, planes = exr_reader.read(path)
        return {k: np.asarray(v, np.float32) for k, v in planes.items()}
    with exr.File(str(path), separate_channels=True) as f:
        return {n: np.array(c.pixels, dtype=np.float32) for p in f.parts for n, c in p.channels.items()}


def read_layer(path, layer="", components="RGB"):
    """Channels ``<layer>.<c>`` (or bare ``<c>`` for layer "") stacked as (H, W, len(components))."""
    ch = read_channels(path)
    names = [f"{layer}.{c}" if layer else c for c in components]
    missing = [n for n in names if n not in ch]
    if missing:
        raise KeyError(f"{path}: no channels {missing} (has {sorted(ch)})")
    return np.stack([ch[n] for n in names], axis=-1)


def find_pass(channels, pass_name, components):
    """The pass ``pass_name`` of a multilayer render, whatever its view layer: (H, W, C) float32."""
    keys = [k for k in channels if k.endswith(f".{pass_name}.{components[0]}")]
    if not keys:
        raise KeyError(f"no {pass_name} pass (channels: {sorted(channels)})")
    prefix = keys[0][: -len(components[0])]
    return np.stack([channels[prefix + c] for c in components], axis=-1)


def write_rgb(path, rgb):
    """(H, W, 3) float image (row 0 = top) as a 32-bit float RGB EXR, ZIP; NaN written as 0."""
    rgb = np.nan_to_num(np.asarray(rgb, np.float32), nan=0.0)
    exr = _openexr()
    if exr is None:
        from ...core.lut import exr_writer

        exr_writer.write(path, {c: np.ascontiguousarray(rgb[..., i]) for i, c in enumerate("RGB")})
        return Path(path)
    header = {"compression": exr.ZIP_COMPRESSION, "type": exr.scanlineimage}
    with exr.File(header, {"RGB": np.ascontiguousarray(rgb)}) as f:
        f.write(str(path))
    return Path(path)


def object_index_pass(channels):
    """The Object Index pass: "IndexOB" in the EXR of Blender 4.5, "Object Index" from 5.0 on (measured with
    the pinned wheels)."""
    try:
        return find_pass(channels, "Object Index", "X")
    except KeyError:
        return find_pass(channels, "IndexOB", "X")
