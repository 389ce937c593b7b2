"""GPU texture containers for RGBA float tables: KTX 2.0 and DDS with the DX10 header, written and read
in pure Python + numpy (no library that writes float KTX2 installs here: ``pyktx``, Khronos' binding,
has no wheel for CPython 3.11 / 3.13 and needs KTX-Software built from source; see README,
"Dependencies").  Both hold one 2D image, one mip level, four channels of 16-bit or 32-bit IEEE floats,
rows in memory order (the first row of the data is table row 0).

KTX 2.0 (Khronos, "KTX File Format Specification", version 2.0; section numbers below are its):
- 3.1 identifier ``«KTX 20»\\r\\n\\x1A\\n``; 3.2 header: vkFormat (``VK_FORMAT_R16G16B16A16_SFLOAT`` = 97 or
  ``VK_FORMAT_R32G32B32A32_SFLOAT`` = 109), typeSize (2 or 4), pixelWidth, pixelHeight, pixelDepth 0,
  layerCount 0, faceCount 1, levelCount 1, supercompressionScheme 0 (all uint32 little-endian);
- 3.3 index: dfdByteOffset, dfdByteLength, kvdByteOffset, kvdByteLength (uint32), sgdByteOffset,
  sgdByteLength (uint64, 0: no supercompression data); 3.4 level index: byteOffset, byteLength,
  uncompressedByteLength (uint64) of the one level;
- 3.5 data format descriptor: uint32 dfdTotalSize, then one Khronos Basic Data Format Descriptor Block
  (Khronos Data Format Specification 1.3, section 5): vendorId 0 | descriptorType 0, versionNumber 2 |
  descriptorBlockSize 24 + 16 x 4, colorModel RGBSDA (1), colorPrimaries BT709 (1), transferFunction
  LINEAR (1), flags 0, texelBlockDimension 0 (1 x 1 x 1 x 1), bytesPlane0 = texel size, then per channel
  a sample: bitOffset (16 bits) | bitLength - 1 (8) | channelType (4: R 0, G 1, B 2, A 15) | qualifiers
  (4: FLOAT 0x8, SIGNED 0x4), samplePosition 0, sampleLower -1.0 and sampleUpper 1.0 as float32 bit
  patterns (section 5.18: floating-point samples store their bounds as float32);
- 3.6 key/value data: ``uint32 keyAndValueByteLength, key\\0value, padding to 4`` sorted by key;
  ``KTXorientation`` = "rd" (rows of the data go down: row 0 first), ``KTXwriter``, and the project's
  own keys (``rtl.*``: table name, layout, the manifest entry as JSON);
- 3.9 mip level data aligned to lcm(texel block size, 4) = the texel size (8 or 16 bytes).

DDS (Microsoft, "DDS_HEADER", "DDS_PIXELFORMAT", "DDS_HEADER_DXT10" structure reference): magic
``"DDS "``; DDS_HEADER (124 bytes): dwSize 124, dwFlags CAPS | HEIGHT | WIDTH | PITCH | PIXELFORMAT,
dwHeight, dwWidth, dwPitchOrLinearSize = width x texel size, dwDepth 0, dwMipMapCount 1, 11 reserved,
DDS_PIXELFORMAT (32 bytes: dwSize 32, dwFlags DDPF_FOURCC, dwFourCC "DX10", zero masks), dwCaps
DDSCAPS_TEXTURE, zeros; DDS_HEADER_DXT10 (20 bytes): dxgiFormat (``DXGI_FORMAT_R16G16B16A16_FLOAT`` = 10 or
``DXGI_FORMAT_R32G32B32A32_FLOAT`` = 2), resourceDimension TEXTURE2D (3), miscFlag 0, arraySize 1,
miscFlags2 DDS_ALPHA_MODE_CUSTOM (4: alpha is data, not coverage); then the rows, first row first.
"""
from __future__ import annotations

import json
import struct

import numpy as np

