"""Everything from Blender itself: baking the LUTs and the world with progress and cancel
(addon/background_task.py), and the whole path (LUT bake, world sync, validation) in a Python where
``import OpenEXR`` fails, as in Blender's own."""
import json
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytestmark = pytest.mark.blender

REPO = Path(__file__).resolve().parents[2]
ENERGY_FILES = ("ggx_one_minus_E.exr", "ggx_one_minus_E_avg.exr", "ggx_split_sum.exr")


def test_a_background_task_reports_progress_and_stops_when_cancelled(bpy_module):
    from rt_lookdev.addon.background_task import BackgroundTask

    steps = []

    def work(progress):
        for i in range(1000):
            progress(i / 1000, f"step {i}")
            steps.append(i)
            time.sleep(0.002)
        return "done"

    task = BackgroundTask(work).start()
    while task.fraction < 0.01:
        time.sleep(0.005)
    task.cancel()
    assert task.join(5.0)
    assert task.cancelled and task.result is None and task.error is None
    assert 0 < len(steps) < 1000

    finished = BackgroundTask(lambda progress: progress(1.0) or 42).start()
    assert finished.join(5.0) and finished.result == 42 and not finished.cancelled

    failing = BackgroundTask(lambda progress: 1 / 0).start()
    assert failing.join(5.0) and isinstance(failing.error, ZeroDivisionError)


@pytest.fixture
def stale_lut_dir(tmp_path, lut_dir):
    """A copy of the tables without the GGX energy group."""
    folder = tmp_path / "luts"
    shutil.copytree(lut_dir, folder)
    for name in ENERGY_FILES:
        (folder / name).unlink()
    return folder


def test_bake_luts_operator_bakes_what_is_missing_and_a_cancel_keeps_the_folder(registered, empty_scene,
                                                                                 stale_lut_dir, monkeypatch):
    from rt_lookdev.addon import preferences
    from rt_lookdev.addon.background_task import BackgroundTask
    from rt_lookdev.core import lut_bake
    from rt_lookdev.core.lut import catalog

    bpy = registered
    monkeypatch.setattr(preferences, "lut_directory", lambda context=None: stale_lut_dir)
    before = sorted(p.name for p in stale_lut_dir.iterdir())

    # cancelled at its first progress report: nothing written, nothing removed
    def work(progress):
        return lut_bake.bake(stale_lut_dir, groups=["ggx_energy"], workers=1, log=print,
                             progress=lambda group, done, total: progress(done / total))
    task = BackgroundTask(work)
    task.cancel()
    task.start(thread=False)
    assert task.cancelled
    assert sorted(p.name for p in stale_lut_dir.iterdir()) == before

    assert bpy.ops.rtl.bake_luts() == {'FINISHED'}           # headless: runs at once, then reports
    states = {s.name: s.state for s in catalog.lut_status(stale_lut_dir)}
    assert set(states.values()) == {"ok"}, states
    assert all((stale_lut_dir / name).is_file() for name in ENERGY_FILES)
    assert bpy.ops.rtl.bake_luts() == {'FINISHED'}           # nothing to do the second time


_NO_OPENEXR = r'''
import sys
sys.modules["OpenEXR"] = None                 # "import OpenEXR" fails, as in Blender's Python
import json, runpy
from pathlib import Path
import numpy as np
import bpy
import rt_lookdev
from rt_lookdev.addon import preferences, world_sync
from rt_lookdev.core.lut import catalog, exr_reader
lut_dir, cache, out = (Path(a) for a in sys.argv[1:4])
try:
    import OpenEXR
    raise SystemExit("OpenEXR imported")
except ImportError:
    pass
rt_lookdev.register()
preferences.lut_directory = lambda context=None: lut_dir
result = {"bake": sorted(bpy.ops.rtl.bake_luts()),
          "luts": sorted({s.state for s in catalog.lut_status(lut_dir)})}
# a world image made in Blender, baked by Sync RT Lit World into the cache (the project's EXR writer)
bpy.ops.wm.read_homefile(use_empty=True)
scene = bpy.context.scene
image = bpy.data.images.new("sky", 64, 32, float_buffer=True)
y = np.linspace(1.0, 0.0, 32)[:, None, None] * np.ones((32, 64, 1))
image.pixels = np.concatenate([0.2 + y, 0.3 + 0.5 * y, 0.9 * np.ones_like(y), np.ones_like(y)], axis=-1).ravel()
world = bpy.data.worlds.new("sky")
world.use_nodes = True
nt = world.node_tree
env = nt.nodes.new("ShaderNodeTexEnvironment")
env.image = image
nt.links.new(env.outputs["Color"], nt.nodes["Background"].inputs["Color"])
scene.world = world
result["sync_world"] = sorted(bpy.ops.rtl.sync_world())
files = sorted(cache.glob("*.exr"))
result["cache_files"] = [f.name for f in files]
result["sh_read"] = exr_reader.read(files[-1])[0] is not None if files else False
result["world_group"] = "RTL World" in bpy.data.node_groups
rt_lookdev.unregister()
sys.argv = ["validate.py", "--quick", "--cases", "point", "--samples", "16", "--skip-furnace", "--cell", "32",
            "--out", str(out), "--lut-dir", str(lut_dir)]
try:
    runpy.run_path(str(Path(rt_lookdev.__file__).parent / "scripts" / "validate.py"), run_name="__main__")
    result["validate"] = 0
except SystemExit as ex:
    result["validate"] = ex.code
result["validation_json"] = json.loads((out / "validation.json").read_text())["passed"]
print("RTL_RESULT " + json.dumps(result))
'''


def test_bake_sync_world_and_validate_without_openexr(stale_lut_dir, tmp_path):
    """Blender's Python has no OpenEXR: the LUT bake, the world bake and the validation use the project's own
    EXR writer and reader there (core/lut/exr_writer.py, exr_reader.py)."""
    cache = tmp_path / "environments"
    env = dict(os.environ, RTL_ENVIRONMENT_CACHE=str(cache))
    proc = subprocess.run([sys.executable, "-c", _NO_OPENEXR, str(stale_lut_dir), str(cache), str(tmp_path / "val")],
                          capture_output=True, text=True, timeout=600, env=env, cwd=REPO)
    lines = [ln.partition("RTL_RESULT ")[2] for ln in proc.stdout.splitlines() if "RTL_RESULT " in ln]
    assert proc.returncode == 0 and lines, proc.stdout[-3000:] + proc.stderr[-3000:]
    result = json.loads(lines[0])
    assert result["bake"] == ["FINISHED"] and result["luts"] == ["ok"]
    assert result["sync_world"] == ["FINISHED"] and result["world_group"]
    assert any(name.endswith("_sh.exr") for name in result["cache_files"])
    assert any(name.endswith("_ggx_prefiltered.exr") for name in result["cache_files"])
    assert result["sh_read"]
    assert result["validate"] in (0, None) and result["validation_json"] is True
