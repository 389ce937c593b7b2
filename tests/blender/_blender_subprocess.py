"""Run a Python snippet in a fresh interpreter with its own Blender user directory.

bpy reads ``BLENDER_USER_RESOURCES`` once, when it is imported, and can never be
re-imported in a process, so tests that install the extension run in a subprocess
of the same interpreter.  The snippet prints ``RTL_RESULT <json>`` on one line.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

RESULT_PREFIX = "RTL_RESULT "

#: Code shared by the snippets: snapshot of everything an add-on can register.
SNAPSHOT_CODE = r'''
import bpy

def snapshot():
    wm = bpy.context.window_manager
    kc = wm.keyconfigs.addon
    handlers = {}
    for name in dir(bpy.app.handlers):
        value = getattr(bpy.app.handlers, name)
        if isinstance(value, list):
            handlers[name] = len(value)
    return {
        "types": sorted(dir(bpy.types)),
        "ops_rtl": sorted(dir(bpy.ops.rtl)),
        "handlers": handlers,
        "addon_keymaps": None if kc is None else sorted(
            [km.name, len(km.keymap_items)] for km in kc.keymaps
        ),
        "scene_props": sorted(bpy.types.Scene.bl_rna.properties.keys()),
        "window_manager_props": sorted(bpy.types.WindowManager.bl_rna.properties.keys()),
        "addons": sorted(bpy.context.preferences.addons.keys()),
        "asset_libraries": sorted([lib.name, lib.path] for lib in bpy.context.preferences.filepaths.asset_libraries),
    }
'''


def run_snippet(code: str, user_resources: Path, *args: str, timeout: float = 300) -> tuple[dict, str]:
    """Run ``code`` with ``sys.argv[1:] = args``; return (parsed result, full output)."""
    env = dict(os.environ)
    env["BLENDER_USER_RESOURCES"] = str(user_resources)
    proc = subprocess.run(
        [sys.executable, "-c", SNAPSHOT_CODE + code, *args],
        capture_output=True,
        text=True,
        env=env,
        timeout=timeout,
    )
    output = proc.stdout + proc.stderr
    # Blender's report printer may leave a line unterminated, so look anywhere in a line.
    results = [line.partition(RESULT_PREFIX)[2] for line in proc.stdout.splitlines() if RESULT_PREFIX in line]
    if proc.returncode != 0 or len(results) != 1:
        raise AssertionError(
            f"subprocess failed (exit {proc.returncode}, {len(results)} result lines); output:\n{output}"
        )
    return json.loads(results[0]), output
