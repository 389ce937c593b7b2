"""The export's ltc_code tables in three.js (issue 32), rendered in headless Chromium and read back as numbers.

One browser run (module fixture): 8 seeded light and camera configurations x 6 roughness values x 4 table pairs,
5 x 5 pixels each (``validation/benchmarks/three_ltc_benchmark.py`` says how they are made; its full run writes
docs/benchmarks/three_ltc.md).  The tests check that the page reads the exported files right way up, that what
three rendered is what the installed tables give (numpy's copy of three's shading), and that the tables beat three's
own against a brute-force integral of three's BRDF.
"""
import json
import subprocess
import sys
import tempfile

import numpy as np
import pytest

#: No bpy here: what three.js renders from the exported files does not depend on the Blender release (.ci/run runs
#: these in the development environment only; tests/core checks the export under numpy 1 and 2).
pytestmark = pytest.mark.development_release_only

ROUGHNESS = (0.1, 0.25, 0.4, 0.6, 0.8, 1.0)
TABLES = ("three", "rtl_f32", "rtl_f16", "three_half")
#: The patched material (engines/three/src/patch.js): each lobe alone, at two roughness values; "single": the GGX
#: lobe without Turquin's compensation.
PATCH_CASES = [(lobe, r, specular) for lobe in ("specular", "diffuse", "sheen") for r in (0.2, 0.7)
               for specular in (("turquin", "single") if lobe == "specular" else ("turquin",))]


def case_name(lobe, r, specular):
    return f"{lobe}_{r}_{specular}"


@pytest.fixture(scope="module")
def run(browser_ready):
    from rt_lookdev.validation.benchmarks import three_ltc_benchmark as bench

    patched = [{"name": case_name(*case), "params": browser_ready.PATCH_VARIANTS[case[0]](case[1], case[1]),
                "patch": {"specular": case[2], "diffuse": "cod", "sheen": "zeltner"}} for case in PATCH_CASES]
    patched += [{"name": f"{bench.PATCHED}_{i}", "params": browser_ready.PATCH_VARIANTS["specular"](r, r),
                 "patch": {"specular": "single", "diffuse": "lambert", "sheen": "none"}} for i, r in enumerate(ROUGHNESS)]
    spec = {"size": 5, "roughness": list(ROUGHNESS), "tables": list(TABLES), "configs": bench.configurations(8),
            "loadTables": ["f32", "f16"], "patched": patched}
    with tempfile.TemporaryDirectory() as tmp:
        return browser_ready.render(spec, browser_ready.export_tables(tmp))


@pytest.fixture(scope="module")
def rows(run):
    """The read-back values beside the brute-force truth at every pixel (``three_ltc_benchmark.collect_rows``)."""
    from rt_lookdev.validation.benchmarks import three_ltc_benchmark as bench

    return bench.collect_rows(run.configs, [bench.truths(c, ROUGHNESS) for c in run.configs], ROUGHNESS, TABLES)


def test_the_page_reads_the_exported_pair_right_way_up(run):
    """loadRtLookdevTables (three's EXRLoader on the v_descending EXRs) gives the export's tables unchanged, row
    t = 0 first: a flipped or rescaled file would differ by up to the tables' range."""
    from rt_lookdev.validation.benchmarks import three_ltc_benchmark as bench

    assert bench.table_orientation(run) == {"f32": 0.0, "f16": 0.0}


@pytest.mark.parametrize("precision", ["f32", "f16"])
def test_three_renders_what_the_installed_tables_give(run, browser_ready, precision):
    """The render with the exported pair installed equals three's shading evaluated in numpy with that pair
    (measured median 1e-5 relative); three's own pair rendered in the same place is not (it differs by percents),
    so the test fails if installRtLookdev did not take."""
    tables = run.tables[precision]
    mine, theirs = [], []
    for config in run.configs:
        v, corners, in_front = browser_ready.pixel_frames(config.positions, config.camera, config.corners)
        for i, r in enumerate(ROUGHNESS):
            expected = browser_ready.three_rect_area_specular(tables["ltc1"], tables["ltc2"], r, v, corners) * in_front
            sel = expected > 1e-3
            mine += list(np.abs(config.values[f"rtl_{precision}"][i] - expected)[sel] / expected[sel])
            theirs += list(np.abs(config.values["three"][i] - expected)[sel] / expected[sel])
    assert len(mine) > 300
    assert np.median(mine) < 1e-4, np.median(mine)
    assert np.median(theirs) > 1e-3, np.median(theirs)


