"""Exports for engines and standalone renderers (no bpy): the scene description (``scene``)."""
