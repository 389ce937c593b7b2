"""Build the extension zip, install it into a fresh bpy like a user would, use it, remove it."""
from __future__ import annotations

import re
import zipfile
from pathlib import Path, PurePosixPath

import pytest

from rt_lookdev.validation.tools import extension_zip as build_extension
from _blender_subprocess import run_snippet

#: bpy.ops.rtl.* of the enabled extension
OPERATORS = ["add_node_groups", "add_path_traced_twin", "bake_luts", "convert_to_principled", "convert_to_rt_lit",
             "disable_shadows", "enable_shadows", "export_luts", "export_scene", "light_sync_report", "lut_status",
             "new_lookdev_scene", "sync_lights", "sync_world"]

pytestmark = pytest.mark.blender

MODULE = "bl_ext.user_default.rt_lookdev"

INSTALL_CODE = r'''
import json, sys
from pathlib import Path
import addon_utils

MODULE = "bl_ext.user_default.rt_lookdev"
zip_path = sys.argv[1]
result = {"before": snapshot()}

result["install"] = sorted(bpy.ops.extensions.package_install_files(
    filepath=zip_path, repo="user_default", enable_on_install=True))
result["enabled"] = MODULE in bpy.context.preferences.addons

repo = next(r for r in bpy.context.preferences.extensions.repos if r.module == "user_default")
installed = Path(repo.directory) / "rt_lookdev"
result["installed_dir"] = str(installed)
result["installed_files"] = sorted(
    p.relative_to(installed).as_posix() for p in installed.rglob("*") if p.is_file())

catalog = sys.modules[MODULE + ".core.lut.catalog"]
result["default_lut_dir"] = str(catalog.default_lut_dir())
result["lut_states"] = {s.name: s.state for s in catalog.lut_status(catalog.default_lut_dir())}

result["enabled_state"] = snapshot()
with bpy.data.libraries.load(str(installed / "assets" / "rt_lookdev_presets.blend"), assets_only=True) as (src, _):
    result["preset_assets"] = sorted(src.materials)
prefs = bpy.context.preferences.addons[MODULE].preferences
result["prefs_class"] = type(prefs).__name__
result["prefs_bl_idname"] = type(prefs).bl_idname
result["prefs_lut_directory"] = prefs.lut_directory
cache = installed.parent.parent / "chosen cache"     # inside the sandboxed user directory
prefs.environment_cache = str(cache)
result["env_cache"] = [str(cache), str(sys.modules[MODULE + ".addon.world_sync"].default_cache_dir())]
prefs.environment_cache = ""

result["poll"] = bpy.ops.rtl.lut_status.poll()
print("RTL_OPERATOR_CALL_START", flush=True)
result["lut_status"] = sorted(bpy.ops.rtl.lut_status())
print("RTL_OPERATOR_CALL_END", flush=True)

addon_utils.disable(MODULE, default_set=True)
result["after_disable"] = snapshot()

# A second enable/disable cycle must also leave nothing behind.
addon_utils.enable(MODULE, default_set=True, handle_error=None)
result["reenabled"] = MODULE in bpy.context.preferences.addons
result["reenabled_ops"] = sorted(dir(bpy.ops.rtl))
addon_utils.disable(MODULE, default_set=True)
result["after_second_disable"] = snapshot()
print("\nRTL_RESULT " + json.dumps(result), flush=True)
'''

PREFS_CODE = r'''
import json, sys
zip_path, bad_dir, empty_dir, corrupt_dir = sys.argv[1:5]
MODULE = "bl_ext.user_default.rt_lookdev"
bpy.ops.extensions.package_install_files(filepath=zip_path, repo="user_default", enable_on_install=True)
prefs = bpy.context.preferences.addons[MODULE].preferences

def call():
    try:
        return {"result": sorted(bpy.ops.rtl.lut_status()), "error": None}
    except RuntimeError as ex:
        return {"result": None, "error": str(ex)}

result = {"poll_default": bpy.ops.rtl.lut_status.poll()}
prefs.lut_directory = bad_dir
result["poll_bad"] = bpy.ops.rtl.lut_status.poll()
result["bad"] = call()
prefs.lut_directory = empty_dir
print("RTL_EMPTY_START", flush=True)
result["empty"] = call()
print("RTL_EMPTY_END", flush=True)
prefs.lut_directory = corrupt_dir
result["corrupt"] = call()
prefs.lut_directory = ""
result["poll_reset"] = bpy.ops.rtl.lut_status.poll()
print("\nRTL_RESULT " + json.dumps(result), flush=True)
'''


@pytest.fixture(scope="module")
def extension_zip(tmp_path_factory):
    return build_extension.build(tmp_path_factory.mktemp("dist"))


def test_zip_holds_runtime_files_only(extension_zip):
    names = zipfile.ZipFile(extension_zip).namelist()
    manifest = build_extension.read_manifest()
    assert manifest["id"] == "rt_lookdev"
    assert extension_zip.name == f"rt_lookdev-{manifest['version']}.zip"
    for required in ("__init__.py", "blender_manifest.toml", "addon/__init__.py", "core/__init__.py"):
        assert required in names
    assert any(n.startswith("core/lut/") for n in names)
    assert any(n.startswith("node_groups/") for n in names)
    assert any(PurePosixPath(n).match("luts/*.exr") for n in names)
    top = {PurePosixPath(n).parts[0] for n in names}
    assert not top & {"tests", "scripts", "validation", "docs", ".ci", ".git", ".venv", "dist", "out",
                      "pyproject.toml"}
    assert not [n for n in names if "__pycache__" in n or n.endswith(".pyc")]


