"""Lights in sync without a button: a depsgraph handler that re-syncs the RT Lit groups when the scene's
shaded lights change (a light added, removed, hidden from renders, moved to an excluded collection, or an
area light changing shape) or what their ranges reach does, and converts a lookdev preset to RT Lit when it is
first used (``preset_assets.convert_pending``: a preset dropped from the Asset Browser).

Moving and editing a light needs no sync: drivers carry its transform and data into the groups, with
Python auto-run off too.  The handler compares the lights' signature (name, kind, shape:
``materials.light_signature``) and which lights reach which material (``materials.material_reach``) with the ones
stored at the last sync.  It is on by default; the preference "Sync Lights Automatically" turns it off.

What an update costs.  A full check walks every object (1.6 ms at 1,000 objects, 9 ms once a light has a range), and
moving a light updates every object whose material uses "RTL Scene Lights".  So the handler keeps, per scene, what the
last full check found (``_SceneState``: the shaded lights, and with a ranged light the sphere around each rendered
object, by material) and re-reads only what an update names (``Updates``): the shaded lights when an object or a light
changed (a few; a rename has no flag), the objects whose transform or geometry changed.  An update of a collection, a
change of the view layers' collections, or an object the state does not know is checked in full.  Measured:
docs/benchmarks/light_sync.md.

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
import numpy as np
from bpy.app.handlers import persistent

from ..core.lut.exr_io import LutError
from . import materials, preferences, preset_assets as presets, shadows
from .common import WORLD_GROUP, WORLD_RECORD_KEY, node_groups_kept_on_error

_busy = [False]
#: scene pointer -> ``_SceneState``: what the last full check of the scene found, followed since.
_states = {}
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
    _failures[scene.name] = Failure(message, isinstance(ex, LutError), _attempt_key(_state(scene), lut_dir))
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
    shadows.refresh_shadows(scene, lut_dir)      # the shadow probes' light copies follow the synced lights
    return records, groups


def sync_if_needed(scene, lut_dir=None, updates=None):
    """Convert the presets first used since the last update, then re-sync the RT Lit groups when ``scene``'s lights
    or what they reach changed since the last sync; returns whether anything was done (raises ``SyncError`` when a
    sync failed: nothing was changed).  ``updates``: what the depsgraph update that calls names (``Updates``), all
    that is re-read; without it everything is checked."""
    if _busy[0]:
        return False
    pending = presets.pending_presets()
    state = _state(scene, updates)
    stale = state is not None and state.out_of_sync()
    if not stale:
        _failures.pop(scene.name, None)         # nothing waits for a sync: an earlier failure no longer holds
    if not pending and not stale:
        return False
    lut_dir = Path(lut_dir) if lut_dir is not None else preferences.lut_directory()
    failed = _failures.get(scene.name)
    if not pending and failed is not None and failed.key == _attempt_key(state, lut_dir):
        return False                            # this sync failed, and nothing it depends on changed since
    _busy[0] = True
    try:
        for material in pending:
            try:
                with node_groups_kept_on_error():
                    presets.convert_preset(material, scene, lut_dir)
            except Exception as ex:
                raise _failed(scene, ex, lut_dir) from ex
        # in full before a sync: the state followed from updates is checked against a fresh one
        state = _state(scene)
        if state is not None and state.out_of_sync():
            sync_lights(scene, lut_dir)
    finally:
        _busy[0] = False
    return True


def _attempt_key(state, lut_dir):
    """What a sync depends on besides the groups it rebuilds: the lights and what they reach (``state``), the LUT
    folder and its files, the world's bake."""
    try:
        files = tuple(sorted((e.name, e.stat().st_size, e.stat().st_mtime_ns) for e in os.scandir(lut_dir)))
    except OSError:
        files = ()
    world = bpy.data.node_groups.get(WORLD_GROUP)
    record = world.get(WORLD_RECORD_KEY) if world is not None else None
    lights = (tuple(state.signature), tuple(sorted((k, tuple(v)) for k, v in state.reach().items()))) \
        if state is not None else ()
    return lights, str(lut_dir), files, repr(record.to_dict()) if hasattr(record, "to_dict") else repr(record)


# --- following the scene between updates ----------------------------------------------------------------------------

