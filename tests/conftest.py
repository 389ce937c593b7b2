"""Shared pytest setup.

- The repository is the package ``rt_lookdev`` (installed in editable mode by scripts/env.sh).
- ``BLENDER_USER_RESOURCES`` points at a throw-away directory before anything can
  import bpy, so tests never read or write the developer's ~/.config/blender; baked world
  environments are cached in out/cache/environments (``RTL_ENVIRONMENT_CACHE``) unless set.
- ``blender`` marker for tests that need the bpy module; fixtures ``bpy_module``
  (imports bpy once per session: it must never be re-imported), ``empty_scene``, ``registered`` (the
  add-on's classes) and ``relink_from_library``.
"""
import os
import tempfile
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
_USER_RESOURCES = tempfile.TemporaryDirectory(prefix="rtl-blender-user-")
os.environ["BLENDER_USER_RESOURCES"] = _USER_RESOURCES.name
# baked world environments (addon/world.py) go to the ignored out/ folder, not to ~/.cache
os.environ.setdefault("RTL_ENVIRONMENT_CACHE", str(REPO / "out" / "cache" / "environments"))


@pytest.fixture(scope="session")
def bpy_module():
    import bpy

    return bpy


@pytest.fixture
def empty_scene(bpy_module):
    """Empty the open file (keeps preferences and enabled extensions)."""
    bpy_module.ops.wm.read_homefile(use_empty=True)
    return bpy_module.context.scene


@pytest.fixture(scope="session")
def lut_dir(tmp_path_factory):
    """The shipped LUT folder when it is current, else a fresh bake into a temp folder."""
    from rt_lookdev.core import lut_bake as bake
    from rt_lookdev.core.lut import catalog

    shipped = catalog.default_lut_dir()
    if all(s.state == "ok" for s in catalog.lut_status(shipped)):
        return shipped
    out = tmp_path_factory.mktemp("luts")
    bake.bake(out)
    return out


@pytest.fixture(scope="session")
def tables(lut_dir):
    """The LUT set of ``lut_dir`` (``core.lut.lookup.LutSet``): what numpy evaluation and node groups read."""
    from rt_lookdev.core.lut import lookup

    return lookup.LutSet.from_folder(lut_dir)


@pytest.fixture
def registered(bpy_module):
    """The add-on's classes registered (from the source tree), unregistered afterwards."""
    from rt_lookdev import addon

    addon.register()
    yield bpy_module
    addon.unregister()


@pytest.fixture
def relink_from_library(bpy_module, tmp_path):
    """``relink(collection, name)``: move the local datablock ``bpy.data.<collection>[name]`` into a library
    .blend (``tmp_path``/library.blend) and link it back; returns the linked datablock."""
    def relink(collection, name):
        data = getattr(bpy_module.data, collection)
        library = tmp_path / "library.blend"
        bpy_module.data.libraries.write(str(library), {data[name]})
        data.remove(data[name])
        with bpy_module.data.libraries.load(str(library), link=True) as (_, dst):
            setattr(dst, collection, [name])
        linked = getattr(dst, collection)[0]
        assert linked.library is not None
        return linked

    return relink
