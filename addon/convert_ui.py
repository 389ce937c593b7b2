"""Convert's operators and UI: Convert to RT Lit and Convert to Principled, and the RT Lit switches as
artists see them (their labels, the enum items and their drawing, shared by the Convert dialog, the
material panel ``ui.RTL_PT_material`` and ``switches.RTL_PG_switches``).

The operators find their materials (the active one, or every material of the selected objects), call
``convert.principled_to_rt_lit`` / ``convert.rt_lit_to_principled`` on each, and turn the results and
``convert.ConversionError`` into one report per kind.
"""
from __future__ import annotations

import bpy
from bpy.props import BoolProperty, EnumProperty

from ..core.materials.rt_lit_interface import (DIFFUSE_MODELS, HORIZON_MODELS, OCCLUSION_MODELS, PRINCIPLED_SHEEN,
                                               SHEEN_MODELS, SPECULAR_MODELS, Features)
from . import convert, preferences

# --------------------------------------------------------------------------------------------
# The switches

SPECULAR_LABELS = {
    "single": ("Single Scattering", "GGX single scattering only (loses energy at high roughness)"),
    "turquin": ("Turquin", "Turquin 2019 energy compensation (scales the GGX lobe by 1 / E)"),
    "fdez_aguera": ("Fdez-Agüera", "Fdez-Agüera 2019 multiple-scattering approximation"),
    "kulla_conty": ("Kulla-Conty", "Kulla & Conty 2017 multiple-scattering lobe"),
    "none": ("None", "No specular lobe: diffuse (and cloth, sheen) only"),
}
DIFFUSE_LABELS = {
    "lambert": ("Lambert", "Lambertian diffuse"),
    "cod": ("CoD WWII", "Call of Duty WWII multiscattering diffuse (Chan 2018)"),
    "wrapped": ("Wrapped", "Energy-conserving wrapped diffuse (uses the Wrap input)"),
    "cod_wrapped": ("CoD WWII Wrapped", "Multiscattering diffuse with wrapped lighting, the talk's closing table "
                                        "(uses the Wrap input)"),
    "oren_nayar": ("Oren-Nayar (Cycles)", "Rough diffuse as Cycles shades Principled's Diffuse Roughness: Fujii's "
                   "Oren-Nayar with EON's multiple scattering (uses the Diffuse Roughness input)"),
}

SPECULAR_ITEMS = tuple((m, *SPECULAR_LABELS.get(m, (m.replace("_", " ").title(), ""))) for m in SPECULAR_MODELS)
ENVIRONMENT_MS_ITEMS = (('irradiance', "Irradiance", "Fdez-Aguera 2019: FssEss x radiance + FmsEms x irradiance"),
                        ('radiance', "Radiance", "The talk: (FssEss + FmsEms) x prefiltered radiance"))
DIFFUSE_ITEMS = tuple((m, *DIFFUSE_LABELS.get(m, (m.replace("_", " ").title(), ""))) for m in DIFFUSE_MODELS)
SHEEN_LABELS = {
    "none": ("None", "No sheen lobe"),
    "zeltner": ("Zeltner (Principled)", "Zeltner, Burley & Chiang 2022: the sheen of Blender's Principled BSDF, "
                "layered over the lobes below as Principled does; uses Sheen Roughness"),
    "disney_fitted": ("Disney (fitted LTC)", "Disney sheen (1 - l.h)^5 with its own fitted LTC under area lights"),
    "disney_talk": ("Disney (talk)", "Disney sheen as the talk shades it: the CoD table at r = 0.5 under area lights"),
}
SHEEN_ITEMS = tuple((m, *SHEEN_LABELS.get(m, (m.replace("_", " ").title(), ""))) for m in SHEEN_MODELS)


OCCLUSION_LABELS = {
    "none": ("None", "The world lights every point as if nothing stood around it"),
    "lagarde": ("AO + Lagarde", "The renderer's ambient occlusion on the world's diffuse; its specular occluded by "
                "Lagarde & de Rousiers 2014's fit"),
    "cones": ("AO + Cones", "The renderer's ambient occlusion on the world's diffuse; its specular occluded by "
              "Jimenez et al. 2016's cone intersection"),
    "cones_clipped": ("AO + Clipped Cones", "The renderer's ambient occlusion on the world's diffuse; its specular "
                      "occluded by the cone intersection within the hemisphere (the most accurate)"),
}
OCCLUSION_ITEMS = tuple((m, *OCCLUSION_LABELS.get(m, (m.replace("_", " ").title(), ""))) for m in OCCLUSION_MODELS)