def test_zip_check_rejects_development_files():
    good = ["__init__.py", "blender_manifest.toml", "addon/__init__.py", "core/__init__.py",
            "core/lut/catalog.py", "node_groups/__init__.py", "luts/e.exr", "assets/rt_lookdev_presets.blend",
            "assets/blender_assets.cats.txt"]
    build_extension.check_zip_contents(good, ["luts/e.exr"])
    for extra in ("tests/conftest.py", "scripts/env.sh", "validation/checks/suite.py", ".ci/run", "core/__pycache__/x.pyc"):
        with pytest.raises(build_extension.BuildError, match="should not be shipped"):
            build_extension.check_zip_contents(good + [extra])
    with pytest.raises(build_extension.BuildError, match="missing LUT: luts/f.exr"):
        build_extension.check_zip_contents(good, ["luts/f.exr"])
    with pytest.raises(build_extension.BuildError, match="no luts/\\*.exr"):
        build_extension.check_zip_contents([n for n in good if not n.endswith(".exr")])


def test_install_enable_run_disable_leaves_nothing_behind(extension_zip, tmp_path):
    user_dir = tmp_path / "blender-user"
    result, output = run_snippet(INSTALL_CODE, user_dir, str(extension_zip))

    assert result["install"] == ["FINISHED"]
    assert result["enabled"], "extension not enabled after package_install_files"
    assert MODULE not in result["before"]["addons"]

    # Installed into the sandboxed user directory, with the shipped tables.
    assert result["installed_dir"].startswith(str(user_dir))
    files = result["installed_files"]
    assert "blender_manifest.toml" in files and "addon/operators.py" in files
    exrs = [f for f in files if PurePosixPath(f).match("luts/*.exr")]
    assert exrs, f"no luts/*.exr installed: {files}"
    assert not [f for f in files if f.startswith(("tests/", "scripts/", "validation/", ".ci/"))]
    # The installed add-on reads its own copy of the tables, and they are all ok.
    assert result["default_lut_dir"].startswith(result["installed_dir"])
    assert result["lut_states"] and set(result["lut_states"].values()) == {"ok"}, result["lut_states"]

    # Enabled: the operators and preferences are registered under the extension's name, and the presets are
    # an asset library of the installed copy
    assert result["enabled_state"]["ops_rtl"] == OPERATORS
    libraries = [path for name, path in result["enabled_state"]["asset_libraries"] if name == "RT Lookdev"]
    assert libraries and libraries[0].rstrip("/") == str(Path(result["installed_dir"]) / "assets")
    assert "RTL Gold" in result["preset_assets"] and len(result["preset_assets"]) >= 10
    assert result["prefs_bl_idname"] == MODULE
    assert result["prefs_class"] == "RTL_AddonPreferences"
    assert result["prefs_lut_directory"] == ""
    chosen, used = result["env_cache"]           # the preference "Environment Cache" is where worlds bake
    assert used == chosen and Path(chosen).is_dir()

    assert result["poll"] is True
    assert result["lut_status"] == ["FINISHED"]
    call_output = output.split("RTL_OPERATOR_CALL_START", 1)[1].split("RTL_OPERATOR_CALL_END", 1)[0]
    assert re.search(rf"Info: All {len(result['lut_states'])} LUT tables are up to date", call_output), call_output

    # Disabling restores exactly the state before installation.
    for key in ("after_disable", "after_second_disable"):
        after = result[key]
        for field, before in result["before"].items():
            assert after[field] == before, f"{key}: {field} differs from before install"
    assert result["reenabled"] and result["reenabled_ops"] == OPERATORS


def test_operator_poll_and_reports_follow_the_lut_directory_preference(extension_zip, tmp_path):
    bad_dir = tmp_path / "no such luts"
    empty_dir = tmp_path / "empty"
    empty_dir.mkdir()
    corrupt_dir = tmp_path / "corrupt"
    corrupt_dir.mkdir()
    with zipfile.ZipFile(extension_zip) as zf:
        exrs = [n for n in zf.namelist() if PurePosixPath(n).match("luts/*.exr")]
        for name in exrs:
            (corrupt_dir / PurePosixPath(name).name).write_bytes(b"not an EXR file")
    result, output = run_snippet(
        PREFS_CODE, tmp_path / "blender-user", str(extension_zip), str(bad_dir), str(empty_dir), str(corrupt_dir))

    # Poll fails, with a message naming the directory, while the preference points nowhere.
    assert result["poll_default"] is True
    assert result["poll_bad"] is False
    assert result["bad"]["result"] is None, "operator ran although its LUT directory does not exist"
    assert f"LUT directory does not exist: {bad_dir}" in result["bad"]["error"]
    assert result["poll_reset"] is True

    # An empty directory: every table missing -> WARNING, operator still finishes.
    assert result["empty"] == {"result": ["FINISHED"], "error": None}
    empty_output = output.split("RTL_EMPTY_START", 1)[1].split("RTL_EMPTY_END", 1)[0]
    assert "Warning: LUT tables need baking" in empty_output and "missing:" in empty_output, empty_output

    # Unreadable files: ERROR and CANCELLED (raised as RuntimeError when called from Python).
    assert result["corrupt"]["result"] is None
    assert result["corrupt"]["error"].startswith("Error: Unusable LUT tables"), result["corrupt"]["error"]
    for name in exrs:
        assert PurePosixPath(name).stem in result["corrupt"]["error"]


def test_build_refuses_when_luts_are_not_baked(tmp_path, monkeypatch):
    from rt_lookdev.core.lut import catalog

    monkeypatch.setattr(catalog, "default_lut_dir", lambda: tmp_path / "luts")
    with pytest.raises(build_extension.BuildError, match="python scripts/bake_luts.py") as info:
        build_extension.build(tmp_path / "dist")
    assert "missing" in str(info.value)
    assert not (tmp_path / "dist").exists(), "nothing may be built when LUTs are missing"
