"""The bpy layer of RT Lookdev: operators, preferences and UI.

Everything that touches ``bpy`` lives here; the numeric work is in ``..core``.  Each
submodule defines its classes, and this module registers them in one ``classes``
tuple (in order), then appends the ``menus`` entries; unregistering does both in reverse.
Registration reads no file (it only checks that the preset library exists, to list it as an asset library).
"""
import atexit

import bpy

from . import (compat, convert_ui, export_operators, light_controls, light_sync, lookdev_operators, operators,
               preferences, preset_assets, switches, ui)

classes = (
    *operators.classes,
    *export_operators.classes,
    *lookdev_operators.classes,
    *convert_ui.classes,
    *preferences.classes,
    *switches.classes,
    *ui.classes,
)
#: (menu, draw function): entries appended to Blender's menus (File > Export, 3D viewport > Add).
menus = (*export_operators.menus, *lookdev_operators.menus)


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
    light_controls.register()
    light_sync.register()
    preset_assets.register_library()
    if compat.module_exit_hangs_while_registered():
        atexit.register(unregister)   # runs before bpy's own exit handler (atexit is last in, first out)


def unregister():
    atexit.unregister(unregister)
    preset_assets.unregister_library()
    light_sync.unregister()
    light_controls.unregister()
    switches.unregister()
    for menu, draw in reversed(menus):
        menu.remove(draw)
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
    preferences.clear_status_cache()
