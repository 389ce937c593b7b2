"""Lights in sync without a button: a depsgraph handler that re-syncs the RT Lit groups when the scene's
shaded lights change (a light added, removed, hidden from renders, moved to an excluded collection, or an
area light changing shape), and converts a lookdev preset to RT Lit when it is first used
(``preset_assets.convert_pending``: a preset dropped from the Asset Browser).

Moving and editing a light needs no sync: drivers carry its transform and data into the groups, with
Python auto-run off too.  The handler only compares the lights' signature (name, kind, shape:
``materials.light_signature``) with the one stored at the last sync, so an update that changes nothing
costs a walk over the scene's objects (measured: docs/benchmarks/light_sync.md).  It is on by default;
the preference "Sync Lights Automatically" turns it off.

All or nothing.  A sync (``sync_lights``, also what Sync Lights runs) that fails half-way (a LUT file missing or
damaged, the world's bake gone, an error building a tree) leaves every group and material as it was
(``common.node_groups_kept_on_error``) and says so where the user looks: the RT Lookdev panels show the message
(``failure``) until a sync succeeds, the status bar gets it as a warning, and it names the way out the extension
offers (Bake LUTs, in the preferences and in the panel, which syncs the lights once it has baked).  The handler does
not retry a failed sync until something it depends on changed (the lights or what they reach, the LUT folder and its
files, the world's bake).
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import bpy
from bpy.app.handlers import persistent

from ..core.lut.exr_io import LutError
from . import materials, preferences, preset_assets as presets
from .common import WORLD_GROUP, WORLD_RECORD_KEY, node_groups_kept_on_error

#: Update kinds (datablock types) that can change which lights a scene shades, or assign a preset.
_RELEVANT = (bpy.types.Object, bpy.types.Collection, bpy.types.Light, bpy.types.Scene, bpy.types.Material)
_busy = [False]
#: scene name -> ``Failure``: the last sync of the scene that failed (shown by the panels until one succeeds).
_failures = {}


class SyncError(RuntimeError):
    """A light sync that could not complete and changed nothing; the message says what to do."""


@dataclass(frozen=True)
class Failure:
    """A failed light sync: the ``message`` the user sees, whether baking the LUTs is the way out (``luts``), and
    what the sync depended on (``key``, ``_attempt_key``): the handler does not retry while it is the same."""
    message: str
    luts: bool
    key: tuple


def enabled():
    prefs = preferences.get_preferences()
    return True if prefs is None else bool(prefs.auto_sync_lights)


def failure(scene):
    """The last failed light sync of ``scene`` (``Failure``), or None when its last sync succeeded or nothing waits
    for one."""
    return _failures.get(scene.name) if scene is not None else None


KEPT = "RT Lit keeps the lights of the last sync"


def failure_message(ex, lut_dir):
    """What the user reads when a sync fails with ``ex``: the cause and the way out the extension offers."""
    if isinstance(ex, LutError):
        try:
            statuses = preferences.refresh_status(Path(lut_dir))      # the preferences show the same states
            found = preferences.summarise_status(statuses, [s for s in preferences.STATE_ICONS if s != "ok"])
        except Exception:                                              # noqa: BLE001 - the message still says why
            found = ""
        cause = found or str(ex).split(" Bake it with")[0].split(" Re-bake")[0]
        return f"Lights not synced: LUT tables in {lut_dir} cannot be read ({cause}); {preferences.BAKE_HINT}. {KEPT}"
    return f"Lights not synced ({type(ex).__name__}: {ex}). {KEPT}"


def _failed(scene, ex, lut_dir):
    """Record the failure of a sync of ``scene`` and return the SyncError that says it."""
    message = failure_message(ex, lut_dir)
    _failures[scene.name] = Failure(message, isinstance(ex, LutError), _attempt_key(scene, lut_dir))
    return SyncError(message)


def sync_lights(scene, lut_dir=None):
    """Sync "RTL Scene Lights" with ``scene``'s lights and rebuild the RT Lit groups for them (Sync Lights), all or
    nothing: on failure every group and material is as before and ``SyncError`` says why and what to do; the outcome
    is recorded for the panels (``failure``).  Returns (records, RT Lit groups rebuilt)."""
    lut_dir = Path(lut_dir) if lut_dir is not None else preferences.lut_directory()
    try:
        with node_groups_kept_on_error():
            records = materials.sync_scene_lights(scene)
            groups = materials.rebuild_rt_lit_groups(scene, lut_dir)
    except Exception as ex:
        raise _failed(scene, ex, lut_dir) from ex
    _failures.pop(scene.name, None)
    return records, groups


def sync_if_needed(scene, lut_dir=None):
    """Convert the presets first used since the last update, then re-sync the RT Lit groups when ``scene``'s lights
    changed since the last sync; returns whether anything was done (raises ``SyncError`` when a sync failed: nothing
    was changed)."""
    if _busy[0]:
        return False
    pending = presets.pending_presets()
    stale = materials.lights_out_of_sync(scene)
    if not stale:
        _failures.pop(scene.name, None)         # nothing waits for a sync: an earlier failure no longer holds
    if not pending and not stale:
        return False
    lut_dir = Path(lut_dir) if lut_dir is not None else preferences.lut_directory()
    failed = _failures.get(scene.name)
    if not pending and failed is not None and failed.key == _attempt_key(scene, lut_dir):
        return False                            # this sync failed, and nothing it depends on changed since
    _busy[0] = True
    try:
        for material in pending:
            try:
                with node_groups_kept_on_error():
                    presets.convert_preset(material, scene, lut_dir)
            except Exception as ex:
                raise _failed(scene, ex, lut_dir) from ex
        if materials.lights_out_of_sync(scene):
            sync_lights(scene, lut_dir)
    finally:
        _busy[0] = False
    return True


def _attempt_key(scene, lut_dir):
    """What a sync depends on besides the groups it rebuilds: the lights and what they reach, the LUT folder and its
    files, the world's bake."""
    try:
        files = tuple(sorted((e.name, e.stat().st_size, e.stat().st_mtime_ns) for e in os.scandir(lut_dir)))
    except OSError:
        files = ()
    world = bpy.data.node_groups.get(WORLD_GROUP)
    record = world.get(WORLD_RECORD_KEY) if world is not None else None
    records = materials.scene_lights(scene)
    lights = (tuple(materials.light_signature(records)),
              tuple(sorted((k, tuple(v)) for k, v in materials.material_reach(scene, records).items())))
    return lights, str(lut_dir), files, repr(record.to_dict()) if hasattr(record, "to_dict") else repr(record)


