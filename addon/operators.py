"""Operators of RT Lookdev (``bpy.ops.rtl.*``)."""
from __future__ import annotations

import bpy

from . import preferences
from .background_task import ModalTask
from .common import WORLD_GROUP

#: States that make the tables unusable: the operator fails on these.
ERROR_STATES = ("corrupt", "mismatch")
#: States that mean "bake again": the operator warns on these.
WARNING_STATES = ("missing", "stale")


def _scene_exists(cls, context):
    """poll() of the operators that work on the active scene."""
    if context.scene is None:
        cls.poll_message_set("No active scene")
        return False
    return True


def lut_directory_exists(cls, context):
    """poll() of the operators that read the LUT folder: it must exist."""
    lut_dir = preferences.lut_directory(context)
    if not lut_dir.is_dir():
        cls.poll_message_set(f"LUT directory does not exist: {lut_dir}")
        return False
    return True


class RTL_OT_lut_status(bpy.types.Operator):
    """Check that the baked lookup tables exist and match the current code"""

    bl_idname = "rtl.lut_status"
    bl_label = "Check LUT Status"
    bl_options = {'REGISTER'}

    @classmethod
    def poll(cls, context):
        return lut_directory_exists(cls, context)

    def execute(self, context):
        lut_dir = preferences.lut_directory(context)
        try:
            statuses = preferences.refresh_status(lut_dir)
        except Exception as ex:
            self.report({'ERROR'}, f"Could not check LUTs in {lut_dir}: {ex}")
            return {'CANCELLED'}

        if not statuses:
            self.report({'WARNING'}, f"No LUT tables are defined (checked {lut_dir})")
            return {'FINISHED'}

        unknown = [s for s in statuses if s.state not in ("ok", *ERROR_STATES, *WARNING_STATES)]
        if unknown:
            self.report({'ERROR'}, "Unknown LUT state: " + ", ".join(f"{s.name}={s.state!r}" for s in unknown))
            return {'CANCELLED'}

        errors = [s for s in statuses if s.state in ERROR_STATES]
        if errors:
            # Full per-table messages go to the console; the report stays one line.
            for status in statuses:
                if status.state != "ok":
                    print(f"RT Lookdev: LUT {status.name} is {status.state}: {status.message}")
            message = f"Unusable LUT tables in {lut_dir} ({preferences.summarise_status(statuses, ERROR_STATES)})"
            warnings = preferences.summarise_status(statuses, WARNING_STATES)
            if warnings:
                message += f", also {warnings}"
            self.report({'ERROR'}, f"{message}: {errors[0].message}")
            return {'CANCELLED'}

        warnings = preferences.summarise_status(statuses, WARNING_STATES)
        if warnings:
            self.report({'WARNING'}, f"LUT tables need baking in {lut_dir} ({warnings}); {preferences.BAKE_HINT}")
            return {'FINISHED'}

        self.report({'INFO'}, f"All {len(statuses)} LUT tables are up to date in {lut_dir}")
        return {'FINISHED'}


#: Up to this many lights the Sync Lights report names each; beyond, it counts them per kind (Blender
#: truncates long reports, which cut off the warning after a list of 100 names).
NAMED_LIGHTS_MAX = 8


def _light_summary(records):
    """"Key (quad), Fill (disk)" for a few lights, "96 point, 4 quad" for many, "none" for none."""
    if not records:
        return "none"
    if len(records) <= NAMED_LIGHTS_MAX:
        return ", ".join(f"{obj.name} ({kind})" for obj, kind in records)
    counts = {}
    for _, kind in records:
        counts[kind] = counts.get(kind, 0) + 1
    return ", ".join(f"{n} {kind}" for kind, n in sorted(counts.items(), key=lambda kv: -kv[1]))


#: At most this many lights are named in the "not shaded" part of the report.
IGNORED_LIGHTS_NAMED = 4


