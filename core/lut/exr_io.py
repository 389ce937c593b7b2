"""Read and write LUTs as 32-bit float RGBA OpenEXR files with descriptive metadata.

Orientation: tables are handled in numpy as ``table[j, i, c]`` with row j = node j of the v
axis counted from v = 0.  Blender samples image row j *from the bottom* at v = (j + 0.5)/H,
while an EXR file stores its top row first, so rows are flipped on write and on read
(docs/blender.md, "Tables as images").  Header attributes are prefixed ``rtl.``;
``rtl.content_hash`` is the SHA-256 of the float32 table (table orientation, RGBA
interleaved, little-endian), checked on every read.

Files are written and read with the OpenEXR package when it is importable, else with the
built-in pure-numpy writer and reader (exr_writer.py, exr_reader.py): Blender's bundled Python
has no OpenEXR module.  Either writer's files read back identically with either reader.
"""
from __future__ import annotations

import hashlib
import os
from pathlib import Path

import numpy as np

from . import exr_reader, exr_writer

CHANNELS = ("R", "G", "B", "A")
BAKE_COMMAND = "python scripts/bake_luts.py"


class LutError(RuntimeError):
    """A LUT file cannot be used; the message says which file and what to do."""


class LutMissingError(LutError):
    pass


class LutCorruptError(LutError):
    pass


class LutMismatchError(LutError):
    pass


class LutWriteError(LutError):
    """A LUT file cannot be written (a read-only folder, a full disk, a folder removed meanwhile)."""


WRITE_HINT = ("the LUT folder must be writable and stay in place while tables are written: choose another with "
              "--lut-dir or the add-on's LUT folder preference")


def content_hash(table):
    """SHA-256 of a (H, W, 4) table as little-endian float32."""
    data = np.ascontiguousarray(np.asarray(table, dtype="<f4"))
    return hashlib.sha256(data.tobytes()).hexdigest()


def write_table(path, table, metadata):
    """Write a (H, W, 4) table to ``path`` atomically; returns the content hash (``write_tables``)."""
    return write_tables([(path, table, metadata)])[0]


def write_tables(items):
    """Write [(path, (H, W, 4) table, metadata)] all or none: every file goes to ``<name>.<pid>.tmp`` first (its own
    name per process: two processes baking the same table never write into one file) and
    replaces its target only when all are written, so an interrupted or failed write leaves the previous
    files as they were and no partial file.  Returns the content hashes.  ``LutWriteError`` (naming the
    file, the cause and what to do) when a file cannot be written.

    ``metadata`` maps attribute names (without the ``rtl.`` prefix) to str (EXR ``string``), int
    (``int``, 32-bit; bool is stored as 0/1) or float (``float``, rounded to 32 bits).  Written with
    the OpenEXR package when it is importable, else with the built-in writer (exr_writer.py; Blender's
    bundled Python lacks the package): the same attributes, the same pixels, ZIP compression.
    """
    prepared = [_prepared(Path(path), table, metadata) for path, table, metadata in items]
    written = []
    try:
        for path, channels, attributes, _ in prepared:
            tmp = path.with_name(f"{path.name}.{os.getpid()}.tmp")
            written.append(tmp)
            try:
                path.parent.mkdir(parents=True, exist_ok=True)
                _write_exr(tmp, channels, attributes)
            except OSError as ex:
                raise LutWriteError(f"cannot write {path}: {ex.strerror or ex}; {WRITE_HINT}") from ex
        for (path, *_), tmp in zip(prepared, written):
            try:
                tmp.replace(path)
            except OSError as ex:
                raise LutWriteError(f"cannot replace {path}: {ex.strerror or ex}; {WRITE_HINT}") from ex
    except BaseException:
        for tmp in written:
            tmp.unlink(missing_ok=True)
        raise
    return [digest for *_, digest in prepared]


