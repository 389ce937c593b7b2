"""A small OpenEXR writer for the LUT files this project writes, in pure Python + numpy + zlib.

Blender's bundled Python has no ``OpenEXR`` module, so ``exr_io.write_table`` writes with this
when that import fails (baking a world's environment from inside Blender, for instance).  It
writes one flavour only: a single-part scanline image, 32-bit FLOAT (or 16-bit HALF, ``pixel_type="half"``)
channels with x/y sampling 1,
INCREASING_Y line order, NO, ZIPS or ZIP compression (ZIP by default, as ``write_table`` uses with
the OpenEXR package).  Attributes: the required ones (channels, compression, dataWindow,
displayWindow, lineOrder, pixelAspectRatio, screenWindowCenter, screenWindowWidth), ``type`` =
"scanlineimage" as the OpenEXR package writes it, and user attributes of type string (``str``),
int (``int``/``bool``) or float (``float``), the attribute types the OpenEXR Python bindings
(3.x) choose for those Python values: ints as 32-bit ``int``, floats rounded to 32-bit ``float``.

Format: OpenEXR file layout (openexr.com, "OpenEXR File Layout",
https://openexr.com/en/latest/OpenEXRFileLayout.html):

- magic number 20000630 (int32), version field (int32): version 2 in the low byte; bit 10
  ("long names") is set when an attribute or channel name is longer than 31 bytes;
- header: attributes ``name\\0 type\\0 int32 size value``, ended by a single ``\\0``; all integers
  and floats little-endian; ``chlist`` = per channel ``name\\0 int32 pixelType, uint8 pLinear,
  3 reserved zero bytes, int32 xSampling, int32 ySampling``, ended by ``\\0``, channels sorted by
  name (so RGBA is stored A, B, G, R);  ``box2i`` = int32 xMin, yMin, xMax, yMax;
- line offset table: one uint64 per scan-line block, the absolute file offset of the block;
- scan-line blocks: int32 y of the block's first line, int32 size of the data, data.  A block holds
  1 (NO, ZIPS) or 16 (ZIP) scan lines; within it each line stores every channel in turn (channel
  order of the chlist), each as ``width`` little-endian float32.  Compressed data (zlib stream) is
  that byte string reordered (the bytes at even positions first, then those at odd positions) and
  delta-coded (byte i becomes ``b[i] - b[i-1] + 128`` mod 256, byte 0 unchanged) before deflating;
  when that is not smaller than the raw block, the raw block is stored instead (a reader tells
  them apart by the size).

Readers: the OpenEXR library and ``exr_reader.py`` (tests/core/test_exr_writer.py).
"""
from __future__ import annotations

import struct
import zlib
from pathlib import Path

import numpy as np

MAGIC = 20000630
VERSION = 2
LONG_NAMES = 0x400
COMPRESSIONS = {"none": (0, 1), "zips": (2, 1), "zip": (3, 16)}   # name -> (code, lines per block)
_PIXEL_TYPES = {"half": (1, "<f2"), "float": (2, "<f4")}    # EXR pixel type code, numpy dtype
_INT32 = (-2**31, 2**31 - 1)
ZLIB_LEVEL = 6


class ExrWriteError(ValueError):
    pass


def _attribute(name, type_name, value):
    return name.encode() + b"\0" + type_name.encode() + b"\0" + struct.pack("<i", len(value)) + value


def attribute_value(name, value):
    """(type name, bytes) of a metadata value, with the attribute types the OpenEXR bindings use."""
    if isinstance(value, str):
        return "string", value.encode("utf-8")
    if isinstance(value, int):                    # bool included (stored 0/1, as the bindings do)
        if not _INT32[0] <= value <= _INT32[1]:
            raise ExrWriteError(f"attribute {name!r}: {value} does not fit an EXR int (32-bit)")
        return "int", struct.pack("<i", int(value))
    if isinstance(value, float):                  # numpy.float64 included; numpy.float32 is not a float
        with np.errstate(over="ignore"):          # beyond float32 range: inf, as the bindings store it
            return "float", np.array(value, dtype="<f4").tobytes()
    raise ExrWriteError(f"attribute {name!r}: unsupported value type {type(value).__name__} "
                        "(str, int or float; numpy scalars other than float64 are refused, as by the bindings)")