KTX2_IDENTIFIER = b"\xabKTX 20\xbb\r\n\x1a\n"
VK_FORMATS = {np.dtype("<f2"): 97, np.dtype("<f4"): 109}        # R16G16B16A16_SFLOAT, R32G32B32A32_SFLOAT
DXGI_FORMATS = {np.dtype("<f2"): 10, np.dtype("<f4"): 2}        # R16G16B16A16_FLOAT, R32G32B32A32_FLOAT
_DFD_CHANNELS = (0, 1, 2, 15)                                   # KHR_DF_CHANNEL_RGBSDA_R, G, B, ALPHA
_DF_FLOAT_SIGNED = 0x8 | 0x4                                    # KHR_DF_SAMPLE_DATATYPE_FLOAT | SIGNED
_FLOAT_BITS = {-1.0: 0xBF800000, 1.0: 0x3F800000}


class ContainerError(ValueError):
    """A file that is not the container it claims to be; the message says which field is wrong."""


def _rgba(table, dtype):
    a = np.ascontiguousarray(np.asarray(table), dtype=np.dtype(dtype).newbyteorder("<"))
    if a.ndim != 3 or a.shape[2] != 4:
        raise ContainerError(f"expected an (H, W, 4) table, got {a.shape}")
    if a.dtype not in VK_FORMATS:
        raise ContainerError(f"only float16 and float32 tables are written, not {a.dtype}")
    return a


# --- KTX 2.0 -----------------------------------------------------------------------------------------

def _dfd(texel_bytes, channel_bits):
    samples = b""
    for i, channel in enumerate(_DFD_CHANNELS):
        word0 = (i * channel_bits) | ((channel_bits - 1) << 16) | ((channel | (_DF_FLOAT_SIGNED << 4)) << 24)
        samples += struct.pack("<4I", word0, 0, _FLOAT_BITS[-1.0], _FLOAT_BITS[1.0])
    block_size = 24 + len(samples)
    block = struct.pack("<IHHBBBB4B8B", 0, 2, block_size, 1, 1, 1, 0, 0, 0, 0, 0,
                        texel_bytes, 0, 0, 0, 0, 0, 0, 0) + samples
    return struct.pack("<I", 4 + len(block)) + block


def _key_values(values):
    out = b""
    for key in sorted(values):
        raw = values[key]
        data = key.encode() + b"\0" + (raw if isinstance(raw, bytes) else str(raw).encode() + b"\0")
        out += struct.pack("<I", len(data)) + data + b"\0" * (-len(data) % 4)
    return out


def ktx2_bytes(table, dtype="<f4", metadata=None, writer="RT Lookdev"):
    """A KTX 2.0 file holding ``table`` (H, W, 4; row 0 first) as RGBA ``dtype`` (float16 / float32);
    ``metadata``: extra key/value pairs (str values, NUL-terminated in the file)."""
    a = _rgba(table, dtype)
    h, w, _ = a.shape
    texel = a.dtype.itemsize * 4
    dfd = _dfd(texel, a.dtype.itemsize * 8)
    kvd = _key_values({"KTXorientation": "rd", "KTXwriter": writer, **(metadata or {})})
    header_size = 12 + 9 * 4 + 4 * 4 + 2 * 8 + 3 * 8
    dfd_offset = header_size
    kvd_offset = dfd_offset + len(dfd)
    data_offset = kvd_offset + len(kvd)
    data_offset += -data_offset % texel
    data = a.tobytes()
    head = KTX2_IDENTIFIER + struct.pack("<9I", VK_FORMATS[a.dtype], a.dtype.itemsize, w, h, 0, 0, 1, 1, 0)
    head += struct.pack("<4I2Q", dfd_offset, len(dfd), kvd_offset, len(kvd), 0, 0)
    head += struct.pack("<3Q", data_offset, len(data), len(data))
    body = head + dfd + kvd
    return body + b"\0" * (data_offset - len(body)) + data


