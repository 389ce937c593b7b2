import sys
from pathlib import Path

import numpy as np
import OpenEXR
import pytest

from rt_lookdev.core import lut_bake as bake
from rt_lookdev.core.ir import semantics
from rt_lookdev.core.lut import catalog, exr_io, exr_reader, lookup

REPO = Path(__file__).resolve().parents[2]


def _random_table(h=5, w=7, seed=0):
    rng = np.random.default_rng(seed)
    t = (rng.normal(size=(h, w, 4)) * 10.0 ** rng.integers(-30, 30, (h, w, 4))).astype(np.float32)
    t[0, 0] = [0.0, -0.0, np.finfo(np.float32).tiny, np.finfo(np.float32).max]
    return t


def test_exr_round_trip_is_bit_exact(tmp_path):
    table = _random_table()
    exr_io.write_table(tmp_path / "t.exr", table, {"table": "test", "samples": 3})
    back, meta = exr_io.read_table(tmp_path / "t.exr", "test", (5, 7))
    assert back.dtype == np.float32 and back.tobytes() == table.tobytes()
    assert meta["samples"] == 3 and meta["content_hash"] == exr_io.content_hash(table)


def test_builtin_reader_matches_openexr(tmp_path, lut_dir):
    files = [tmp_path / "random.exr"] + sorted(Path(lut_dir).glob("*.exr"))
    exr_io.write_table(files[0], _random_table(40, 9, 1), {"table": "random", "f": 0.25})
    for path in files:
        attrs, planes = exr_reader.read(path)
        with OpenEXR.File(str(path), separate_channels=True) as f:
            header = dict(f.header())
            channels = {n: np.array(c.pixels) for n, c in f.channels().items()}
        assert set(planes) == set(channels)
        for name, pixels in channels.items():
            assert planes[name].tobytes() == pixels.astype("<f4").tobytes()
        rtl = {k: v for k, v in header.items() if k.startswith("rtl.")}
        assert rtl and all(attrs[k] == v for k, v in rtl.items())


def test_read_table_without_openexr_module(monkeypatch, lut_dir):
    spec = catalog.TABLES["ggx_split_sum"]
    with_module, _ = exr_io.read_table(Path(lut_dir) / spec.filename, spec.name, spec.shape)
    monkeypatch.setitem(sys.modules, "OpenEXR", None)   # import now raises ImportError, as in Blender
    without, meta = exr_io.read_table(Path(lut_dir) / spec.filename, spec.name, spec.shape)
    assert without.tobytes() == with_module.tobytes() and meta["table"] == spec.name


def test_file_orientation_is_blender_bottom_up(tmp_path):
    table = np.zeros((3, 2, 4), np.float32)
    table[0, :, 0] = 1.0                      # table row 0 = v node 0 = bottom of the image
    exr_io.write_table(tmp_path / "o.exr", table, {"table": "o"})
    with OpenEXR.File(str(tmp_path / "o.exr"), separate_channels=True) as f:
        red = np.array(f.channels()["R"].pixels)
    assert np.all(red[-1] == 1.0) and np.all(red[:-1] == 0.0)   # EXR stores the top row first


def test_missing_corrupt_and_mismatched_files(tmp_path, lut_dir):
    spec = catalog.TABLES["ggx_one_minus_E"]
    with pytest.raises(exr_io.LutMissingError, match="bake_luts.py"):
        exr_io.read_table(tmp_path / "nope.exr", spec.name, spec.shape)
    garbage = tmp_path / "garbage.exr"
    garbage.write_bytes(b"not an exr at all")
    with pytest.raises(exr_io.LutCorruptError, match="--force"):
        exr_io.read_table(garbage, spec.name, spec.shape)
    truncated = tmp_path / "truncated.exr"
    truncated.write_bytes((Path(lut_dir) / spec.filename).read_bytes()[:600])
    with pytest.raises(exr_io.LutCorruptError):
        exr_io.read_table(truncated, spec.name, spec.shape)
    with pytest.raises(exr_io.LutMismatchError, match="ggx_one_minus_E_avg"):
        exr_io.read_table(Path(lut_dir) / "ggx_one_minus_E_avg.exr", spec.name, spec.shape)
    with pytest.raises(exr_io.LutMismatchError, match="64x64"):
        exr_io.read_table(Path(lut_dir) / spec.filename, spec.name, (32, 32))
    foreign = tmp_path / "foreign.exr"
    with OpenEXR.File({"compression": OpenEXR.ZIP_COMPRESSION}, {"R": np.zeros((2, 2), np.float32)}) as f:
        f.write(str(foreign))
    with pytest.raises(exr_io.LutMismatchError, match="not an RT Lookdev LUT"):
        exr_io.read_table(foreign, spec.name, spec.shape)


