"""RT Lookdev: real-time-style shading (multiscattering BRDFs, LTC area lights) for Blender.

This file is the extension's entry point.  Blender imports the repository root as
``bl_ext.<repo>.rt_lookdev``; plain Python (tests, scripts) imports it as
``rt_lookdev`` (scripts/env.sh installs the checkout in editable mode: pyproject.toml).  Importing this package must not
import ``bpy``: the numpy core in ``core/`` is used without Blender.  The bpy layer
(``addon/``) is imported only when Blender calls ``register``.
"""


def register():
    from .addon import register as _register

    _register()


def unregister():
    from .addon import unregister as _unregister

    _unregister()
