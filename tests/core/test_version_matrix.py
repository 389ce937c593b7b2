"""The table of ``bash scripts/test.sh --matrix`` from the files each run leaves (validation/tools/version_matrix.py)."""
from rt_lookdev.validation.tools import version_matrix

XML = """<?xml version="1.0" encoding="utf-8"?><testsuites><testsuite name="pytest" errors="{e}" failures="{f}"
skipped="{s}" tests="{t}" time="1.0"></testsuite></testsuites>"""


def test_rows_count_passed_failed_skipped_per_environment(tmp_path):
    (tmp_path / "dev.xml").write_text(XML.format(e=0, f=0, s=2, t=10))
    (tmp_path / "dev.rc").write_text("0 88")
    (tmp_path / "dev.env").write_text("5.2.3 3.13.0 2.5.5")
    (tmp_path / "4.5.xml").write_text(XML.format(e=1, f=2, s=0, t=10))
    (tmp_path / "4.5.rc").write_text("1 105")
    (tmp_path / "4.5.env").write_text("4.5.15 3.11.7 1.26.4")
    rows = version_matrix.rows(tmp_path)
    assert [r["environment"] for r in rows] == ["requirements.lock", "requirements/blender-4.5.lock"]
    assert (rows[0]["passed"], rows[0]["failed"], rows[0]["skipped"]) == (8, 0, 2)
    assert (rows[1]["passed"], rows[1]["failed"], rows[1]["blender"], rows[1]["numpy"]) == (7, 3, "4.5.15", "1.26.4")
    assert version_matrix.main([str(tmp_path)]) == 1            # a failing release fails the matrix
    assert "| requirements/blender-4.5.lock | 4.5.15 | 3.11.7 | 1.26.4 | 7 | 3 | 0 | 105 s |" in \
        (tmp_path / "matrix.md").read_text()