def read_ktx2(data):
    """(table (H, W, 4) float32, key/value dict of str) of a file ``ktx2_bytes`` wrote; every header field
    is checked against what this exporter writes."""
    if data[:12] != KTX2_IDENTIFIER:
        raise ContainerError("not a KTX 2.0 file (identifier)")
    fmt, type_size, w, h, depth, layers, faces, levels, scheme = struct.unpack_from("<9I", data, 12)
    dtype = {v: k for k, v in VK_FORMATS.items()}.get(fmt)
    if dtype is None or type_size != dtype.itemsize:
        raise ContainerError(f"vkFormat {fmt} / typeSize {type_size}: not RGBA16F or RGBA32F")
    if (depth, layers, faces, levels, scheme) != (0, 0, 1, 1, 0):
        raise ContainerError(f"not one 2D level without supercompression: depth {depth}, layers {layers}, "
                             f"faces {faces}, levels {levels}, scheme {scheme}")
    dfd_off, dfd_len, kvd_off, kvd_len, _, _ = struct.unpack_from("<4I2Q", data, 48)
    offset, length, uncompressed = struct.unpack_from("<3Q", data, 80)
    if length != uncompressed or length != w * h * 4 * dtype.itemsize or offset % (4 * dtype.itemsize):
        raise ContainerError(f"level 0: offset {offset}, length {length}, expected {w * h * 4 * dtype.itemsize}")
    if data[dfd_off:dfd_off + dfd_len] != _dfd(4 * dtype.itemsize, 8 * dtype.itemsize):
        raise ContainerError("data format descriptor does not describe RGBA float samples")
    values, pos = {}, kvd_off
    while pos < kvd_off + kvd_len:
        (n,) = struct.unpack_from("<I", data, pos)
        key, _, value = data[pos + 4:pos + 4 + n].partition(b"\0")
        values[key.decode()] = value.rstrip(b"\0").decode()
        pos += 4 + n + (-n % 4)
    table = np.frombuffer(data, dtype, w * h * 4, offset).reshape(h, w, 4)
    return table.astype(np.float32), values


# --- DDS -------------------------------------------------------------------------------------------------

_DDSD = 0x1 | 0x2 | 0x4 | 0x8 | 0x1000               # CAPS | HEIGHT | WIDTH | PITCH | PIXELFORMAT
_DDPF_FOURCC = 0x4
_DDSCAPS_TEXTURE = 0x1000
_DX10_TEXTURE2D = 3
_DDS_ALPHA_MODE_CUSTOM = 4


def dds_bytes(table, dtype="<f4"):
    """A DDS file (DX10 header) holding ``table`` (H, W, 4; row 0 first) as RGBA ``dtype``."""
    a = _rgba(table, dtype)
    h, w, _ = a.shape
    pixel_format = struct.pack("<II4s5I", 32, _DDPF_FOURCC, b"DX10", 0, 0, 0, 0, 0)
    header = struct.pack("<7I44x", 124, _DDSD, h, w, w * 4 * a.dtype.itemsize, 0, 1) + pixel_format
    header += struct.pack("<5I", _DDSCAPS_TEXTURE, 0, 0, 0, 0)
    dx10 = struct.pack("<5I", DXGI_FORMATS[a.dtype], _DX10_TEXTURE2D, 0, 1, _DDS_ALPHA_MODE_CUSTOM)
    return b"DDS " + header + dx10 + a.tobytes()


def read_dds(data):
    """The table (H, W, 4) float32 of a file ``dds_bytes`` wrote; the header fields are checked."""
    if data[:4] != b"DDS ":
        raise ContainerError("not a DDS file (magic)")
    size, flags, h, w, pitch, _, _ = struct.unpack_from("<7I", data, 4)
    pf_size, pf_flags, fourcc = struct.unpack_from("<II4s", data, 76)
    if size != 124 or pf_size != 32 or not pf_flags & _DDPF_FOURCC or fourcc != b"DX10":
        raise ContainerError(f"header size {size}, pixel format {pf_size}/{pf_flags:#x}/{fourcc!r}: not a DX10 DDS")
    fmt, dim, _, array, _ = struct.unpack_from("<5I", data, 128)
    dtype = {v: k for k, v in DXGI_FORMATS.items()}.get(fmt)
    if dtype is None or dim != _DX10_TEXTURE2D or array != 1:
        raise ContainerError(f"dxgiFormat {fmt}, dimension {dim}, array size {array}: not one RGBA float 2D texture")
    if pitch != w * 4 * dtype.itemsize or len(data) < 148 + h * pitch:
        raise ContainerError(f"pitch {pitch} or length {len(data)} does not fit {w} x {h} RGBA texels")
    return np.frombuffer(data, dtype, w * h * 4, 148).reshape(h, w, 4).astype(np.float32)


def json_value(value):
    """A metadata value as compact JSON (for the KTX2 key/value data)."""
    return json.dumps(value, separators=(",", ":"), sort_keys=True)
