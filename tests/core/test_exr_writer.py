"""The pure-numpy EXR writer (core/lut/exr_writer.py): files the OpenEXR library and the built-in
reader both read bit-exactly, with the header the OpenEXR bindings write, and ``exr_io.write_table``
/ the environment bake working without the OpenEXR module (as in Blender's bundled Python)."""
import json
import struct
import sys

import numpy as np
import OpenEXR
import pytest

from rt_lookdev.core.environment import prefilter
from rt_lookdev.core.lut import exr_io, exr_reader, exr_writer

F32 = np.finfo(np.float32)


def _special_table(h, w, seed):
    """A smooth (compressible) float32 table with random rows over ~60 decades and both signs mixed
    in, plus inf/nan/-0/denormals/1e8 planted."""
    rng = np.random.default_rng(seed)
    y, x = np.meshgrid(np.linspace(0, 1, h), np.linspace(0, 1, w), indexing="ij")
    t = np.stack([x * y, np.sin(3 * x) + y, 1 - x, np.ones_like(x)], axis=-1).astype(np.float32)
    noisy = rng.random(h) < 0.25
    t[noisy] = (rng.normal(size=(noisy.sum(), w, 4)) * 10.0 ** rng.integers(-30, 30, (noisy.sum(), w, 4)))
    specials = np.array([np.inf, -np.inf, np.nan, -0.0, 0.0, F32.smallest_subnormal, -3 * F32.smallest_subnormal,
                         F32.tiny / 2, 1e8, -1e8, F32.max, -F32.max], dtype=np.float32)
    flat = t.reshape(-1)
    flat[rng.choice(flat.size, min(flat.size, specials.size), replace=False)] = specials[:flat.size]
    flat[-1:] = np.array([0x7FC12345], dtype="<u4").view("<f4")      # a NaN with a payload
    return t


def _blocks(path):
    """[(y, stored size)] of the scan-line blocks of an EXR file written by exr_writer."""
    attrs, _ = exr_reader.read(path)
    data = path.read_bytes()
    # the offset table follows "type" (the last attribute) and the 0 byte ending the header
    table_start = data.index(b"scanlineimage") + len(b"scanlineimage") + 1
    x0, y0, x1, y1 = attrs["dataWindow"]
    lines = {0: 1, 2: 1, 3: 16}[attrs["compression"]]
    n = (y1 - y0 + lines) // lines
    return [struct.unpack_from("<ii", data, o) for o in struct.unpack_from(f"<{n}Q", data, table_start)]


def _read_openexr(path):
    with OpenEXR.File(str(path), separate_channels=True) as f:
        header = dict(f.header())
        planes = {n: np.array(c.pixels) for n, c in f.channels().items()}
    return header, planes


def _hide_openexr(monkeypatch):
    monkeypatch.setitem(sys.modules, "OpenEXR", None)       # import now raises ImportError, as in Blender


@pytest.mark.parametrize("compression", ["zip", "zips", "none"])
@pytest.mark.parametrize("shape", [(64, 64), (37, 5), (1, 3), (16, 1), (17, 64)])
def test_round_trip_is_bit_exact_with_both_readers(tmp_path, shape, compression):
    table = _special_table(*shape, seed=shape[0] * 100 + shape[1])
    planes = {c: table[:, :, i] for i, c in enumerate("RGBA")}
    path = tmp_path / "t.exr"
    exr_writer.write(path, planes, {"n": 7}, compression)
    header, by_library = _read_openexr(path)
    attrs, by_reader = exr_reader.read(path)
    assert set(by_library) == set(by_reader) == set("RGBA") and header["n"] == attrs["n"] == 7
    for c in "RGBA":
        assert by_library[c].dtype == np.float32 and by_library[c].shape == shape
        assert by_library[c].tobytes() == planes[c].tobytes() == by_reader[c].tobytes()
    assert attrs["compression"] == {"none": 0, "zips": 2, "zip": 3}[compression]
    assert attrs["channels"] == ["A", "B", "G", "R"]
    lines = 16 if compression == "zip" else 1
    blocks = _blocks(path)
    assert [y for y, _ in blocks] == list(range(0, shape[0], lines))
    raw = [min(lines, shape[0] - y) * shape[1] * 16 for y, _ in blocks]
    deflated = [size < r for (_, size), r in zip(blocks, raw)]
    assert all(size <= r for (_, size), r in zip(blocks, raw))
    if compression == "none":
        assert not any(deflated)
    elif shape[1] >= 5:                   # a long enough line of a smooth table deflates
        assert any(deflated)


