"""Make the repository importable as the package ``rt_lookdev`` from plain Python.

The repository root *is* the Blender extension package (its ``__init__.py`` holds
``register``/``unregister``), and Blender imports it as ``bl_ext.<repo>.rt_lookdev``.
Scripts and tests run outside Blender's extension system, where the checkout's
folder name is arbitrary, so they load the root under the fixed name
``rt_lookdev``.  Every module inside uses relative imports, so both names work.
"""
from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[1]
PACKAGE = "rt_lookdev"


def import_package():
    """Return the ``rt_lookdev`` package, loading it from the repository root once."""
    module = sys.modules.get(PACKAGE)
    if module is not None:
        return module
    spec = importlib.util.spec_from_file_location(
        PACKAGE, REPO_ROOT / "__init__.py", submodule_search_locations=[str(REPO_ROOT)]
    )
    module = importlib.util.module_from_spec(spec)
    sys.modules[PACKAGE] = module
    spec.loader.exec_module(module)
    return module


import_package()
