"""Lookdev materials composed from the shading techniques (pure Python; no bpy)."""
