"""Lights in sync without a button: a depsgraph handler that re-syncs the RT Lit groups when the scene's
shaded lights change (a light added, removed, hidden from renders, moved to an excluded collection, or an
area light changing shape), and converts a lookdev preset to RT Lit when it is first used
(``preset_assets.convert_pending``: a preset dropped from the Asset Browser).

Moving and editing a light needs no sync: drivers carry its transform and data into the groups, with
Python auto-run off too.  The handler only compares the lights' signature (name, kind, shape:
``materials.light_signature``) with the one stored at the last sync, so an update that changes nothing
costs a walk over the scene's objects (measured: docs/benchmarks/light_sync.md).  It is on by default;
the preference "Sync Lights Automatically" turns it off.
"""
from __future__ import annotations

import bpy
from bpy.app.handlers import persistent

from . import materials, preferences, preset_assets as presets

#: Update kinds (datablock types) that can change which lights a scene shades, or assign a preset.
_RELEVANT = (bpy.types.Object, bpy.types.Collection, bpy.types.Light, bpy.types.Scene, bpy.types.Material)
_busy = [False]


def enabled():
    prefs = preferences.get_preferences()
    return True if prefs is None else bool(prefs.auto_sync_lights)


def sync_if_needed(scene, lut_dir=None):
    """Convert the presets first used since the last update, then re-sync the RT Lit groups when ``scene``'s
    lights changed since the last sync; returns whether anything was done."""
    if _busy[0]:
        return False
    pending = presets.pending_presets()
    if not pending and not materials.lights_out_of_sync(scene):
        return False
    lut_dir = lut_dir if lut_dir is not None else preferences.lut_directory()
    _busy[0] = True
    try:
        for material in pending:
            presets.convert_preset(material, scene, lut_dir)
        if materials.lights_out_of_sync(scene):
            materials.sync_scene_lights(scene)
            materials.rebuild_rt_lit_groups(scene, lut_dir)
    finally:
        _busy[0] = False
    return True


@persistent
def on_depsgraph_update(scene, depsgraph=None):
    if _busy[0] or not enabled():
        return
    if depsgraph is not None and not any(isinstance(u.id, _RELEVANT) for u in depsgraph.updates):
        return
    try:
        sync_if_needed(scene)
    except Exception as ex:       # never break the user's edit; Sync Lights reports the cause
        print(f"RT Lookdev: automatic light sync failed ({type(ex).__name__}: {ex}); use Sync Lights")


def register():
    if on_depsgraph_update not in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.append(on_depsgraph_update)


def unregister():
    if on_depsgraph_update in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.remove(on_depsgraph_update)