def _ignored_settings(records):
    """"Key (node tree (...)), Fill (glossy ray visibility off)": the light settings RT Lit does not shade, a few
    lights (``light_model.unshaded_settings``)."""
    from . import light_model

    parts = [f"{obj.name} ({', '.join(found)})" for obj, kind in records
             if (found := light_model.unshaded_settings(obj, kind))]
    if len(parts) > IGNORED_LIGHTS_NAMED:
        parts = parts[:IGNORED_LIGHTS_NAMED] + [f"{len(parts) - IGNORED_LIGHTS_NAMED} more lights"]
    return ", ".join(parts)


def _over_capacity(groups, lights, has_world):
    """The warning for RT Lit groups that shade more lights than their feature set holds in Cycles
    (core/materials/cycles_capacity.py: measured SVM-stack capacity), or "".  ``lights``: the scene's lights, what
    a group shades unless it was culled to a subset of them."""
    from ..core.materials import cycles_capacity
    from ..core.materials.rt_lit_interface import Features
    from .common import FEATURES_KEY, LIGHTS_SUBSET_KEY

    over = {}
    for ng in groups:
        if ng.users == 0:                # every material using it now has a culled group: nothing renders with it
            continue
        features = Features.from_dict(ng[FEATURES_KEY])
        capacity, measured = cycles_capacity.light_capacity(features, has_world)
        shaded = len(ng[LIGHTS_SUBSET_KEY]) if LIGHTS_SUBSET_KEY in ng else lights
        if shaded > capacity:
            bound = ("tested up to" if cycles_capacity.is_lower_bound(capacity) else
                     "at most" if measured else "about")
            over.setdefault(features.label(), f"({features.label()}) {bound} {capacity}")
    over = list(over.values())
    if not over:
        return ""
    return (f"Cycles renders RT Lit materials black beyond their shader-stack capacity, "
            f"{'with' if has_world else 'without'} the World term: {'; '.join(over)} lights "
            f"(docs/benchmarks/rt_lit.md); EEVEE has no such limit")


def _black_under_spread_lights(groups, records):
    """Blender 4.x: the warning for RT Lit groups whose switches overflow Cycles' shader stack under an area light with
    spread (core/materials/cycles_capacity.py, ``SPREAD_IN_4``) when the scene has one, or ""."""
    from ..core import lights as core_lights
    from ..core.materials import cycles_capacity
    from ..core.materials.rt_lit_interface import Features
    from .common import FEATURES_KEY

    if bpy.app.version >= (5, 0, 0):
        return ""
    spread = [obj.name for obj, kind in records if "spread" in core_lights.split_kind(kind)[1]]
    if not spread:
        return ""
    black = sorted({features.label() for features in (Features.from_dict(ng[FEATURES_KEY]) for ng in groups if ng.users)
                    if not cycles_capacity.renders_under_spread_in_4(features)})
    if not black:
        return ""
    return (f"Blender 4.x: RT Lit materials ({'; '.join(black)}) render black in Cycles under an area light with spread "
            f"({', '.join(spread[:3])}): beyond its shader stack; Blender 5 renders them, as does EEVEE, or choose "
            "fewer switches (core/materials/cycles_capacity.py)")


class RTL_OT_sync_lights(bpy.types.Operator):
    """Rebuild the RT Lit groups for the lights now in the scene (after adding, removing or
    changing the shape of a light; moving or editing a light needs no sync: drivers follow it)"""

    bl_idname = "rtl.sync_lights"
    bl_label = "Sync RT Lit Lights"
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context):
        return _scene_exists(cls, context)

    def execute(self, context):
        from . import light_sync

        lut_dir = preferences.lut_directory(context)
        try:         # all or nothing: a failed sync changes no group or material (light_sync.sync_lights)
            records, groups = light_sync.sync_lights(context.scene, lut_dir)
        except light_sync.SyncError as ex:
            self.report({'ERROR'}, str(ex))
            return {'CANCELLED'}
        message = f"RT Lit: {len(records)} lights [{_light_summary(records)}]; {len(groups)} RT Lit groups rebuilt"
        ignored = _ignored_settings(records)
        if ignored:
            message += f"; not shaded: {ignored}"
        over = ". ".join(w for w in (_over_capacity(groups, len(records), WORLD_GROUP in bpy.data.node_groups),
                                     _black_under_spread_lights(groups, records)) if w)
        if over:
            self.report({'WARNING'}, f"{message}. {over}")
        else:
            self.report({'INFO'}, message)
        return {'FINISHED'}


