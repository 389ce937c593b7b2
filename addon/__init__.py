"""The bpy layer of RT Lookdev: operators, preferences and UI.

Everything that touches ``bpy`` lives here; the numeric work is in ``..core``.  Each
submodule defines its classes, and this module registers them in one ``classes``
tuple (in order), then appends the ``menus`` entries; unregistering does both in reverse.
Registration does no file I/O.
"""
import bpy

from . import compat, convert, export_operators, light_sync, operators, preferences, switches, ui

classes = (
    *operators.classes,
    *export_operators.classes,
    *convert.classes,
    *preferences.classes,
    *switches.classes,
    *ui.classes,
)
#: (menu, draw function): entries appended to Blender's menus (File > Export).
menus = (*export_operators.menus,)


def register():
    """Register every class; on a Blender older than ``compat.MINIMUM_VERSION`` refuse with a message
    naming the supported releases (Blender shows it where the add-on is enabled), registering nothing."""
    if not compat.supported():
        raise RuntimeError(compat.unsupported_message())
    for cls in classes:
        bpy.utils.register_class(cls)
    for menu, draw in menus:
        menu.append(draw)
    switches.register()
    light_sync.register()


def unregister():
    light_sync.unregister()
    switches.unregister()
    for menu, draw in reversed(menus):
        menu.remove(draw)
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
    preferences.clear_status_cache()
