"""The RT Lit switches of a material, shown and edited in its RT Lookdev panel.

``Material.rtl_switches`` reads and writes the switches stored on an RT Lit material
(``convert.stored_features``, the one record of them): setting one rebuilds the material's RT Lit group
with the new switches, as the Convert dialog would (``convert.principled_to_rt_lit`` on an RT Lit material
only swaps its group, keeping every input value and link).
"""
from __future__ import annotations

from dataclasses import replace

import bpy
from bpy.props import BoolProperty, EnumProperty, PointerProperty

from ..core.materials.rt_lit_interface import Features
from . import convert, convert_ui

_ENUMS = {"specular": convert_ui.SPECULAR_ITEMS, "diffuse": convert_ui.DIFFUSE_ITEMS,
          "environment_ms": convert_ui.ENVIRONMENT_MS_ITEMS, "sheen": convert_ui.SHEEN_ITEMS,
          "occlusion": convert_ui.OCCLUSION_ITEMS, "horizon": convert_ui.HORIZON_ITEMS}


def _features(material):
    return convert.stored_features(material) or Features()


def _getter(name):
    def get(self):
        value = getattr(_features(self.id_data), name)
        if name in _ENUMS:
            return [item[0] for item in _ENUMS[name]].index(value)
        return value
    return get


def _setter(name):
    def set_value(self, value):
        material = self.id_data
        if name in _ENUMS:
            value = _ENUMS[name][value][0]
        old = _features(material)
        new = replace(old, **{name: value})
        if new == old or not convert.is_rt_lit_material(material):
            return
        from . import preferences

        try:
            convert.principled_to_rt_lit(material, convert.default_group_factory(preferences.lut_directory()), new)
        except Exception as ex:      # a property cannot report: the console shows it, nothing changed
            print(f"RT Lookdev: could not rebuild '{material.name}' with {new.label()}: {ex}")
    return set_value


def _enum(name, label):
    return EnumProperty(name=label, items=_ENUMS[name], get=_getter(name), set=_setter(name))


class RTL_PG_switches(bpy.types.PropertyGroup):
    specular: _enum("specular", "Specular")
    diffuse: _enum("diffuse", "Diffuse")
    sheen: _enum("sheen", "Sheen")
    cloth: BoolProperty(name="Cloth", get=_getter("cloth"), set=_setter("cloth"))
    environment_ms: _enum("environment_ms", "World Multiscattering")
    occlusion: _enum("occlusion", "World Occlusion")
    horizon: _enum("horizon", "Area Light Horizon")


classes = (RTL_PG_switches,)


def register():
    bpy.types.Material.rtl_switches = PointerProperty(type=RTL_PG_switches)


def unregister():
    del bpy.types.Material.rtl_switches
