"""engines/three's generated library (core/export/three_area.py): the committed module is what the IR gives, and it
holds every function and table the patch (engines/three/src/patch.js) names."""
import json
import re
import subprocess
import sys
from pathlib import Path

from rt_lookdev.core.export import three_area

REPO = Path(__file__).resolve().parents[2]


def test_the_committed_module_is_what_the_ir_gives():
    """`python scripts/build_three_area.py --check` (the README's command) passes: the IR and the file agree."""
    proc = subprocess.run([sys.executable, "scripts/build_three_area.py", "--check"], cwd=REPO, capture_output=True,
                          text=True, timeout=300)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "up to date" in proc.stdout


def test_the_module_has_what_the_patch_calls():
    text = (REPO / three_area.MODULE_PATH).read_text()
    functions = json.loads(re.search(r"RTL_AREA_FUNCTIONS = Object.freeze\( (.*) \);", text).group(1))
    patch = (REPO / "engines" / "three" / "src" / "patch.js").read_text()
    for name in re.findall(r"ident\( '([^']+)' \)", patch):
        assert name in functions, name
    tables = json.loads(re.search(r"RTL_AREA_TABLES = Object.freeze\( (.*) \);", text).group(1))
    assert set(tables) == {"ltc_ggx_inv", "ltc_ggx_mag", "ltc_cod_diffuse_inv", "ltc_cod_diffuse_mag", "zeltner_sheen"}
    glsl = json.loads(re.search(r"RTL_AREA_GLSL = (.*);", text).group(1))
    for table in tables.values():
        assert f"uniform sampler2D {table['uniform']};" in glsl
    assert "#version" not in glsl          # an include: three's program has its own header


def test_a_stale_module_is_reported(tmp_path, monkeypatch):
    """--check fails (exit 1) on a file that differs from the IR's output."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("build_three_area", REPO / "scripts" / "build_three_area.py")
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)
    monkeypatch.setattr(script, "REPO", tmp_path)
    target = tmp_path / three_area.MODULE_PATH
    target.parent.mkdir(parents=True)
    target.write_text("// old\n")
    assert script.main(["--check"]) == 1
    assert script.main([]) == 0 and script.main(["--check"]) == 0
