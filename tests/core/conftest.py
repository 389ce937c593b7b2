"""Fixtures for the numpy core tests (no bpy)."""
import pytest

from rt_lookdev.core.lut import lookup


@pytest.fixture(scope="session")
def energy_tables(lut_dir):
    return lookup.LutSet.from_folder(lut_dir)
