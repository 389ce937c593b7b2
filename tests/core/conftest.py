"""Fixtures for the numpy core tests (no bpy)."""
import pytest

from rt_lookdev.core.lut import bake, catalog, lookup


@pytest.fixture(scope="session")
def lut_dir(tmp_path_factory):
    """The shipped LUT folder when it is current, else a fresh bake into a temp folder."""
    shipped = catalog.default_lut_dir()
    if all(s.state == "ok" for s in catalog.lut_status(shipped)):
        return shipped
    out = tmp_path_factory.mktemp("luts")
    bake.bake(out)
    return out


@pytest.fixture(scope="session")
def energy_tables(lut_dir):
    return lookup.EnergyTables(lut_dir)