class Updates:
    """What one depsgraph update names that the light sync depends on, read without a Python loop over its entries:
    moving a light updates every object whose material uses "RTL Scene Lights" (2,000 entries at 1,000 objects, 25 ms
    to walk in Python), so the kinds come from ``id_type_updated`` and the moved objects from the entries' flags
    (``foreach_get``)."""

    #: Up to this many entries are walked in Python, and up to this many moved objects looked up one by one (each
    #: lookup walks the entries in C); more, in one walk.
    LOOKUPS = 32

    def __init__(self, depsgraph):
        updated = depsgraph.id_type_updated
        self.collections = updated('COLLECTION')     # only a full check follows these
        self.scene = updated('SCENE')                # its view layers' collections are compared
        self.objects = updated('OBJECT')
        self.lights = updated('LIGHT')
        # the kinds of datablock that can change which lights a scene shades and what they reach, or assign a preset
        self.relevant = self.collections or self.scene or self.objects or self.lights or updated('MATERIAL')
        self._depsgraph = depsgraph
        self._changed = None

    def moved(self):
        """The objects whose transform or geometry this update changed (originals)."""
        return self._scan()[0]

    def light_data(self):
        """The pointers of the light data whose transform or geometry this update changed (a light's data edited: its
        power, shape, controls)."""
        return self._scan()[1]

    def _scan(self):
        """The entries with a transform or geometry change, read once: (objects, light data pointers)."""
        if self._changed is None:
            updates = self._depsgraph.updates
            count = len(updates)
            if count <= self.LOOKUPS:             # a few entries: walked once
                blocks = [u.id for u in updates if u.is_updated_transform or u.is_updated_geometry]
            else:
                changed, geometry = np.zeros(count, bool), np.zeros(count, bool)
                updates.foreach_get("is_updated_transform", changed)
                updates.foreach_get("is_updated_geometry", geometry)
                changed |= geometry
                found = np.flatnonzero(changed)
                if len(found) <= self.LOOKUPS:
                    blocks = [updates[int(i)].id for i in found]
                else:
                    blocks = [update.id for update, flag in zip(updates, changed) if flag]
            self._changed = ([block.original for block in blocks if isinstance(block, bpy.types.Object)],
                             {block.original.as_pointer() for block in blocks if isinstance(block, bpy.types.Light)})
        return self._changed


def followed_objects():
    """The light objects the handler holds between updates, in every scene it follows: what it reads at the next
    update (none after a load or an undo or redo step, ``on_undo_step``)."""
    return [obj for state in _states.values() for _, _, obj, _ in state.lights.values()]


def _state(scene, updates=None):
    """``scene``'s ``_SceneState`` brought up to date with ``updates`` (checked in full without them, or when they
    name what only a full check follows); None when the file has no RT Lit group (nothing to keep in sync)."""
    key = scene.as_pointer()
    if not materials.has_rt_lit_groups():
        _states.pop(key, None)
        return None
    state = _states.get(key)
    if state is None or updates is None or not state.follow(scene, updates):
        state = _states[key] = _SceneState(scene)
    return state