class RTL_OT_enable_shadows(bpy.types.Operator):
    """Shadow the RT Lit lights in F12 renders of the scene's engine.  Cycles: each light's RT Lit term (and the
    world's) scaled by a denoised ratio of path-traced shadowed and unshadowed light (Heitz et al. 2018), from two probe
    view layers and a compositor.  EEVEE: the lights' RT Lit terms scaled by EEVEE's own Shadow pass of a white probe
    view layer (one ratio for all lights)"""

    bl_idname = "rtl.enable_shadows"
    bl_label = "Enable RT Lit Shadows"
    bl_options = {'REGISTER', 'UNDO'}

    samples: bpy.props.IntProperty(name="Shadow Samples", default=4, min=1, max=4096,
                                   description="Cycles: samples of the probe view layers: more is less noise, more "
                                               "time (EEVEE's probe renders with the scene's samples)")
    denoise: bpy.props.BoolProperty(name="Denoise", default=True,
                                    description="Cycles: denoise the shadowed and unshadowed estimates (Open Image "
                                                "Denoise)")
    world: bpy.props.BoolProperty(name="Shadow the World", default=True,
                                  description="Cycles only: the world's light occluded too, by its path-traced light "
                                              "on a white probe over RT Lit's own: in Cycles the world's diffuse light "
                                              "becomes the path-traced one (no longer the SH of EEVEE and engines); "
                                              "in EEVEE the world keeps the material's World Occlusion")

    @classmethod
    def poll(cls, context):
        from . import shadows

        if not _scene_exists(cls, context):
            return False
        if shadows.render_engine_shadows(context.scene) is None:
            cls.poll_message_set("RT Lit shadows are computed by Cycles or EEVEE: set the render engine to one of them")
            return False
        return True

    def execute(self, context):
        from . import shadows

        try:               # all or nothing: a refused enable changes nothing (shadows.enable_shadows)
            shadows.enable_shadows(context.scene, self.samples, self.denoise,
                                   lut_dir=preferences.lut_directory(context), world=self.world)
        except shadows.ShadowError as ex:
            self.report({'ERROR'}, str(ex))
            return {'CANCELLED'}
        settings = shadows.shadow_settings(context.scene)
        lights = len(shadows.shadowed_lights(context.scene))
        if settings["engine"] == "EEVEE":
            self.report({'INFO'}, f"RT Lit shadows on: {lights} lights by EEVEE's Shadow pass (EEVEE F12 renders; the "
                                  "world keeps World Occlusion; Cycles and the viewport stay unshadowed)")
            return {'FINISHED'}
        world = " and the world" if settings["world"] else ""
        self.report({'INFO'}, f"RT Lit shadows on: {lights} lights{world}, {self.samples} shadow samples"
                              f"{', denoised' if self.denoise else ''} (Cycles F12 renders; EEVEE and the viewport "
                              "stay unshadowed)")
        return {'FINISHED'}


class RTL_OT_disable_shadows(bpy.types.Operator):
    """Remove the RT Lit shadows: the probe view layers, the light copies and the compositor they added"""

    bl_idname = "rtl.disable_shadows"
    bl_label = "Disable RT Lit Shadows"
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context):
        from . import shadows

        if not _scene_exists(cls, context):
            return False
        if not shadows.shadows_enabled(context.scene):
            cls.poll_message_set("RT Lit shadows are off in this scene")
            return False
        return True

    def execute(self, context):
        from . import shadows

        shadows.disable_shadows(context.scene, preferences.lut_directory(context))
        self.report({'INFO'}, "RT Lit shadows off")
        return {'FINISHED'}