@pytest.mark.parametrize("case", PATCH_CASES, ids=[case_name(*c) for c in PATCH_CASES])
def test_the_patched_material_shades_with_rt_lits_functions(run, browser_ready, tables, case):
    """patchAreaLights: three renders, for each lobe alone, what RT Lit's node functions give in numpy (float64) at
    the same pixels (GGX with its band and exact horizon, Turquin's compensation, CoD diffuse, Zeltner sheen):
    measured median 2e-6 ... 3e-5 relative.  Three's own shading of the same material is percents away."""
    lobe, r, specular = case
    errors = []
    for config in run.configs:
        expected = browser_ready.patched_reference(tables, config, lobe, r, r, specular)
        got = config.patched[case_name(*case)]
        sel = expected > 1e-3 * max(expected.max(), 1e-12)
        errors += list(np.abs(got - expected)[sel] / expected[sel])
    assert len(errors) > 100
    assert np.median(errors) < 1e-4, np.median(errors)
    assert np.quantile(errors, 0.99) < 1e-2, np.quantile(errors, 0.99)


def test_the_exported_pair_beats_threes_own_against_the_truth(rows):
    """Against the brute-force integral of three's BRDF, the exported pair (f32 against three's float tables, f16
    against its half tables) has a lower pooled median and p90 error, and a median at or below three's at
    r = 0.25 ... 0.8.  At r = 0.1 (medians about 4e-4 for both) and r = 1 the two medians are within 0.1 percentage
    point of each other, and at r = 1 ours is the higher on this set (4.65% against 4.59% for the half tables):
    issue 32's "at or below at every roughness" is not met there (docs/benchmarks/three_ltc.md).  This test holds
    what is claimed and fails if either end moves further."""
    from rt_lookdev.validation.benchmarks import three_ltc_benchmark as bench

    stats = bench.summarise(rows, TABLES)
    for ours, theirs in bench.OURS.items():
        assert stats[ours]["pooled"]["rel_median"] < stats[theirs]["pooled"]["rel_median"]
        assert stats[ours]["pooled"]["rel_p90"] < stats[theirs]["pooled"]["rel_p90"]
        for r in ROUGHNESS:
            mine, other = (stats[t]["per_roughness"][str(r)] for t in (ours, theirs))
            assert mine["lights_over_10pct"] >= 20
            if r in (0.1, 1.0):
                assert abs(mine["rel_median"] - other["rel_median"]) <= 1e-3, (ours, r)
            else:
                assert mine["rel_median"] <= other["rel_median"], (ours, r)


def test_the_patched_specular_beats_threes_shading_against_the_truth(rows):
    """patchAreaLights in single scattering is the same BRDF as the truth: RT Lit's GGX LTC with its band and exact
    horizon clipping against three's LTC and clipped-sphere form factor (benchmark: pooled median / p90 0.32% /
    1.84% against 3.78% / 19.35%).  Its median is below three's at every roughness and its pooled p90 is under a
    quarter of three's."""
    from rt_lookdev.validation.benchmarks import three_ltc_benchmark as bench

    stats = bench.summarise(rows, ("three", bench.PATCHED))
    mine, theirs = stats[bench.PATCHED], stats["three"]
    for r in ROUGHNESS:
        assert mine["per_roughness"][str(r)]["rel_median"] < theirs["per_roughness"][str(r)]["rel_median"], r
    assert mine["pooled"]["rel_p90"] < 0.25 * theirs["pooled"]["rel_p90"]


def test_the_package_unit_tests_pass(browser_ready):
    """engines/three's own tests (npm test: node --test, the installer's checks)."""
    proc = subprocess.run(["npm", "test", "--silent"], cwd=browser_ready.PACKAGE, capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr


def test_the_benchmark_script_writes_its_report(browser_ready, tmp_path):
    """The README's command (scripts/benchmark_three_ltc.py), at its smallest: it writes its Markdown and JSON."""
    repo = browser_ready.REPO
    proc = subprocess.run([sys.executable, "scripts/benchmark_three_ltc.py", "--configs", "2", "--size", "3",
                           "--workers", "0", "--out", str(tmp_path / "three_ltc.md")], cwd=repo,
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    result = json.loads((tmp_path / "three_ltc.json").read_text())
    assert result["loaded_table_max_difference"] == {"f32": 0.0, "f16": 0.0}
    assert "| pooled |" in (tmp_path / "three_ltc.md").read_text()
    assert "rtl_patched" in result["stats"]