class _SceneState:
    """What a full check of a scene finds, kept up to date from depsgraph updates: the shaded lights (their signature
    entries, and the location and range of the ranged ones) and, when a light has a range, the sphere around each
    rendered object by material (``_Spheres``) and which lights reach none of a material's objects."""

    def __init__(self, scene):
        records = materials.scene_lights(scene)
        self.count = len(records)
        self.signature = materials.light_signature(records)
        self.layout = materials.render_layout(scene)
        self.lights = {obj.as_pointer(): (i, entry, obj, obj.name)
                       for i, ((obj, _), entry) in enumerate(zip(records, self.signature))}
        self.ranged = {i: (loc, r) for i, loc, r in materials.ranged_lights(records)}
        self.spheres = None
        if self.ranged:
            rendered = materials.rendered_objects(scene)
            self.rendered = {obj.as_pointer() for obj in rendered}
            self.spheres = _Spheres(scene, rendered)
        self.beyond = None          # {material pointer: lights reaching none of its objects}, None: to compute
        self.moved_lights = set()   # indices of the ranged lights moved since ``beyond`` was computed

    def follow(self, scene, updates):
        """Re-read what ``updates`` names; False when only a full check can follow them."""
        if updates.collections or (updates.scene and materials.render_layout(scene) != self.layout):
            return False
        try:
            if (updates.objects or updates.lights) and not self._follow_lights(updates):
                return False
            if self.spheres is not None and updates.objects:
                for obj in updates.moved():    # one not rendered stays so while the render's collections are the same
                    pointer = obj.as_pointer()
                    if pointer in self.rendered and obj.type != "LIGHT" and \
                            self.spheres.update(pointer, materials.reach_row(obj)):
                        self.beyond = None
        except ReferenceError:       # an object removed since: its collection's update comes with it, but be sure
            return False
        return True

    def _follow_lights(self, updates):
        """Re-read the shaded lights: with a ranged light (the update's changes are read anyway) those whose object or
        data this update changed, and the names (a rename has no flag); else all of them (a few)."""
        if self.spheres is None:
            return all(self._follow_light(light) for light in self.lights.values())
        if any(obj.name != name for _, _, obj, name in self.lights.values()):
            return False
        moved, data = {obj.as_pointer() for obj in updates.moved()}, updates.light_data()
        return all(self._follow_light(light, light[2].data.as_pointer() in data)
                   for pointer, light in self.lights.items() if pointer in moved or light[2].data.as_pointer() in data)

    def _follow_light(self, light, data_changed=True):
        """Re-read one shaded light: its signature entry when its data changed (a transform alone changes no name,
        kind, shape or colour: reading the entry again is a third of a moved light's update), its location and range
        when it has one."""
        index, entry, obj, _ = light
        kind = materials.light_kind(obj)
        if kind is None or data_changed and materials.light_signature([(obj, kind)])[0] != entry:
            return False                # renamed, another kind or shape: the signature changed
        if index in self.ranged:
            (_, loc, r), = materials.ranged_lights([(obj, kind)])
            if (loc, r) != self.ranged[index]:
                self.ranged[index] = (loc, r)
                self.moved_lights.add(index)
        return True

    def reach(self):
        """``materials.material_reach`` of the scene, from the followed spheres and lights."""
        if self.spheres is None:
            return {}
        if self.beyond is None or self.moved_lights:     # the moved lights' columns, or all of them
            redo = self.ranged.keys() if self.beyond is None else self.moved_lights
            found = materials.out_of_range([(i, *self.ranged[i]) for i in sorted(redo)], self.spheres.arrays)
            self.beyond = found if self.beyond is None else \
                {m: (far - self.moved_lights) | found[m] for m, far in self.beyond.items()}
            self.moved_lights = set()
        return materials.reach_of_materials(self.beyond, self.count)

    def out_of_sync(self):
        """``materials.lights_out_of_sync`` of the scene."""
        return materials.differs_from_sync(self.signature, self.reach)


class _Spheres:
    """The spheres around the rendered objects (``materials.reach_rows``) as arrays per material
    (``materials.material_spheres``); an object that moves has its rows replaced in place."""

    def __init__(self, scene, rendered):
        self.rows = materials.reach_rows(scene, rendered)
        self._arrange()

    def _arrange(self):
        self.places = {}
        self.arrays = materials.material_spheres(self.rows, self.places)

    def update(self, pointer, row):
        """Replace the sphere of the object at ``pointer`` (``row``: its ``reach_row``); whether it changed."""
        old = self.rows.get(pointer)
        if row == old:
            return False
        if row is None:
            del self.rows[pointer]
        else:
            self.rows[pointer] = row
        if old is None or row is None or row[0] != old[0]:     # other materials: arranged anew
            self._arrange()
            return True
        _, _, centres, radii = self.arrays
        for i in self.places[pointer]:
            centres[i], radii[i] = row[1], row[2]
        return True


# --- the handler ------------------------------------------------------------------------------------------------------

@persistent
def on_depsgraph_update(scene, depsgraph=None):
    if _busy[0]:
        return
    if not enabled():
        _states.clear()            # not followed while off: checked in full when turned on again
        return
    updates = Updates(depsgraph) if depsgraph is not None else None
    if updates is not None and not updates.relevant:
        return
    try:
        sync_if_needed(scene, updates=updates)
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
    """Another file: nothing of this one's state or failures holds there."""
    _states.clear()
    _failures.clear()


@persistent
def on_undo_step(*_):
    """An undo or redo step: forget what the handler followed.  Blender's global undo reads the file state back into
    new memory and frees the datablocks it replaces (an undone light among them), so the objects ``_SceneState`` holds
    would be freed memory: reading one (the handler runs during the undo's own depsgraph update) crashes Blender.  The
    next update checks the scene in full.  Failures are kept: they say what a sync needs, whatever the step."""
    _states.clear()


#: (handler list name, function): what this module adds to ``bpy.app.handlers``.
_HANDLERS = (
    ("depsgraph_update_post", on_depsgraph_update),
    ("load_post", on_load),
    ("undo_pre", on_undo_step),
    ("undo_post", on_undo_step),
    ("redo_pre", on_undo_step),
    ("redo_post", on_undo_step),
)


def register():
    for name, function in _HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        if function not in handlers:
            handlers.append(function)


def unregister():
    for name, function in _HANDLERS:
        handlers = getattr(bpy.app.handlers, name)
        if function in handlers:
            handlers.remove(function)
    _states.clear()