def _prepared(path, table, metadata):
    """(path, channels, attributes, content hash) of one table, checked before anything is written."""
    table = np.asarray(table, dtype=np.float32)
    if table.ndim != 3 or table.shape[2] != 4:
        raise ValueError(f"expected a (H, W, 4) table, got shape {table.shape}")
    if not np.all(np.isfinite(table)):
        raise ValueError(f"refusing to write non-finite values to {path}")
    digest = content_hash(table)
    attributes = {"rtl." + key: value for key, value in metadata.items()}
    attributes["rtl.content_hash"] = digest
    for name, value in attributes.items():       # the same checks whichever writer runs
        exr_writer.attribute_value(name, value)
    stored = np.flipud(table)
    channels = {name: np.ascontiguousarray(stored[:, :, c]) for c, name in enumerate(CHANNELS)}
    return path, channels, attributes, digest


def _write_exr(path, channels, attributes):
    """Write {name: (H, W) float32, top row first} and attributes, ZIP-compressed, with the OpenEXR
    package, or the built-in writer where it is absent."""
    try:
        import OpenEXR
    except ImportError:
        exr_writer.write(path, channels, attributes, compression="zip")
        return
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage, **attributes}
    with OpenEXR.File(header, channels) as exr:
        exr.write(str(path))


def read_header(path):
    """The ``rtl.`` attributes of an EXR file (prefix stripped).  Raises LutError subclasses."""
    return _open(path)[0]


def read_table(path, expected_table=None, expected_shape=None):
    """Read a table written by ``write_table`` and verify it.

    Returns (table (H, W, 4) float32, metadata).  Raises LutMissingError, LutCorruptError
    (unreadable file, missing channels, content hash mismatch) or LutMismatchError (the
    file holds another table or another size than expected).
    """
    meta, channels = _open(path, with_pixels=True)
    name = meta.get("table")
    if expected_table is not None and name != expected_table:
        raise LutMismatchError(
            f"{path}: holds table {name!r}, expected {expected_table!r}. "
            f"Re-bake with `{BAKE_COMMAND} --force`.")
    missing = [c for c in CHANNELS if c not in channels]
    if missing:
        raise LutCorruptError(f"{path}: channels {missing} missing. Re-bake with `{BAKE_COMMAND} --force`.")
    table = np.flipud(np.stack([channels[c] for c in CHANNELS], axis=-1)).astype(np.float32)
    if expected_shape is not None and table.shape[:2] != tuple(expected_shape):
        raise LutMismatchError(
            f"{path}: table {name!r} is {table.shape[1]}x{table.shape[0]}, expected "
            f"{expected_shape[1]}x{expected_shape[0]}. Re-bake with `{BAKE_COMMAND} --force`.")
    stored_hash = meta.get("content_hash")
    if stored_hash != content_hash(table):
        raise LutCorruptError(
            f"{path}: pixel data does not match its content hash (file damaged or edited). "
            f"Re-bake with `{BAKE_COMMAND} --force`.")
    return table, meta


def _read_exr(path, with_pixels):
    """(header, channels) with the OpenEXR package, or the built-in reader where it is absent
    (Blender's bundled Python has no OpenEXR module)."""
    try:
        import OpenEXR
    except ImportError:
        return exr_reader.read(path)
    with OpenEXR.File(str(path), separate_channels=True, header_only=not with_pixels) as exr:
        header = {k: v for k, v in exr.header().items()}  # the dict is cleared on close
        channels = ({n: np.array(ch.pixels) for n, ch in exr.channels().items()}
                    if with_pixels else {})
    return header, channels


def _open(path, with_pixels=False):
    path = Path(path)
    if not path.is_file():
        raise LutMissingError(f"LUT file {path} is missing. Bake it with `{BAKE_COMMAND}`.")
    try:
        header, channels = _read_exr(path, with_pixels)
    except Exception as exc:  # damaged files raise plain exceptions
        raise LutCorruptError(
            f"{path}: not a readable OpenEXR file ({exc}). Re-bake with `{BAKE_COMMAND} --force`."
        ) from exc
    meta = {k[4:]: v for k, v in header.items() if isinstance(k, str) and k.startswith("rtl.")}
    if "table" not in meta:
        raise LutMismatchError(f"{path}: not an RT Lookdev LUT (no rtl.table attribute).")
    return meta, channels