def test_edited_pixels_fail_the_content_hash(tmp_path, lut_dir):
    src = Path(lut_dir) / "ggx_split_sum.exr"
    with OpenEXR.File(str(src), separate_channels=True) as f:
        header = dict(f.header())
        channels = {n: np.array(c.pixels) for n, c in f.channels().items()}
    channels["G"][10, 10] += 1e-3
    header = {k: v for k, v in header.items() if k.startswith("rtl.") or k == "compression"}
    with OpenEXR.File(header, channels) as f:
        f.write(str(tmp_path / "edited.exr"))
    with pytest.raises(exr_io.LutCorruptError, match="content hash"):
        exr_io.read_table(tmp_path / "edited.exr", "ggx_split_sum", (64, 64))


def test_write_refuses_non_finite(tmp_path):
    t = np.zeros((2, 2, 4), np.float32)
    t[1, 1, 2] = np.nan
    with pytest.raises(ValueError, match="non-finite"):
        exr_io.write_table(tmp_path / "n.exr", t, {"table": "n"})
    assert not (tmp_path / "n.exr").exists()


@pytest.fixture
def fast_energy_group(monkeypatch):
    """The energy group with 16 samples per cell: same code path, a fraction of a second."""
    group = catalog.GROUPS["ggx_energy"]
    fast = catalog.BakeGroup(group.name, group.generator_version, dict(group.params, samples=16), group.sources)
    monkeypatch.setitem(catalog.GROUPS, "ggx_energy", fast)
    return fast


def test_bake_cache_hit_and_miss(tmp_path, fast_energy_group, monkeypatch):
    lines = []
    first = bake.bake(tmp_path, log=lines.append, groups=["ggx_energy"])
    assert [r.state for r in first] == ["baked"]
    mtimes = {p: p.stat().st_mtime_ns for p in tmp_path.glob("*.exr")}
    assert len(mtimes) == 3
    second = bake.bake(tmp_path, log=lines.append, groups=["ggx_energy"])
    assert [r.state for r in second] == ["cached"] and "nothing to do" in lines[-1]
    assert {p: p.stat().st_mtime_ns for p in tmp_path.glob("*.exr")} == mtimes
    assert all(catalog.table_status(catalog.TABLES[n], tmp_path).state == "ok"
               for n in ("ggx_one_minus_E", "ggx_one_minus_E_avg", "ggx_split_sum"))
    # a changed input makes the files stale and the next bake redoes them
    changed = catalog.BakeGroup("ggx_energy", 1, dict(fast_energy_group.params, samples=32), fast_energy_group.sources)
    monkeypatch.setitem(catalog.GROUPS, "ggx_energy", changed)
    assert {catalog.table_status(catalog.TABLES[n], tmp_path).state
            for n in ("ggx_one_minus_E", "ggx_one_minus_E_avg", "ggx_split_sum")} == {"stale"}
    assert [r.state for r in bake.bake(tmp_path, log=lines.append, groups=["ggx_energy"])] == ["baked"]
    # a damaged file is re-baked too
    (tmp_path / "ggx_one_minus_E_avg.exr").write_bytes(b"junk")
    assert catalog.table_status(catalog.TABLES["ggx_one_minus_E_avg"], tmp_path).state == "corrupt"
    assert [r.state for r in bake.bake(tmp_path, log=lines.append, groups=["ggx_energy"])] == ["baked"]


def test_bake_is_deterministic(fast_energy_group):
    a = bake.compute_energy_tables(16, 64)
    b = bake.compute_energy_tables(16, 64)
    assert all(a[k].tobytes() == b[k].tobytes() for k in a)


def test_shipped_luts_are_current():
    status = catalog.lut_status(catalog.default_lut_dir())
    assert [s.state for s in status] == ["ok"] * len(catalog.TABLES), [s.message for s in status]


def test_docs_describe_every_table():
    doc = (REPO / "docs" / "luts.md").read_text()
    for spec in catalog.TABLES.values():
        assert spec.filename in doc and spec.channels in doc, spec.name


