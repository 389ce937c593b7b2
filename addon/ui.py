"""The RT Lookdev panels in the material, world and light properties, and what they show of the light sync."""
from __future__ import annotations

import textwrap

import bpy

#: Characters per line of a message in a panel (labels do not wrap).
LINE_WIDTH = 52


def draw_light_sync_failure(layout, scene):
    """The last failed light sync of ``scene`` (addon/light_sync.py), if any: its message, and the ways out (Bake LUTs
    when the tables are the cause, Sync Lights); nothing while the lights are in sync."""
    from . import light_sync

    failed = light_sync.failure(scene)
    if failed is None:
        return
    box = layout.box()
    col = box.column(align=True)
    for i, line in enumerate(textwrap.wrap(failed.message, LINE_WIDTH, break_on_hyphens=False)):
        col.label(text=line, icon='ERROR' if i == 0 else 'BLANK1')
    row = box.row(align=True)
    if failed.luts:
        row.operator("rtl.bake_luts", icon='RENDER_STILL')
    row.operator("rtl.sync_lights", icon='FILE_REFRESH')


def draw_shadows(layout, scene):
    """RT Lit's light shadows in ``scene`` (addon/shadows.py): on (its settings, what each engine does) with the
    button that removes them, or the button that adds them."""
    from . import shadows

    box = layout.box()
    settings = shadows.shadow_settings(scene)
    if settings is None:
        box.operator("rtl.enable_shadows", icon='LIGHT_SUN')
        box.label(text="Lights unshadowed in every engine", icon='INFO')
        return
    if settings["engine"] == "EEVEE":
        box.label(text="Shadows: EEVEE's Shadow pass (one ratio for all lights)", icon='CHECKMARK')
        box.label(text="EEVEE F12: lights shadowed; world as World Occlusion says", icon='BLANK1')
        box.label(text="Cycles, viewport: lights unshadowed (enable again in Cycles)", icon='BLANK1')
    else:
        box.label(text=f"Shadows: {settings['samples']} samples{', denoised' if settings['denoise'] else ''}",
                  icon='CHECKMARK')
        box.label(text="Cycles F12: lights " + ("and world shadowed" if settings["world"] else "shadowed")
                  + " (ratio estimator)", icon='BLANK1')
        box.label(text="EEVEE, viewport: lights unshadowed (enable again in EEVEE)", icon='BLANK1')
    if shadows.render_engine_shadows(scene) != settings["engine"]:
        box.label(text=f"Set up for {settings['engine']}: the scene renders with another engine", icon='ERROR')
    box.operator("rtl.disable_shadows", icon='X')


class _PropertiesPanel:
    """An "RT Lookdev" panel of the Properties editor (the context is set by each panel)."""
    bl_label = "RT Lookdev"
    bl_space_type = 'PROPERTIES'
    bl_region_type = 'WINDOW'


class RTL_PT_material(_PropertiesPanel, bpy.types.Panel):
    bl_context = "material"

    @classmethod
    def poll(cls, context):
        return context.material is not None

    def draw(self, context):
        from . import convert, convert_ui
        from .common import FEATURES_KEY

        layout = self.layout
        mat = context.material
        draw_light_sync_failure(layout, context.scene)
        col = layout.column(align=True)
        if convert.is_rt_lit_material(mat):
            switches = getattr(mat, "rtl_switches", None)
            if switches is not None:          # editing a switch rebuilds the group (addon/switches.py)
                convert_ui.draw_switches(col, switches)
            else:
                col.label(text="RT Lit: " + ", ".join(f"{k} {v}" for k, v in dict(mat.get(FEATURES_KEY, {})).items()))
            col.operator("rtl.convert_to_principled", icon='MATERIAL')
        else:
            col.operator("rtl.convert_to_rt_lit", icon='SHADING_RENDERED')
        layout.operator("rtl.sync_lights", icon='LIGHT_AREA')
        draw_shadows(layout, context.scene)
        layout.operator("rtl.sync_world", icon='WORLD')
        layout.operator("rtl.add_node_groups", icon='NODETREE')
        layout.operator("rtl.lut_status", icon='IMAGE_DATA')


class RTL_PT_world(_PropertiesPanel, bpy.types.Panel):
    """The World term of RT Lit: whether the world can be used, and the sync button."""
    bl_context = "world"

    @classmethod
    def poll(cls, context):
        return context.scene is not None

    def draw(self, context):
        from . import world_sync as world

        layout = self.layout
        setup = world.world_setup(context.scene.world)
        col = layout.column(align=True)
        if setup.usable:
            col.label(text=f"Environment: {setup.label}", icon='CHECKMARK')
            if setup.note:
                col.label(text=setup.note)
            group = bpy.data.node_groups.get(world.WORLD_GROUP)
            record = group.get(world.RECORD_KEY) if group is not None else None
            if record is None or record.get("image") != setup.label:
                col.label(text="Not synced: RT Lit shades no World term yet", icon='INFO')
            elif setup.source != "image":
                col.label(text="Changes to the world's nodes need a sync (strength is live)", icon='INFO')
        else:
            col.label(text="RT Lit World term off:", icon='INFO')
            col.label(text=setup.reason)
        layout.operator("rtl.sync_world", icon='WORLD')


class RTL_PT_light(bpy.types.Panel):
    """RT Lookdev's controls of a light: range, cone falloff, quad-to-spot fallback."""
    bl_label = "RT Lookdev"
    bl_space_type = 'PROPERTIES'
    bl_region_type = 'WINDOW'
    bl_context = "data"

    @classmethod
    def poll(cls, context):
        return getattr(context, "light", None) is not None

    def draw(self, context):
        layout = self.layout
        data = context.light
        draw_light_sync_failure(layout, context.scene)      # a light added or changed may be what failed to sync
        if data.type == 'SUN':
            layout.label(text="RT Lit has no controls for sun lights", icon='INFO')
            return
        area = data.type == 'AREA'
        quad = area and data.shape in ('SQUARE', 'RECTANGLE')
        col = layout.column()
        row = col.row(align=True)
        row.prop(data, "rtl_use_range")
        sub = row.row(align=True)
        sub.active = data.rtl_use_range
        sub.prop(data, "rtl_range", text="")
        if area:
            col.prop(data, "rtl_use_cone")
            if quad:
                col.prop(data, "rtl_spot_fallback")
            angles = col.column(align=True)
            angles.active = data.rtl_use_cone or (quad and data.rtl_spot_fallback)
            angles.prop(data, "rtl_cone_inner")
            angles.prop(data, "rtl_cone_outer")
        col.label(text="RT Lit materials follow after Sync Lights (automatic by default)", icon='INFO')


classes = (RTL_PT_material, RTL_PT_world, RTL_PT_light)