class RTL_OT_light_sync_report(bpy.types.Operator):
    """Show why the automatic light sync could not sync the lights (run by it after a failed sync: a depsgraph
    handler cannot report; the RT Lookdev panels keep showing the message until a sync succeeds)"""

    bl_idname = "rtl.light_sync_report"
    bl_label = "Report Light Sync"
    bl_options = {'INTERNAL'}

    message: bpy.props.StringProperty(name="Message", options={'SKIP_SAVE'})

    @classmethod
    def poll(cls, context):
        if context.window_manager is None:
            cls.poll_message_set("No window manager to report to")
            return False
        return True

    def execute(self, context):
        if not self.message:
            self.report({'INFO'}, "RT Lit: the lights are in sync")
            return {'CANCELLED'}
        self.report({'WARNING'}, self.message)
        return {'FINISHED'}


class RTL_OT_add_node_groups(bpy.types.Operator):
    """Load every RT Lookdev node group into this file (they then appear in Add > Group);
    groups already present and current are reused, stale ones are rebuilt in place"""

    bl_idname = "rtl.add_node_groups"
    bl_label = "Add RT Lookdev Node Groups"
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context):
        return lut_directory_exists(cls, context)

    def execute(self, context):
        from ..core.lut.lookup import LutSet
        from ..node_groups import library
        from . import node_emit

        tables = LutSet.from_folder(preferences.lut_directory(context))
        wm = context.window_manager
        functions = library.all_functions()
        before = set(bpy.data.node_groups.keys())
        try:
            wm.progress_begin(0, len(functions))
            for i, fn in enumerate(functions):
                node_emit.ensure_function_group(fn, tables)
                wm.progress_update(i + 1)
        except Exception as ex:
            self.report({'ERROR'}, f"Could not build the node groups: {ex}")
            return {'CANCELLED'}
        finally:
            wm.progress_end()
        added = len(set(bpy.data.node_groups.keys()) - before)
        self.report({'INFO'}, f"RT Lookdev: {len(functions)} node groups available ({added} new)")
        return {'FINISHED'}


class RTL_OT_sync_world(ModalTask, bpy.types.Operator):
    """Bake what the World shows (its environment image, its plain colour, or else Cycles' render of its nodes;
    cached by content) and rebuild the RT Lit groups with its light; a world that shows nothing has no World
    term.  Changing the World's strength or Mapping rotation needs no sync: drivers follow it.
    The bake runs in the background (Esc cancels)"""

    bl_idname = "rtl.sync_world"
    bl_label = "Sync RT Lit World"
    bl_options = {'REGISTER', 'UNDO'}
    _label = "RT Lit World bake"

    @classmethod
    def poll(cls, context):
        return _scene_exists(cls, context)

    def execute(self, context):
        from . import materials, shadows
        from . import world_sync as world

        scene = context.scene
        lut_dir = preferences.lut_directory(context)
        setup = world.world_setup(scene.world)
        try:
            job = world.bake_job(scene) if setup.usable else None
        except Exception as ex:
            what = "render the world" if setup.source == "render" else "read the world's image"
            self.report({'ERROR'}, f"Could not {what}: {ex}")
            return {'CANCELLED'}

        def work(progress):
            def stage(name, done, total):     # SH: the first 5%; the prefiltered levels: the rest
                fraction = 0.05 * done / total if name == "sh" else 0.05 + 0.95 * done / max(total, 1)
                progress(fraction, f"{name} {done}/{total}")
            return job(stage) if job is not None else None

        def finish(bake):
            try:
                record = world.sync_world(scene, bake=bake)
                shadows.refresh_shadows(scene, lut_dir)      # the World term's shadows follow the synced world
                groups = materials.rebuild_rt_lit_groups(scene, lut_dir)
                world.remove_stale_environment_images(keep=record and record["table"])
            except Exception as ex:
                self.report({'ERROR'}, f"Could not sync the world: {ex}")
                return {'CANCELLED'}
            rebuilt = f"{len(groups)} RT Lit groups rebuilt"
            if record is None:
                self.report({'WARNING'}, f"RT Lit World term off: {setup.reason}; {rebuilt}")
            else:
                shown = f"'{record['image']}'" if record.get("source") == "image" else record["image"]
                self.report({'INFO'}, f"RT Lit World: {shown} {world.bake_summary(bake)}; {rebuilt}")
            return {'FINISHED'}

        return self.start_task(context, work, finish)


