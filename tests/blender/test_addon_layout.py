"""Structure rules of the add-on: no bpy in the core, Blender naming conventions, clean (un)register."""
from __future__ import annotations

import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

REPO_ROOT = Path(__file__).resolve().parents[2]

NO_BPY_CODE = textwrap.dedent(
    """
    import json, pkgutil, importlib, sys
    import rt_lookdev, rt_lookdev.core
    imported = ["rt_lookdev", "rt_lookdev.core"]
    for info in pkgutil.walk_packages(rt_lookdev.core.__path__, "rt_lookdev.core."):
        importlib.import_module(info.name)
        imported.append(info.name)
    print(json.dumps({"imported": imported, "bpy_loaded": "bpy" in sys.modules,
                      "bpy_like": sorted(m for m in sys.modules if m.split(".")[0] in
                                         ("bpy", "bmesh", "mathutils", "addon_utils", "_bpy"))}))
    """
)


def test_package_and_core_do_not_import_bpy():
    proc = subprocess.run(
        [sys.executable, "-c", NO_BPY_CODE],
        capture_output=True, text=True, timeout=300,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    import json

    result = json.loads(proc.stdout.strip().splitlines()[-1])
    core_files = {
        ".".join(("rt_lookdev",) + p.relative_to(REPO_ROOT).with_suffix("").parts).removesuffix(".__init__")
        for p in (REPO_ROOT / "core").rglob("*.py")
    }
    assert core_files <= set(result["imported"]), f"not imported: {core_files - set(result['imported'])}"
    assert not result["bpy_loaded"] and not result["bpy_like"], result["bpy_like"]


OPERATOR_NAME = re.compile(r"^(?P<prefix>[A-Z][A-Z0-9]*)_OT_(?P<name>[a-z][a-z0-9_]*)$")
TYPE_TAGS = {"Panel": "PT", "Menu": "MT", "UIList": "UL", "Header": "HT"}


@pytest.mark.blender
def test_registered_classes_follow_blender_naming(bpy_module):
    from rt_lookdev import addon

    operators = [c for c in addon.classes if issubclass(c, bpy_module.types.Operator)]
    assert operators, "addon.classes holds no operators"
    for cls in operators:
        match = OPERATOR_NAME.match(cls.__name__)
        assert match, f"{cls.__name__}: operator classes must be named PREFIX_OT_name"
        expected = f"{match['prefix'].lower()}.{match['name']}"
        assert cls.bl_idname == expected, f"{cls.__name__}.bl_idname is {cls.bl_idname!r}, expected {expected!r}"
        assert getattr(cls, "bl_label", ""), f"{cls.__name__} has no bl_label"
    for cls in addon.classes:
        for base, tag in TYPE_TAGS.items():
            if issubclass(cls, getattr(bpy_module.types, base)):
                assert re.match(rf"^[A-Z][A-Z0-9]*_{tag}_\w+$", cls.__name__), f"{cls.__name__}: use PREFIX_{tag}_name"
    assert len(set(addon.classes)) == len(addon.classes), "a class is listed twice"


@pytest.mark.blender
def test_register_unregister_in_process(bpy_module, empty_scene):
    """Registering the source tree directly (no addon_utils) works and falls back to the shipped luts/."""
    import rt_lookdev
    from rt_lookdev.addon import preferences
    from rt_lookdev.core.lut import catalog

    assert preferences.ADDON_PACKAGE == "rt_lookdev"
    assert preferences.RTL_AddonPreferences.bl_idname == "rt_lookdev"
    before = set(dir(bpy_module.types))
    rt_lookdev.register()
    try:
        assert "RTL_OT_lut_status" in dir(bpy_module.types)
        assert preferences.get_preferences() is None  # not enabled through addon_utils
        assert preferences.lut_directory() == catalog.default_lut_dir()
        assert bpy_module.ops.rtl.lut_status.poll() == catalog.default_lut_dir().is_dir()
    finally:
        rt_lookdev.unregister()
    assert set(dir(bpy_module.types)) == before
    assert "lut_status" not in dir(bpy_module.ops.rtl)
    # conftest sandboxed the user directory before bpy was imported.
    assert bpy_module.utils.user_resource('EXTENSIONS').startswith(os.environ["BLENDER_USER_RESOURCES"])


@pytest.mark.blender
def test_an_unsupported_blender_is_refused_with_the_supported_releases(bpy_module, monkeypatch):
    """On a Blender older than the manifest's minimum, register() raises a message naming the supported
    releases and registers nothing (instead of failing later on a missing API)."""
    import tomllib

    import rt_lookdev
    from rt_lookdev.addon import compat

    manifest = tomllib.loads((REPO_ROOT / "blender_manifest.toml").read_text())
    assert tuple(int(x) for x in manifest["blender_version_min"].split(".")) == compat.MINIMUM_VERSION
    before = set(dir(bpy_module.types))
    monkeypatch.setattr(compat, "version", lambda: (4, 2, 23))
    with pytest.raises(RuntimeError, match=r"needs Blender 4\.5\.0 or newer .*4\.5 LTS.*this is 4\.2\.23"):
        rt_lookdev.register()
    assert set(dir(bpy_module.types)) == before
    monkeypatch.undo()
    assert compat.supported()             # the release under test is a supported one


class _RecordingLayout:
    """Stands in for bpy.types.UILayout (which cannot be created headless); records calls."""

    def __init__(self, calls):
        self.calls = calls

    def _child(self, *args, **kwargs):
        return self

    box = column = row = _child

    def label(self, text="", icon='NONE'):
        self.calls.append(("label", text, icon))

    def prop(self, data, name, **kwargs):
        self.calls.append(("prop", name))

    def operator(self, idname, **kwargs):
        self.calls.append(("operator", idname, kwargs.get("icon", 'NONE')))


@pytest.mark.blender
def test_preferences_draw_lists_every_table(bpy_module, tmp_path):
    from types import SimpleNamespace

    from rt_lookdev.addon import preferences
    from rt_lookdev.core.lut import catalog

    valid_icons = set(bpy_module.types.UILayout.bl_rna.functions["label"].parameters["icon"].enum_items.keys())
    assert set(preferences.STATE_ICONS.values()) <= valid_icons
    # Every state the catalog can report has an icon.
    assert set(preferences.STATE_ICONS) == {"ok", "missing", "stale", "corrupt", "mismatch"}

    calls = []
    fake_prefs = SimpleNamespace(layout=_RecordingLayout(calls), lut_directory=str(tmp_path))
    fake_context = SimpleNamespace(preferences=SimpleNamespace(addons={
        preferences.ADDON_PACKAGE: SimpleNamespace(preferences=fake_prefs)}))
    preferences.clear_status_cache()
    preferences.RTL_AddonPreferences.draw(fake_prefs, fake_context)

    statuses = catalog.lut_status(tmp_path)  # an empty folder: every table missing
    labels = [c for c in calls if c[0] == "label"]
    for status in statuses:
        assert ("label", status.name, preferences.STATE_ICONS["missing"]) in labels
    assert ("prop", "lut_directory") in calls
    assert calls[-2][:2] == ("operator", "rtl.lut_status") and calls[-1][:2] == ("operator", "rtl.bake_luts")
    assert ("prop", "environment_cache") in calls
    for call in calls:
        if call[0] in ("label", "operator"):
            assert call[-1] in valid_icons | {'NONE'}, call
    assert str(tmp_path) in preferences._status_cache
    preferences.clear_status_cache()


@pytest.mark.blender
def test_a_python_process_with_the_add_on_registered_exits(tmp_path):
    """``import bpy``, register, exit without unregistering: the process ends, cleanly.  Before 5.0 the bpy module
    hangs for ever at exit while a class is registered (addon/compat.py, ``module_exit_hangs_while_registered``);
    the add-on unregisters itself at exit there, once, even after an earlier register / unregister pair."""
    from _blender_subprocess import run_snippet

    code = textwrap.dedent(
        """
        import json
        from rt_lookdev import addon
        addon.register(); addon.unregister()
        addon.register()
        print("RTL_RESULT " + json.dumps({"registered": "RTL_OT_lut_status" in dir(bpy.types)}))
        """
    )
    result, output = run_snippet(code, tmp_path / "user", timeout=120)
    assert result == {"registered": True}
    assert "Traceback" not in output and "Error in atexit" not in output, output
