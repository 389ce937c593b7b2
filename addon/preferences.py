"""Add-on preferences: where the LUT tables are read from, and their status."""
from __future__ import annotations

from pathlib import Path

import bpy
from bpy.props import BoolProperty, StringProperty

from ..core.lut import catalog

#: The extension's top-level package: ``bl_ext.<repo>.rt_lookdev`` when Blender loads
#: the extension, ``rt_lookdev`` when tests load the source tree.  Add-on preferences
#: are keyed by this name (``context.preferences.addons[ADDON_PACKAGE]``).  This
#: module's ``__package__`` is ``<root>.addon``, so drop the last component.
ADDON_PACKAGE = __package__.rpartition(".")[0]

#: Icons shown next to each table in the preferences, by ``LutStatus.state``.
STATE_ICONS = {
    "ok": 'CHECKMARK',
    "missing": 'ERROR',
    "stale": 'TIME',
    "corrupt": 'CANCEL',
    "mismatch": 'CANCEL',
}

#: Where the extension bakes the tables: what a message about unusable tables suggests (its zip has no scripts/).
BAKE_HINT = ("bake them with Bake LUTs (Edit > Preferences > Add-ons > RT Lookdev, or the button in the RT Lookdev "
             "panel) or set another LUT directory there")

# Last status per LUT directory (str path -> list[LutStatus]).  Filled lazily by
# draw() and refreshed by RTL_OT_lut_status, so redraws do not re-read the tables.
_status_cache: dict[str, list] = {}


def get_preferences(context=None):
    """The add-on's preferences, or None when it was registered without addon_utils."""
    context = context or bpy.context
    addon = context.preferences.addons.get(ADDON_PACKAGE)
    return addon.preferences if addon is not None else None


def lut_directory(context=None) -> Path:
    """The directory to read LUTs from: the preference if set, else the shipped ``luts/``."""
    prefs = get_preferences(context)
    custom = prefs.lut_directory.strip() if prefs is not None else ""
    if custom:
        return Path(bpy.path.abspath(custom))
    return catalog.default_lut_dir()


def environment_cache_directory(context=None):
    """The preference "Environment Cache" as a path, or None when it is empty (or the add-on is registered
    without addon_utils): then ``world_sync.default_cache_dir`` falls back to $RTL_ENVIRONMENT_CACHE."""
    prefs = get_preferences(context)
    custom = prefs.environment_cache.strip() if prefs is not None else ""
    return Path(bpy.path.abspath(custom)).expanduser() if custom else None


def refresh_status(lut_dir: Path) -> list:
    """Check every table in ``lut_dir`` and remember the result for draw()."""
    statuses = list(catalog.lut_status(lut_dir))
    _status_cache[str(lut_dir)] = statuses
    return statuses


def summarise_status(statuses, states):
    """``"corrupt: a, b; mismatch: c"``: the tables of ``statuses`` in each of ``states``."""
    parts = []
    for state in states:
        names = [s.name for s in statuses if s.state == state]
        if names:
            parts.append(f"{state}: {', '.join(names)}")
    return "; ".join(parts)


def cached_status(lut_dir: Path) -> list:
    statuses = _status_cache.get(str(lut_dir))
    if statuses is None:
        statuses = refresh_status(lut_dir)
    return statuses


def clear_status_cache():
    _status_cache.clear()


class RTL_AddonPreferences(bpy.types.AddonPreferences):
    bl_idname = ADDON_PACKAGE

    lut_directory: StringProperty(
        name="LUT Directory",
        description=(
            "Folder holding the baked lookup-table EXR files. "
            "Leave empty to use the tables shipped with the add-on"
        ),
        subtype='DIR_PATH',
        default="",
    )
    environment_cache: StringProperty(
        name="Environment Cache",
        description=("Folder for the baked world environments (SH and prefiltered levels, named by the image's "
                     "content). Empty: $RTL_ENVIRONMENT_CACHE, else ~/.cache/rt_lookdev/environments"),
        subtype='DIR_PATH',
        default="",
    )
    auto_sync_lights: BoolProperty(
        name="Sync Lights Automatically",
        description=("Rebuild the RT Lit groups when lights are added, removed, hidden from renders, moved to an "
                     "excluded collection or change shape (moving and editing lights needs no sync)"),
        default=True,
    )

    def draw(self, context):
        layout = self.layout
        layout.prop(self, "lut_directory")
        layout.prop(self, "environment_cache")
        layout.prop(self, "auto_sync_lights")

        lut_dir = lut_directory(context)
        box = layout.box()
        box.label(text=f"Tables in {lut_dir}", icon='FILE_FOLDER')
        if not lut_dir.is_dir():
            box.label(text="Directory does not exist", icon='ERROR')
        else:
            try:
                statuses = cached_status(lut_dir)
            except Exception as ex:  # show, never break the preferences panel
                box.label(text=f"Could not check tables: {ex}", icon='ERROR')
            else:
                col = box.column(align=True)
                for status in statuses:
                    row = col.row()
                    row.label(text=status.name, icon=STATE_ICONS.get(status.state, 'QUESTION'))
                    row.label(text=status.state)
                    if status.state != "ok" and status.message:
                        col.label(text=f"    {status.message}")
        row = layout.row()
        row.operator("rtl.lut_status", icon='FILE_REFRESH')
        row.operator("rtl.bake_luts", icon='RENDER_STILL')


classes = (RTL_AddonPreferences,)