HORIZON_LABELS = {
    "sphere_table": ("Sphere Table (Talk)", "The talk's clipless form for every light: the cheapest, exact for lights "
                     "wholly above the horizon, off by several times for lights that cross it"),
    "exact_quads": ("Exact for Quads", "Quad lights clipped exactly at the surface's horizon, disk and sphere lights "
                    "by the talk's sphere table (a quad costs about 1.8x the talk's nodes). In Blender 4.5 the largest "
                    "feature set overflows Cycles' shader stack and renders black"),
    "exact": ("Exact", "Every area light clipped exactly at the surface's horizon: disks too, at about 2.7x the talk's "
              "nodes per disk light. In Blender 4.5 the largest feature set overflows Cycles' shader stack"),
}
HORIZON_ITEMS = tuple((m, *HORIZON_LABELS.get(m, (m.replace("_", " ").title(), ""))) for m in HORIZON_MODELS)


def draw_switches(layout, owner):
    """The RT Lit switches of ``owner`` (the Convert dialog, or a material's ``rtl_switches``): specular,
    the world form (active for Fdez-Aguera), diffuse, sheen, cloth, the world's occlusion and the area lights'
    horizon."""
    layout.prop(owner, "specular")
    sub = layout.row()
    sub.active = owner.specular == 'fdez_aguera'
    sub.prop(owner, "environment_ms")
    layout.prop(owner, "diffuse")
    layout.prop(owner, "sheen")
    layout.prop(owner, "cloth")
    layout.prop(owner, "occlusion")
    layout.prop(owner, "horizon")
    if owner.horizon != "sphere_table" and not convert.exact_horizon_renders(
            Features(owner.specular, owner.diffuse, sheen=owner.sheen, cloth=owner.cloth)):
        layout.label(text="Blender 4.x: renders black with these switches (shader stack)", icon='ERROR')


# --------------------------------------------------------------------------------------------
# Operators

TARGET_ITEMS = (
    ('ACTIVE', "Active Material", "Convert the active material"),
    ('SELECTED', "Selected Objects", "Convert every material of the selected objects"),
)


def _active_material(context):
    material = getattr(context, "material", None)
    if material is None:
        obj = getattr(context, "object", None) or getattr(context, "active_object", None)
        material = obj.active_material if obj is not None else None
    return material


def _selected_materials(context):
    materials, seen = [], set()
    for obj in getattr(context, "selected_objects", None) or ():
        for slot in obj.material_slots:
            mat = slot.material
            if mat is not None and mat.name_full not in seen:
                seen.add(mat.name_full)
                materials.append(mat)
    return materials


def target_materials(context, target):
    if target == 'SELECTED':
        return _selected_materials(context)
    material = _active_material(context)
    return [material] if material is not None else []


def _report_results(op, done, failures, verb):
    """One report per kind; returns the operator's result set."""
    warnings = [w for r in done for w in r.warnings]
    for message in failures + warnings:
        print(f"RT Lookdev: {message}")
    if not done:
        op.report({'ERROR'}, "; ".join(failures) if failures else "No material to convert")
        return {'CANCELLED'}
    names = ", ".join(f"'{r.material}'" for r in done)
    summary = f"{verb} {len(done)} material{'s' if len(done) != 1 else ''} ({names})"
    if failures or warnings:
        op.report({'WARNING'}, "; ".join([summary] + failures + warnings))
    else:
        op.report({'INFO'}, summary)
    return {'FINISHED'}


