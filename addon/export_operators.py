"""File > Export entries of RT Lookdev: the LUTs for game engines (core/export/luts.py) and the scene
description for the real-time renderer and engines (addon/scene_export.py).  Each picks a folder,
shows a progress bar while it writes, and reports what it wrote."""
from __future__ import annotations

from pathlib import Path

import bpy

from ..core.export import luts as lut_export
from . import preferences

_FORMAT_ITEMS = (
    ("exr", "OpenEXR", "OpenEXR scanline, ZIP, FLOAT or HALF channels"),
    ("ktx2", "KTX 2.0", "KTX 2.0, RGBA16F / RGBA32F with a data format descriptor and key/value metadata"),
    ("dds", "DDS", "DDS with the DX10 header, R16G16B16A16_FLOAT / R32G32B32A32_FLOAT"),
    ("npz", "NumPy .npz", "one archive per precision: an array per table and the manifest"),
    ("c", "C header", "float arrays, IEEE half as uint16, sizes and layout as constants"),
    ("glsl", "GLSL include", "each table's lookup function, as the shader backend writes it"),
    ("hlsl", "HLSL include", "each table's lookup function, as the shader backend writes it"),
)
_PRECISION_ITEMS = (("f32", "Float32", "32-bit float texels"),
                    ("f16", "Half", "16-bit float texels (rtl: scaled where small values need it; ltc_code: plain "
                                    "values; manifest)"))
_LAYOUT_ITEMS = (("rtl", "RT Lookdev", "the project's tables and names (docs/luts.md)"),
                 ("ltc_code", "ltc_code", "LTC pairs packed as selfshadow/ltc_code's published ltc_1 / ltc_2: a drop-in "
                  "(standalone GGX fit, plain half values)"))


class _FolderExport:
    """A folder browser: ``directory`` is the folder picked."""
    directory: bpy.props.StringProperty(name="Folder", subtype='DIR_PATH')
    filter_folder: bpy.props.BoolProperty(default=True, options={'HIDDEN'})

    def invoke(self, context, event):
        context.window_manager.fileselect_add(self)
        return {'RUNNING_MODAL'}


def _progress(context):
    """(begin, update(fraction), end) on the window manager's progress bar (nothing in the background)."""
    wm = context.window_manager
    show = wm is not None and not bpy.app.background
    return ((lambda: wm.progress_begin(0, 100)) if show else (lambda: None),
            (lambda f: wm.progress_update(100.0 * f)) if show else (lambda f: None),
            (lambda: wm.progress_end()) if show else (lambda: None))


class RTL_OT_export_luts(_FolderExport, bpy.types.Operator):
    """Export the lookup tables for game engines, with a manifest that says exactly how to index them"""

    bl_idname = "rtl.export_luts"
    bl_label = "Export RT Lookdev LUTs"
    bl_options = {'REGISTER'}

    formats: bpy.props.EnumProperty(name="Formats", items=_FORMAT_ITEMS, options={'ENUM_FLAG'},
                                    default={"exr", "ktx2", "dds", "npz", "c", "glsl", "hlsl"})
    precisions: bpy.props.EnumProperty(name="Precision", items=_PRECISION_ITEMS, options={'ENUM_FLAG'},
                                       default={"f32", "f16"})
    layout: bpy.props.EnumProperty(name="Layout", items=_LAYOUT_ITEMS, default="rtl")

    @classmethod
    def poll(cls, context):
        if not preferences.lut_directory(context).is_dir():
            cls.poll_message_set(f"LUT directory does not exist: {preferences.lut_directory(context)}")
            return False
        return True

    def execute(self, context):
        if not self.directory:
            self.report({'ERROR'}, "Choose a folder to export into")
            return {'CANCELLED'}
        begin, update, end = _progress(context)
        order = [f for f, *_ in _FORMAT_ITEMS if f in self.formats]
        begin()
        try:
            result = lut_export.export(Path(bpy.path.abspath(self.directory)), preferences.lut_directory(context),
                                       order, [p for p, *_ in _PRECISION_ITEMS if p in self.precisions], self.layout,
                                       progress=lambda done, total, name: update(done / total))
        except lut_export.LutExportError as exc:
            self.report({'ERROR'}, f"LUT export refused: {exc}")
            return {'CANCELLED'}
        finally:
            end()
        size = sum(result.files.values()) / 1e6
        self.report({'INFO'}, f"RT Lookdev: {len(result.files)} files ({size:.1f} MB, layout {self.layout}, "
                              f"{', '.join(order)}) written to {result.folder}")
        return {'FINISHED'}


class RTL_OT_export_scene(_FolderExport, bpy.types.Operator):
    """Export the scene's RT Lit lookdev (camera, lights, world bake, materials, meshes, tables) for the
    real-time renderer and engines"""

    bl_idname = "rtl.export_scene"
    bl_label = "Export RT Lookdev Scene"
    bl_options = {'REGISTER'}

    @classmethod
    def poll(cls, context):
        if context.scene is None or context.scene.camera is None:
            cls.poll_message_set("The scene needs a camera")
            return False
        return True

    def execute(self, context):
        from . import scene_export
        from ..core.export.scene import SceneDescriptionError

        if not self.directory:
            self.report({'ERROR'}, "Choose a folder to export into")
            return {'CANCELLED'}
        try:
            desc = scene_export.export_scene(context.scene, Path(bpy.path.abspath(self.directory)),
                                             preferences.lut_directory(context))
        except (scene_export.SceneExportError, SceneDescriptionError) as exc:
            self.report({'ERROR'}, f"Scene export refused: {exc}")
            return {'CANCELLED'}
        self.report({'INFO'}, f"RT Lookdev: {len(desc.objects)} objects, {len(desc.lights)} lights, "
                              f"{len(desc.materials)} materials exported to {desc.folder}")
        return {'FINISHED'}


def _menu_export(self, context):
    self.layout.operator(RTL_OT_export_luts.bl_idname, text="RT Lookdev LUTs")
    self.layout.operator(RTL_OT_export_scene.bl_idname, text="RT Lookdev Scene (real-time)")


classes = (RTL_OT_export_luts, RTL_OT_export_scene)
#: (menu, draw function) pairs the add-on appends on register and removes on unregister.
menus = ((bpy.types.TOPBAR_MT_file_export, _menu_export),)
