"""The RT Lookdev panel in the material properties."""
from __future__ import annotations

import bpy


class RTL_PT_material(bpy.types.Panel):
    bl_label = "RT Lookdev"
    bl_space_type = 'PROPERTIES'
    bl_region_type = 'WINDOW'
    bl_context = "material"

    @classmethod
    def poll(cls, context):
        return context.material is not None

    def draw(self, context):
        from . import convert

        layout = self.layout
        mat = context.material
        col = layout.column(align=True)
        if convert.is_rt_lit_material(mat):
            features = mat.get("rtl_features", {})
            col.label(text="RT Lit: " + ", ".join(f"{k} {v}" for k, v in dict(features).items()))
            col.operator("rtl.convert_to_rt_lit", text="Change Switches")
            col.operator("rtl.convert_to_principled", icon='MATERIAL')
        else:
            col.operator("rtl.convert_to_rt_lit", icon='SHADING_RENDERED')
        layout.operator("rtl.sync_lights", icon='LIGHT_AREA')
        layout.operator("rtl.add_node_groups", icon='NODETREE')
        layout.operator("rtl.lut_status", icon='IMAGE_DATA')


classes = (RTL_PT_material,)