class RTL_OT_convert_to_rt_lit(bpy.types.Operator):
    """Convert Principled BSDF materials to RT Lit lookdev materials (the Principled BSDF is kept,
    collapsed, for converting back)"""

    bl_idname = "rtl.convert_to_rt_lit"
    bl_label = "Convert to RT Lit"
    bl_options = {'REGISTER', 'UNDO'}

    target: EnumProperty(name="Materials", items=TARGET_ITEMS, default='ACTIVE')
    specular: EnumProperty(
        name="Specular",
        description="Specular multiple-scattering model the RT Lit group is built with",
        items=SPECULAR_ITEMS,
        default=Features().specular,
    )
    diffuse: EnumProperty(
        name="Diffuse",
        description="Diffuse model the RT Lit group is built with",
        items=DIFFUSE_ITEMS,
        default=Features().diffuse,
    )
    sheen: EnumProperty(name="Sheen", description="Sheen lobe the RT Lit group is built with", items=SHEEN_ITEMS,
                        default=Features().sheen)
    cloth: BoolProperty(name="Cloth", description="Build the group with the Ashikhmin cloth lobe",
                        default=Features().cloth)
    environment_ms: EnumProperty(
        name="World Multiscattering",
        description="Fdez-Aguera multiple scattering under the world: lit by the irradiance (the paper) or "
                    "by the prefiltered radiance (the talk's approximation)",
        items=ENVIRONMENT_MS_ITEMS,
        default=Features().environment_ms,
    )
    occlusion: EnumProperty(name="World Occlusion",
                            description="How the scene occludes the world's light (Cycles' and EEVEE's Ambient "
                                        "Occlusion node feeds it)", items=OCCLUSION_ITEMS, default=Features().occlusion)
    horizon: EnumProperty(name="Area Light Horizon",
                          description="How the lobes meet the surface's horizon under area lights",
                          items=HORIZON_ITEMS, default=Features().horizon)

    @classmethod
    def poll(cls, context):
        if _active_material(context) is None and not _selected_materials(context):
            cls.poll_message_set("No active material, and no selected object has a material")
            return False
        return True

    def features(self):
        return Features(specular=self.specular, diffuse=self.diffuse, sheen=self.sheen, cloth=self.cloth,
                        environment_ms=self.environment_ms, occlusion=self.occlusion, horizon=self.horizon)

    def invoke(self, context, event):
        material = _active_material(context)
        stored = convert.stored_features(material)
        if stored is not None:
            self.specular, self.diffuse = stored.specular, stored.diffuse
            self.sheen, self.cloth = stored.sheen, stored.cloth
            self.environment_ms, self.occlusion = stored.environment_ms, stored.occlusion
            self.horizon = stored.horizon
        else:
            if self.sheen == "none" and convert.principled_uses_sheen(material):
                self.sheen = PRINCIPLED_SHEEN
            if convert.principled_uses_diffuse_roughness(material):
                self.diffuse = "oren_nayar"
        return context.window_manager.invoke_props_dialog(self)

    def draw(self, context):
        self.layout.prop(self, "target")
        draw_switches(self.layout, self)

    def execute(self, context):
        materials = target_materials(context, self.target)
        if not materials:
            self.report({'ERROR'}, "No material to convert" + (
                " (no selected object has a material)" if self.target == 'SELECTED' else ""))
            return {'CANCELLED'}
        factory = convert.default_group_factory(preferences.lut_directory(context))
        features = self.features()
        done, failures = [], []
        for material in materials:
            try:
                done.append(convert.principled_to_rt_lit(material, factory, features))
            except convert.ConversionError as ex:
                failures.append(str(ex))
            except Exception as ex:  # the group factory failed: nothing was changed
                failures.append(f"Material '{material.name}': could not build the RT Lit group "
                                f"({type(ex).__name__}: {ex})")
        return _report_results(self, done, failures, f"Converted to RT Lit ({features.label()})")


class RTL_OT_convert_to_principled(bpy.types.Operator):
    """Convert RT Lit materials back to Principled BSDF, keeping the values and links edited in RT Lit"""

    bl_idname = "rtl.convert_to_principled"
    bl_label = "Convert to Principled"
    bl_options = {'REGISTER', 'UNDO'}

    target: EnumProperty(name="Materials", items=TARGET_ITEMS, default='ACTIVE')

    @classmethod
    def poll(cls, context):
        candidates = [_active_material(context)] + _selected_materials(context)
        if not any(convert.is_rt_lit_material(m) for m in candidates if m is not None):
            cls.poll_message_set("Neither the active material nor a selected object's material is an RT Lit material")
            return False
        return True

    def execute(self, context):
        materials = [m for m in target_materials(context, self.target)]
        if not materials:
            self.report({'ERROR'}, "No material to convert")
            return {'CANCELLED'}
        if self.target == 'SELECTED':  # non-RT Lit materials among the selection are not errors
            materials = [m for m in materials if convert.is_rt_lit_material(m)] or materials
        done, failures = [], []
        for material in materials:
            try:
                done.append(convert.rt_lit_to_principled(material))
            except convert.ConversionError as ex:
                failures.append(str(ex))
        return _report_results(self, done, failures, "Converted to Principled")


classes = (RTL_OT_convert_to_rt_lit, RTL_OT_convert_to_principled)