def test_incompressible_blocks_are_stored_raw(tmp_path):
    bits = np.random.default_rng(3).integers(0, 2**32, (20, 8, 4), dtype=np.uint64).astype("<u4")
    bits[(bits & 0x7F800000) == 0x7F800000] &= 0xBFFFFFFF          # no inf/nan: any finite bit pattern
    table = bits.view("<f4")
    planes = {c: table[:, :, i] for i, c in enumerate("RGBA")}
    path = tmp_path / "raw.exr"
    path.write_bytes(exr_writer.encode(planes, compression="zip"))
    assert _blocks(path) == [(0, 16 * 8 * 4 * 4), (16, 4 * 8 * 4 * 4)]     # raw: deflate did not win
    _, by_library = _read_openexr(path)
    _, by_reader = exr_reader.read(path)
    assert all(by_library[c].tobytes() == planes[c].tobytes() == by_reader[c].tobytes() for c in "RGBA")


def test_header_is_byte_identical_to_openexr(tmp_path, monkeypatch):
    table = _special_table(9, 4, 1)
    table[~np.isfinite(table)] = 1.0
    metadata = {"table": "h", "s": "h\u00e9llo", "i": -5, "b": True, "f": 0.1, "huge": 1e300,
                "a_name_longer_than_thirty_one_bytes": 2}          # sets the long-names version bit
    exr_io.write_table(tmp_path / "lib.exr", table, metadata)
    _hide_openexr(monkeypatch)
    exr_io.write_table(tmp_path / "pure.exr", table, metadata)
    lib, pure = (tmp_path / "lib.exr").read_bytes(), (tmp_path / "pure.exr").read_bytes()
    end = lib.index(b"scanlineimage") + len(b"scanlineimage") + 1     # "type" is the last attribute
    assert lib[end - 1] == 0 and lib[:end] == pure[:end]
    assert struct.unpack_from("<i", pure, 4)[0] == 0x402


@pytest.mark.parametrize("shape", [(64, 64), (1, 9), (23, 17)])
def test_write_table_without_openexr_matches_the_openexr_path(tmp_path, monkeypatch, shape):
    table = _special_table(*shape, seed=7)
    table[~np.isfinite(table)] = -2.5
    metadata = {"table": "w", "description": "RGBA; A = 1", "samples": 1024, "layout_version": 3,
                "flag": False, "scale": 0.3, "params": json.dumps({"roughness": [0, 0.5, 1]})}
    digest_lib = exr_io.write_table(tmp_path / "lib.exr", table, metadata)
    _hide_openexr(monkeypatch)
    digest_pure = exr_io.write_table(tmp_path / "pure.exr", table, metadata)
    assert digest_pure == digest_lib == exr_io.content_hash(table)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["lib.exr", "pure.exr"]      # no .tmp left
    results = {}
    for reader in ("pure reader", "OpenEXR"):
        if reader == "OpenEXR":
            monkeypatch.setitem(sys.modules, "OpenEXR", OpenEXR)
        for writer in ("lib", "pure"):
            results[writer, reader] = exr_io.read_table(tmp_path / f"{writer}.exr", "w", shape)
    reference_table, reference_meta = results["lib", "OpenEXR"]
    assert reference_meta["scale"] == np.float32(0.3) and reference_meta["flag"] == 0
    for key, (back, meta) in results.items():
        assert back.tobytes() == table.tobytes(), key
        assert meta == reference_meta and all(type(meta[k]) is type(reference_meta[k]) for k in meta), key