def _reorder_predict(raw):
    """The ZIP pre-pass: even-position bytes then odd-position bytes, then byte deltas + 128."""
    b = np.frombuffer(raw, dtype=np.uint8)
    t = np.concatenate([b[0::2], b[1::2]])
    out = t.copy()
    out[1:] = (t[1:].astype(np.int16) - t[:-1] + 128).astype(np.uint8)   # wraps mod 256
    return out.tobytes()


def encode(planes, attributes=None, compression="zip", pixel_type="float"):
    """The bytes of an EXR file holding ``planes`` ({channel name: (H, W) array, top row first},
    stored as float32, or float16 with ``pixel_type="half"``) and ``attributes`` ({name: str | int | float})."""
    if pixel_type not in _PIXEL_TYPES:
        raise ExrWriteError(f"pixel type {pixel_type!r}: expected one of {sorted(_PIXEL_TYPES)}")
    type_code, dtype = _PIXEL_TYPES[pixel_type]
    if compression not in COMPRESSIONS:
        raise ExrWriteError(f"compression {compression!r}: expected one of {sorted(COMPRESSIONS)}")
    code, lines = COMPRESSIONS[compression]
    if not planes:
        raise ExrWriteError("no channels")
    names = sorted(planes)
    arrays = [np.asarray(planes[n], dtype=dtype) for n in names]
    shape = arrays[0].shape
    if len(shape) != 2 or shape[0] < 1 or shape[1] < 1 or any(a.shape != shape for a in arrays):
        raise ExrWriteError(f"channels must be non-empty 2D arrays of one shape, got "
                            f"{[a.shape for a in arrays]}")
    height, width = shape
    box = struct.pack("<4i", 0, 0, width - 1, height - 1)
    chlist = b"".join(n.encode() + b"\0" + struct.pack("<iB3xii", type_code, 0, 1, 1) for n in names) + b"\0"
    header = {
        "channels": ("chlist", chlist),
        "compression": ("compression", bytes([code])),
        "dataWindow": ("box2i", box),
        "displayWindow": ("box2i", box),
        "lineOrder": ("lineOrder", b"\0"),                      # INCREASING_Y
        "pixelAspectRatio": ("float", struct.pack("<f", 1.0)),
        "screenWindowCenter": ("v2f", struct.pack("<2f", 0.0, 0.0)),
        "screenWindowWidth": ("float", struct.pack("<f", 1.0)),
        "type": ("string", b"scanlineimage"),
    }
    for name, value in (attributes or {}).items():
        if not isinstance(name, str) or not name or "\0" in name:
            raise ExrWriteError(f"attribute name {name!r}: expected a non-empty string")
        if name in header:
            raise ExrWriteError(f"attribute {name!r} is written by the writer itself")
        header[name] = attribute_value(name, value)
    longest = max(len(n.encode()) for n in list(header) + names)
    if longest > 255:
        raise ExrWriteError(f"attribute or channel name longer than 255 bytes ({longest})")
    version = VERSION | (LONG_NAMES if longest > 31 else 0)

    head = [struct.pack("<ii", MAGIC, version)]
    head += [_attribute(n, *header[n]) for n in sorted(header)]
    head.append(b"\0")
    head = b"".join(head)

    pixels = np.stack(arrays, axis=1)                   # (H, C, W): each line holds channel after channel
    blocks = []
    for y in range(0, height, lines):
        raw = pixels[y:y + lines].tobytes()
        data = raw
        if code != 0:
            packed = zlib.compress(_reorder_predict(raw), ZLIB_LEVEL)
            if len(packed) < len(raw):
                data = packed
        blocks.append(struct.pack("<ii", y, len(data)) + data)
    offsets, pos = [], len(head) + 8 * len(blocks)
    for block in blocks:
        offsets.append(pos)
        pos += len(block)
    return head + struct.pack(f"<{len(offsets)}Q", *offsets) + b"".join(blocks)


def write(path, planes, attributes=None, compression="zip", pixel_type="float"):
    """Write ``encode(planes, attributes, compression, pixel_type)`` to ``path`` (not atomically: callers
    that need that write a temporary name and rename, as ``exr_io.write_table`` does)."""
    data = encode(planes, attributes, compression, pixel_type)
    Path(path).write_bytes(data)
