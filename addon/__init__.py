"""The bpy layer of RT Lookdev: operators, preferences and UI.

Everything that touches ``bpy`` lives here; the numeric work is in ``..core``.  Each
submodule defines its classes, and this module registers them in one ``classes``
tuple (in order) and unregisters them in reverse.  Registration does no file I/O.
"""
import bpy

from . import compat, convert, operators, preferences, ui

classes = (
    *operators.classes,
    *convert.classes,
    *preferences.classes,
    *ui.classes,
)


def register():
    """Register every class; on a Blender older than ``compat.MINIMUM_VERSION`` refuse with a message
    naming the supported releases (Blender shows it where the add-on is enabled), registering nothing."""
    if not compat.supported():
        raise RuntimeError(compat.unsupported_message())
    for cls in classes:
        bpy.utils.register_class(cls)


def unregister():
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
    preferences.clear_status_cache()