def test_metadata_the_bindings_cannot_store_is_refused_by_both_paths(tmp_path, monkeypatch):
    table = np.zeros((2, 2, 4), np.float32)
    for hidden in (False, True):
        if hidden:
            _hide_openexr(monkeypatch)
        for bad in ({"table": "x", "n": 2**31}, {"table": "x", "v": np.float32(1.0)}, {"table": "x", "l": [1]}):
            with pytest.raises(exr_writer.ExrWriteError):
                exr_io.write_table(tmp_path / "x.exr", table, bad)
        assert not any(tmp_path.iterdir())


def test_environment_bake_without_openexr_equals_the_openexr_bake(tmp_path, monkeypatch):
    h, w = 32, 64
    theta = (np.arange(h) + 0.5)[:, None] / h * np.pi
    phi = (np.arange(w) + 0.5)[None, :] / w * 2 * np.pi
    image = np.stack([1 + np.cos(theta) * np.cos(phi), 1 + np.sin(2 * phi) * np.sin(theta) ** 2,
                      np.broadcast_to(0.5 + 0.5 * (theta < 0.6), (h, w))], axis=-1).astype(np.float32)
    image[5, 40] = 50.0                                              # a small bright "sun"
    settings = prefilter.PrefilterSettings(width=16, height=8, roughness=(0.0, 0.5, 1.0))
    with_lib = prefilter.bake_environment_image(image, "synthetic", "test://synthetic", tmp_path / "lib", settings)
    _hide_openexr(monkeypatch)
    without = prefilter.bake_environment_image(image, "synthetic", "test://synthetic", tmp_path / "pure", settings)
    assert with_lib.states == without.states == {"sh": "baked", "prefiltered": "baked"}
    assert np.array_equal(with_lib.sh_image, without.sh_image)
    assert with_lib.sh_json_path.read_text() == without.sh_json_path.read_text()
    for attr in ("sh_path", "prefiltered_path"):
        for reader in ("pure reader", "OpenEXR"):
            if reader == "OpenEXR":
                monkeypatch.setitem(sys.modules, "OpenEXR", OpenEXR)
            a_table, a_meta = exr_io.read_table(getattr(with_lib, attr))
            b_table, b_meta = exr_io.read_table(getattr(without, attr))
            assert a_table.tobytes() == b_table.tobytes() and a_meta == b_meta
        _hide_openexr(monkeypatch)
    levels, rl, _ = prefilter.read_prefiltered(without.prefiltered_path)
    assert levels.shape == (3, 8, 16, 3) and rl == [0.0, 0.5, 1.0]
    again = prefilter.bake_environment_image(image, "synthetic", "test://synthetic", tmp_path / "pure", settings)
    assert again.states == {"sh": "cached", "prefiltered": "cached"}    # the pure files pass the cache check


@pytest.mark.parametrize("compression", [OpenEXR.ZIP_COMPRESSION, OpenEXR.NO_COMPRESSION])
def test_multi_part_files_read_like_openexr(tmp_path, monkeypatch, compression):
    """Blender's multilayer renders are multi-part EXRs: the built-in reader gives every part's channels, as
    the OpenEXR package does, so the validation reads renders in a Python without OpenEXR (Blender's)."""
    from rt_lookdev.validation.harness import exr_images

    rng = np.random.default_rng(7)
    parts = []
    for name, (h, w) in (("ViewLayer.Combined", (21, 13)), ("ViewLayer.Normal", (21, 13))):
        channels = {f"{name}.{c}": rng.normal(size=(h, w)).astype(np.float32) for c in "RGB"}
        header = {"compression": compression, "type": OpenEXR.scanlineimage, "name": name}
        parts.append(OpenEXR.Part(header, channels))
    path = tmp_path / "multilayer.exr"
    with OpenEXR.File(parts) as f:
        f.write(str(path))
    expected = exr_images.read_channels(path)                          # with the OpenEXR package
    attrs, planes = exr_reader.read(path)
    assert sorted(planes) == sorted(expected) and len(planes) == 6
    for name, plane in planes.items():
        assert np.array_equal(plane, expected[name]), name
    monkeypatch.setitem(sys.modules, "OpenEXR", None)                  # as in Blender's Python
    without = exr_images.read_channels(path)
    assert all(np.array_equal(without[n], expected[n]) for n in expected)
