"""Operators of the one-click lookdev scene (``addon/lookdev_scene.py``), in the 3D viewport's Add menu:
New Lookdev Scene, and Add Path-Traced Twin of the active lookdev scene."""
from __future__ import annotations

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, StringProperty

from . import lookdev_scene, preferences, shadows
from .convert_ui import DIFFUSE_ITEMS, SPECULAR_ITEMS
from .operators import lut_directory_exists
from ..core.materials.rt_lit_interface import DEFAULT_OCCLUSION, Features


def _hdri_items(self, context):
    names = list(lookdev_scene.studio_hdris())
    items = [(n, n.title(), f"Blender's studio HDRI '{n}'") for n in names]
    return items + [("NONE", "None", "No world: no World term")]


class RTL_OT_new_lookdev_scene(bpy.types.Operator):
    """Add a new scene set up for lookdev: spheres across roughness (dielectric and gold) with RT Lit
    materials, a key rectangle, a fill disk and a rim spot light, a studio HDRI world, a camera and
    render settings for RT Lit (Cycles, 0 bounces)"""

    bl_idname = "rtl.new_lookdev_scene"
    bl_label = "New Lookdev Scene"
    bl_options = {'REGISTER', 'UNDO'}

    scene_name: StringProperty(name="Name", default="RT Lookdev")
    hdri: EnumProperty(name="World", description="Studio HDRI lighting the scene (baked once, then cached)",
                       items=_hdri_items)
    world_strength: FloatProperty(name="World Strength", default=1.0, min=0.0, soft_max=4.0)
    view_transform: EnumProperty(
        name="View Transform",
        items=(("AgX", "AgX", "Blender's default display transform"),
               ("Standard", "Standard", "No tone mapping: the values the measurements compare")),
        default="AgX")
    floor: BoolProperty(name="Floor", default=False,
                        description="A grey RT Lit floor under the spheres (shadowed with Shadows on)")
    shadows: BoolProperty(name="Shadows", default=False,
                          description="The lights' and the world's shadows in Cycles renders (F12), and World "
                                      "Occlusion on every RT Lit material for EEVEE and the viewport (their lights "
                                      "stay unshadowed)")
    specular: EnumProperty(name="Specular", items=SPECULAR_ITEMS, default=Features().specular)
    diffuse: EnumProperty(name="Diffuse", items=DIFFUSE_ITEMS, default=Features().diffuse)

    @classmethod
    def poll(cls, context):
        return lut_directory_exists(cls, context)

    def invoke(self, context, event):
        if "studio" in lookdev_scene.studio_hdris():
            self.hdri = "studio"
        return context.window_manager.invoke_props_dialog(self)

    def execute(self, context):
        wm = context.window_manager
        show = not bpy.app.background
        hdri = None if self.hdri in ("", "NONE") else self.hdri
        if show:
            wm.progress_begin(0, 1)
        try:
            occlusion = DEFAULT_OCCLUSION if self.shadows else "none"
            scene = lookdev_scene.new_lookdev_scene(
                self.scene_name or "RT Lookdev", Features(specular=self.specular, diffuse=self.diffuse,
                                                          occlusion=occlusion),
                hdri=hdri, world_strength=self.world_strength, view_transform=self.view_transform,
                lut_dir=preferences.lut_directory(context), floor=self.floor,
                progress=(lambda done, total: wm.progress_update(done / total)) if show else None)
            if self.shadows:
                shadows.enable_shadows(scene, lut_dir=preferences.lut_directory(context))
        except Exception as ex:
            self.report({'ERROR'}, f"Could not build the lookdev scene: {type(ex).__name__}: {ex}")
            return {'CANCELLED'}
        finally:
            if show:
                wm.progress_end()
        if context.window is not None:
            context.window.scene = scene
        spheres = len(lookdev_scene.lookdev_spheres(scene))
        world = f"world '{hdri}'" if hdri else "no world"
        shadowed = "; shadows on (Cycles F12)" if self.shadows else ""
        self.report({'INFO'}, f"Lookdev scene '{scene.name}': {spheres} RT Lit objects, 3 lights, {world}{shadowed}; "
                              "Add > Path-Traced Twin compares it with Cycles path tracing")
        return {'FINISHED'}


class RTL_OT_add_path_traced_twin(bpy.types.Operator):
    """Add a scene that path-traces the active scene with its Principled materials: the same lights, camera
    and world, copies of the RT Lit objects that follow the originals, the other objects as they are.  Switch
    scenes to compare"""

    bl_idname = "rtl.add_path_traced_twin"
    bl_label = "Add Path-Traced Twin"
    bl_options = {'REGISTER', 'UNDO'}

    bounces: IntProperty(name="Bounces", default=0, min=0, max=64,
                         description="Cycles bounces of the twin; 0 is direct light only, what RT Lit shades "
                                     "(plus the shadows RT Lit does not)")
    samples: IntProperty(name="Samples", default=128, min=1, max=65536)

    @classmethod
    def poll(cls, context):
        scene = context.scene
        if scene is None:
            cls.poll_message_set("No active scene")
            return False
        if lookdev_scene.twin_of(scene) is not None:
            cls.poll_message_set("This scene is a path-traced twin; switch to its lookdev scene")
            return False
        if not any(lookdev_scene.uses_rt_lit(o) for o in scene.objects):
            cls.poll_message_set("The scene has no object with an RT Lit material")
            return False
        return True

    def execute(self, context):
        try:
            twin = lookdev_scene.add_path_traced_twin(context.scene, self.bounces, self.samples)
        except Exception as ex:
            self.report({'ERROR'}, f"Could not add the twin: {type(ex).__name__}: {ex}")
            return {'CANCELLED'}
        count = sum(1 for o in twin.objects if lookdev_scene.TWIN_SOURCE_KEY in o.keys())
        self.report({'INFO'}, f"Path-traced twin '{twin.name}': {count} objects copied with Principled materials, "
                              f"{len(twin.objects) - count} shared, {self.bounces} bounces, {self.samples} samples")
        return {'FINISHED'}


def _menu_add(self, context):
    layout = self.layout
    layout.separator()
    layout.operator(RTL_OT_new_lookdev_scene.bl_idname, text="RT Lookdev Scene", icon='SHADING_RENDERED')
    layout.operator(RTL_OT_add_path_traced_twin.bl_idname, text="RT Lookdev Path-Traced Twin",
                    icon='SHADING_RENDERED')


classes = (RTL_OT_new_lookdev_scene, RTL_OT_add_path_traced_twin)
menus = ((bpy.types.VIEW3D_MT_add, _menu_add),)
