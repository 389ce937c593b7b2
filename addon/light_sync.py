"""Lights in sync without a button: a depsgraph handler that re-syncs the RT Lit groups when the scene's
shaded lights change (a light added, removed, hidden from renders, moved to an excluded collection, or an
area light changing shape).

Moving and editing a light needs no sync: drivers carry its transform and data into the groups, with
Python auto-run off too.  The handler only compares the lights' signature (name, kind, shape:
``materials.light_signature``) with the one stored at the last sync, so an update that changes nothing
costs a walk over the scene's objects (measured: docs/benchmarks/light_sync.md).  It is on by default;
the preference "Sync Lights Automatically" turns it off.
"""
from __future__ import annotations

import bpy
from bpy.app.handlers import persistent

from . import materials, preferences

#: Update kinds (datablock types) that can change which lights a scene shades.
_RELEVANT = (bpy.types.Object, bpy.types.Collection, bpy.types.Light, bpy.types.Scene)
_busy = [False]


def enabled():
    prefs = preferences.get_preferences()
    return True if prefs is None else bool(prefs.auto_sync_lights)


def sync_if_needed(scene, lut_dir=None):
    """Re-sync the RT Lit groups when ``scene``'s lights changed since the last sync; returns whether it did."""
    if _busy[0] or not materials.lights_out_of_sync(scene):
        return False
    _busy[0] = True
    try:
        materials.sync_scene_lights(scene)
        materials.rebuild_rt_lit_groups(scene, lut_dir if lut_dir is not None else preferences.lut_directory())
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