def test_bilinear_sampling_reconstructs_nodes_and_extends():
    table = np.arange(4 * 3 * 4, dtype=np.float64).reshape(4, 3, 4)
    j, i = np.meshgrid(np.arange(4), np.arange(3), indexing="ij")
    got = semantics.sample_bilinear(table, (i + 0.5) / 3, (j + 0.5) / 4)
    assert np.array_equal(got, table)
    assert np.array_equal(semantics.sample_bilinear(table, -1.0, 2.0), table[3, 0])       # EXTEND
    mid = semantics.sample_bilinear(table, 1.0 / 3, 0.5 / 4)                                 # halfway in u
    assert np.allclose(mid, 0.5 * (table[0, 0] + table[0, 1]))
    x = np.linspace(0, 1, 7)
    assert np.allclose(lookup.lut_coordinate(x, 64) * 64 - 0.5, x * 63)


def test_energy_lut_matches_cycles_nodes(energy_tables):
    from rt_lookdev.core import energy_checks
    result = energy_checks.cycles_table_comparison(energy_tables)
    assert result["max_abs_diff_E_lut"] < 1e-3 and result["max_abs_diff_E_avg_lut"] < 1e-3
    assert result["E_avg_r1_lut"] == pytest.approx(0.409, abs=1e-3)


def test_writing_without_openexr_uses_the_pure_writer(tmp_path, monkeypatch):
    """Blender's own Python has no OpenEXR: tables are still written (core/lut/exr_writer.py) and read."""
    monkeypatch.setitem(sys.modules, "OpenEXR", None)
    table = np.arange(16, dtype=np.float32).reshape(2, 2, 4)
    exr_io.write_table(tmp_path / "x.exr", table, {"table": "x"})
    got, meta = exr_io.read_table(tmp_path / "x.exr")
    np.testing.assert_array_equal(got, table)
    assert meta["table"] == "x"


def test_inputs_hash_sees_code_not_comments(tmp_path):
    """Editing a comment or a docstring of a source module leaves the tables current; editing code
    makes them stale (``catalog.code_text``)."""
    src = '"""Module doc."""\nimport math  # a comment\n\n\ndef f(x):\n    """Doc."""\n    # note\n    return x * 2  # why\n'
    a = tmp_path / "a.py"
    a.write_text(src)
    base = catalog.code_text(a)
    assert "comment" not in base and "Doc" not in base and "return x * 2" in base
    a.write_text(src.replace("a comment", "another comment").replace('"""Doc."""', '"""Other\n    doc."""'))
    assert catalog.code_text(a) == base
    a.write_text(src.replace("x * 2", "x * 3"))
    assert catalog.code_text(a) != base


def _quick_compute(monkeypatch, during=None):
    """Replace the bake's computation by constant tables of the right shapes (the write path is under
    test, not the integrals); ``during(group)`` runs while a group is "computed"."""
    def compute(name, progress=None):
        if during is not None:
            during(name)
        return {s.name: np.full(s.shape + (4,), 0.5, np.float32) for s in catalog.TABLES.values() if s.group == name}

    monkeypatch.setattr(bake, "_compute", compute)


def test_a_failed_write_keeps_the_previous_tables_and_names_the_fix(tmp_path, monkeypatch):
    """A LUT folder that cannot be written (read-only, full, gone): LutWriteError naming the file, the cause
    and the way out; the group's previous files stay byte-identical and no partial (.tmp) file is left."""
    _quick_compute(monkeypatch)
    bake.bake(tmp_path, groups=["ggx_energy"], workers=1, log=lambda line: None)
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    assert len(before) >= 2
    calls = []
    real = exr_io._write_exr

    def failing(path, channels, attributes):
        calls.append(path)
        if len(calls) == 2:                   # the group's second table: the first is already written
            raise PermissionError(13, "Permission denied", str(path))
        real(path, channels, attributes)

    monkeypatch.setattr(exr_io, "_write_exr", failing)
    with pytest.raises(exr_io.LutWriteError, match=r"Permission denied.*--lut-dir"):
        bake.bake(tmp_path, force=True, groups=["ggx_energy"], workers=1, log=lambda line: None)
    assert len(calls) == 2
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_a_lut_folder_removed_during_a_bake_is_recreated_whole(tmp_path, monkeypatch):
    """The folder vanishes while a group is computed: the bake writes the whole group again, with metadata
    that reads back as current."""
    import shutil

    folder = tmp_path / "luts"
    folder.mkdir()
    _quick_compute(monkeypatch, during=lambda name: shutil.rmtree(folder, ignore_errors=True))
    bake.bake(folder, groups=["ggx_energy"], workers=1, log=lambda line: None)
    specs = [s for s in catalog.TABLES.values() if s.group == "ggx_energy"]
    assert sorted(p.name for p in folder.iterdir()) == sorted(s.filename for s in specs)
    assert bake.group_is_current("ggx_energy", folder)
