"""A small OpenEXR reader for the LUT files this project writes, in pure Python + numpy.

Blender's bundled Python has no ``OpenEXR`` module, so the add-on reads its tables with
this when that import fails.  It supports what ``exr_io.write_table`` produces and Blender's own
scanline renders, and refuses anything else with a clear error: scanline images (single-part, or
multi-part as Blender's multilayer renders are), NO or ZIP(S) compression, FLOAT (32-bit) or HALF (16-bit) channels (all of one type), x/y sampling 1.  Attributes of type string, int,
float and double are decoded; others are kept as raw bytes.

Format: OpenEXR file layout (openexr.com, "OpenEXR File Layout"): magic 20000630, version
word, attributes (name\\0 type\\0 int32 size, value) ended by \\0, a uint64 offset per
chunk, then chunks (int32 y, int32 size, data).  ZIP chunks hold 16 scanlines (ZIPS 1),
deflated after a byte-delta predictor and an even/odd byte split; each scanline stores
the channels in alphabetical order.
"""
from __future__ import annotations

import struct
import zlib

import numpy as np

MAGIC = 20000630
_NO, _ZIPS, _ZIP = 0, 2, 3
_LINES_PER_CHUNK = {_NO: 1, _ZIPS: 1, _ZIP: 16}
_HALF, _FLOAT = 1, 2
_DTYPES = {_HALF: "<f2", _FLOAT: "<f4"}


class ExrFormatError(ValueError):
    pass


def _cstring(data, pos):
    end = data.index(b"\0", pos)
    return data[pos:end].decode("latin-1"), end + 1


def _parse_channels(value):
    channels, pos = [], 0
    while value[pos:pos + 1] != b"\0":
        name, pos = _cstring(value, pos)
        pixel_type, _p_linear, x_samp, y_samp = struct.unpack_from("<iB3xii", value, pos)
        pos += 16
        channels.append((name, pixel_type, x_samp, y_samp))
    return channels


def _decode_attribute(type_name, value):
    if type_name == "string":
        return value.decode("utf-8")
    if type_name == "int":
        return struct.unpack("<i", value)[0]
    if type_name == "float":
        return struct.unpack("<f", value)[0]
    if type_name == "double":
        return struct.unpack("<d", value)[0]
    if type_name == "chlist":
        return _parse_channels(value)
    if type_name in ("compression", "lineOrder"):
        return value[0]
    if type_name == "box2i":
        return struct.unpack("<4i", value)
    return value


def _unzip(data, expected):
    raw = np.frombuffer(zlib.decompress(data), dtype=np.uint8)
    if raw.size != expected:
        raise ExrFormatError(f"chunk inflates to {raw.size} bytes, expected {expected}")
    # undo the predictor: t[i] = t[i-1] + raw[i] - 128 (mod 256)
    t = (np.cumsum(np.concatenate([[raw[0]], raw[1:].astype(np.int64) - 128])) & 0xFF).astype(np.uint8)
    half = (raw.size + 1) // 2
    out = np.empty(raw.size, dtype=np.uint8)
    out[0::2] = t[:half]
    out[1::2] = t[half:]
    return out.tobytes()


def _read_header(data, pos):
    """(attributes, types, position after the header's terminating \\0) of one header."""
    attrs, types = {}, {}
    while data[pos:pos + 1] != b"\0":
        name, pos = _cstring(data, pos)
        type_name, pos = _cstring(data, pos)
        size = struct.unpack_from("<i", data, pos)[0]
        pos += 4
        attrs[name] = _decode_attribute(type_name, data[pos:pos + size])
        types[name] = type_name
        pos += size
    return attrs, types, pos + 1


def _layout(attrs):
    """(x0, y0, x1, y1, channels, dtype, lines per chunk, chunks) of one part, checked."""
    compression = attrs.get("compression")
    if compression not in _LINES_PER_CHUNK:
        raise ExrFormatError(f"unsupported compression {compression}")
    x0, y0, x1, y1 = attrs["dataWindow"]
    channels = sorted(attrs["channels"])
    types_used = {pixel_type for _, pixel_type, _, _ in channels}
    for name, pixel_type, xs, ys in channels:
        if pixel_type not in _DTYPES or xs != 1 or ys != 1 or len(types_used) != 1:
            raise ExrFormatError(f"channel {name}: only unsubsampled 32-bit or 16-bit float channels, all of one "
                                 "type, are supported")
    lines = _LINES_PER_CHUNK[compression]
    return x0, y0, x1, y1, channels, np.dtype(_DTYPES[types_used.pop()]), lines, (y1 - y0 + lines) // lines


def _read_part(data, offsets, layout, compression, multipart, planes):
    x0, y0, x1, y1, channels, dtype, lines, _ = layout
    width = x1 - x0 + 1
    for name, *_ in channels:
        planes[name] = np.empty((y1 - y0 + 1, width), dtype="<f4")
    for offset in offsets:
        if multipart:                      # each chunk starts with its part number
            offset += 4
        y, size = struct.unpack_from("<ii", data, offset)
        chunk = data[offset + 8:offset + 8 + size]
        rows = min(lines, y1 + 1 - y)
        expected = rows * width * dtype.itemsize * len(channels)
        if compression != _NO and size < expected:
            chunk = _unzip(chunk, expected)
        if len(chunk) != expected:
            raise ExrFormatError(f"chunk at line {y}: {len(chunk)} bytes, expected {expected}")
        block = np.frombuffer(chunk, dtype=dtype).reshape(rows, len(channels), width)
        for c, (name, *_) in enumerate(channels):
            planes[name][y - y0:y - y0 + rows] = block[:, c]


def read(path):
    """Return (attributes dict, {channel name: (H, W) float32 array, top row first}).  A multi-part file
    (Blender's multilayer renders) gives the channels of every part and the first part's attributes."""
    with open(path, "rb") as f:
        data = f.read()
    if len(data) < 8 or struct.unpack_from("<i", data, 0)[0] != MAGIC:
        raise ExrFormatError("not an OpenEXR file (bad magic number)")
    version = struct.unpack_from("<i", data, 4)[0]
    if version & 0xFF != 2 or version & 0xA00:   # tiled / deep bits (0x400 long names, 0x1000 multi-part: read)
        raise ExrFormatError(f"unsupported EXR flavour (version word {version:#x})")
    multipart = bool(version & 0x1000)
    headers, pos = [], 8
    while True:                           # multi-part: headers, then an empty one (a lone \0)
        attrs, _, pos = _read_header(data, pos)
        headers.append(attrs)
        if not multipart or data[pos:pos + 1] == b"\0":
            pos += 1 if multipart else 0
            break
    layouts = [_layout(h) for h in headers]
    planes = {}
    for attrs, layout in zip(headers, layouts):
        n_chunks = layout[-1]
        offsets = struct.unpack_from(f"<{n_chunks}Q", data, pos)
        pos += 8 * n_chunks
        _read_part(data, offsets, layout, attrs["compression"], multipart, planes)
    attrs = dict(headers[0])
    attrs["channels"] = [name for name in planes]
    return attrs, planes
