"""The lookdev presets as assets: the library file, its registration, and conversion on first use.

The library (``assets/rt_lookdev_presets.blend`` and its catalog file ``assets/blender_assets.cats.txt``,
built by ``scripts/build_presets.py`` from ``core.materials.presets``) holds Principled materials marked
as assets in the "RT Lookdev" catalogs, each carrying the RT Lit switches it converts with
(``PRESET_KEY``).  They hold no RT Lit group: a group depends on the lights of the scene it shades
(``materials.py``), which the library cannot know.  When a preset is dropped on an object (or appended
and assigned), the depsgraph handler of ``light_sync`` converts it to RT Lit for the scene's lights and
the installed tables (``convert_pending``); without the extension it renders as the Principled material
it is.

Enabling the extension adds the folder as the asset library "RT Lookdev" to the preferences (once; an
existing entry for the folder is kept), and disabling it removes the entry it added.
"""
from __future__ import annotations

from pathlib import Path

import bpy

from ..core.materials import presets as core_presets
from ..core.materials.rt_lit_interface import Features
from .common import RT_LIT_NODE_NAME

ASSETS_DIR = Path(__file__).resolve().parents[1] / "assets"
LIBRARY_FILE = ASSETS_DIR / "rt_lookdev_presets.blend"
CATALOG_FILE = ASSETS_DIR / "blender_assets.cats.txt"
LIBRARY_NAME = "RT Lookdev"
#: Custom property of a preset material not converted yet: {"features": {...}, "rt_lit": {...}}.
PRESET_KEY = "rtl_preset"
_added = []          # the asset library entries this session added (removed on unregister)


# --- building the library (scripts/build_presets.py) ---------------------------------------------------

def catalog_text():
    """The catalog definition file Blender reads beside the library's .blend files (format version 1)."""
    lines = ["# Asset catalogs of RT Lookdev (written by scripts/build_presets.py).", "VERSION 1", ""]
    lines += [f"{uuid}:{path}:{simple}" for uuid, path, simple in core_presets.CATALOGS]
    return "\n".join(lines) + "\n"


def preset_material(preset):
    """A new Principled material for ``preset``, marked as an asset of its catalog, carrying its switches."""
    from .lookdev_scene import principled_material

    mat = principled_material(preset.name, preset.principled)
    mat[PRESET_KEY] = {"features": preset.features.as_dict(), "rt_lit": dict(preset.rt_lit)}
    mat.asset_mark()
    mat.asset_data.catalog_id = core_presets.CATALOG_IDS[preset.catalog]
    mat.asset_data.description = preset.description
    for tag in ("RT Lookdev", preset.catalog, preset.features.specular, preset.features.diffuse):
        mat.asset_data.tags.new(tag, skip_if_exists=True)
    return mat


def build_library(folder=ASSETS_DIR):
    """Write the presets' .blend and catalog file into ``folder``; returns the .blend's path."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    made = [preset_material(p) for p in core_presets.PRESETS]
    path = folder / LIBRARY_FILE.name
    bpy.data.libraries.write(str(path), set(made), fake_user=True, compress=True)
    (folder / CATALOG_FILE.name).write_text(catalog_text())
    for mat in made:
        bpy.data.materials.remove(mat)
    return path


# --- the asset library entry in the preferences --------------------------------------------------------

def _libraries():
    return bpy.context.preferences.filepaths.asset_libraries


def register_library():
    """Add the assets folder to the preferences' asset libraries unless an entry already points at it."""
    if not LIBRARY_FILE.is_file():
        return None
    libraries = _libraries()
    for lib in libraries:
        if Path(bpy.path.abspath(lib.path)).resolve() == ASSETS_DIR.resolve():
            return lib
    lib = libraries.new(name=LIBRARY_NAME, directory=str(ASSETS_DIR))
    _added.append(str(ASSETS_DIR))
    return lib


def unregister_library():
    libraries = _libraries()
    for lib in list(libraries):
        if lib.name == LIBRARY_NAME and str(Path(lib.path)) in _added:
            libraries.remove(lib)
    _added.clear()


# --- conversion on first use ---------------------------------------------------------------------------

def pending_presets():
    """Preset materials not converted yet and in use (assigned to something besides their fake user)."""
    return [m for m in bpy.data.materials
            if PRESET_KEY in m and m.library is None and m.users > (1 if m.use_fake_user else 0)]


def convert_preset(material, scene, lut_dir=None):
    """Convert a preset material to RT Lit with its stored switches and RT Lit-only values."""
    from . import convert, materials

    record = material[PRESET_KEY]
    features = Features.from_dict(record["features"])
    result = convert.principled_to_rt_lit(
        material, lambda f: materials.ensure_rt_lit_group(f, scene, lut_dir), features)
    node = material.node_tree.nodes[RT_LIT_NODE_NAME]
    for key, value in dict(record.get("rt_lit", {})).items():
        node.inputs[key].default_value = tuple(value) if hasattr(value, "__len__") else value
    del material[PRESET_KEY]
    return result


def convert_pending(scene, lut_dir=None):
    """Convert every pending preset (``pending_presets``); returns the conversion results."""
    return [convert_preset(m, scene, lut_dir) for m in pending_presets()]