class RTL_OT_bake_luts(ModalTask, bpy.types.Operator):
    """Bake the lookup tables that are missing, stale or corrupt into the LUT directory (each table group is
    written whole or not at all); in the background, Esc cancels"""

    bl_idname = "rtl.bake_luts"
    bl_label = "Bake LUTs"
    bl_options = {'REGISTER'}
    _label = "RT Lookdev LUT bake"

    force: bpy.props.BoolProperty(name="Force", description="Re-bake the tables that are current too",
                                  default=False)

    @classmethod
    def poll(cls, context):
        lut_dir = preferences.lut_directory(context)
        if not lut_dir.parent.is_dir():
            cls.poll_message_set(f"The LUT directory's folder does not exist: {lut_dir.parent}")
            return False
        return True

    def execute(self, context):
        from ..core import lut_bake
        from ..core.lut import catalog

        lut_dir = preferences.lut_directory(context)
        if lut_dir.is_dir():      # measured tables are not baked: kept, or copied from the shipped folder
            catalog.keep_measured(lut_dir, log=lambda line: print(f"RT Lookdev: {line}"))
        todo = [g for g in catalog.GROUPS if self.force or not lut_bake.group_is_current(g, lut_dir)]
        if not todo:
            self.report({'INFO'}, f"All {len(catalog.TABLES)} LUT tables in {lut_dir} are current; nothing to bake")
            return {'FINISHED'}
        force, scene = self.force, context.scene

        def work(progress):
            def step(group, done, total):
                index = todo.index(group) if group in todo else 0
                progress((index + done / max(total, 1)) / len(todo), f"{group} {done}/{total}")
            lut_dir.mkdir(parents=True, exist_ok=True)
            records = lut_bake.bake(lut_dir, force=force, progress=step, groups=todo, workers=1,
                                    log=lambda line: print(f"RT Lookdev: {line}"))
            catalog.keep_measured(lut_dir, log=lambda line: print(f"RT Lookdev: {line}"))
            return records

        def finish(records):
            from . import light_sync

            preferences.refresh_status(lut_dir)
            baked = [r for r in records if r.state == "baked"]
            seconds = sum(r.seconds for r in baked)
            message = f"Baked {', '.join(r.group for r in baked)} into {lut_dir} in {seconds:.0f} s"
            if light_sync.failure(scene) is None:
                self.report({'INFO'}, f"{message}; Sync Lights rebuilds the RT Lit groups with them")
                return {'FINISHED'}
            try:         # a light sync failed for want of these tables: sync now
                light_sync.sync_lights(scene, lut_dir)
            except light_sync.SyncError as ex:
                self.report({'WARNING'}, f"{message}. {ex}")
            else:
                self.report({'INFO'}, f"{message}; the lights are synced with them")
            return {'FINISHED'}

        return self.start_task(context, work, finish)


classes = (RTL_OT_lut_status, RTL_OT_bake_luts, RTL_OT_sync_lights, RTL_OT_light_sync_report, RTL_OT_sync_world,
           RTL_OT_add_node_groups, RTL_OT_enable_shadows, RTL_OT_disable_shadows)