# --- the handler ------------------------------------------------------------------------------------------------------

@persistent
def on_depsgraph_update(scene, depsgraph=None):
    if _busy[0]:
        return
    if not enabled():
        return
    if depsgraph is not None and not any(isinstance(u.id, _RELEVANT) for u in depsgraph.updates):
        return
    try:
        sync_if_needed(scene)
    except SyncError as ex:        # never break the user's edit: nothing was changed, and the panels say why
        print(f"RT Lookdev: {ex}")
        _report_later(str(ex))
    except Exception as ex:        # noqa: BLE001 - the same: the user's edit goes on
        print(f"RT Lookdev: automatic light sync failed ({type(ex).__name__}: {ex}); use Sync Lights")


def _report_later(message):
    """Show ``message`` as a warning in the status bar (``rtl.light_sync_report``, from a timer: a handler cannot
    report) and redraw the panels that show it; nothing without a window."""
    if bpy.app.background:
        return

    def report():
        wm = bpy.context.window_manager
        window = wm.windows[0] if wm is not None and wm.windows else None
        if window is None:
            return None
        try:
            with bpy.context.temp_override(window=window):
                bpy.ops.rtl.light_sync_report(message=message)
        except Exception as ex:    # noqa: BLE001 - the panels show the message anyway
            print(f"RT Lookdev: could not report the light sync's failure ({ex})")
        for win in wm.windows:
            for area in win.screen.areas:
                if area.type in {'PROPERTIES', 'VIEW_3D'}:
                    area.tag_redraw()
        return None

    bpy.app.timers.register(report, first_interval=0.0)


@persistent
def on_load(*_):
    """Another file: none of this one's failures holds there."""
    _failures.clear()


def register():
    if on_depsgraph_update not in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.append(on_depsgraph_update)
    if on_load not in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.append(on_load)


def unregister():
    if on_depsgraph_update in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.remove(on_depsgraph_update)
    if on_load in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.remove(on_load)
