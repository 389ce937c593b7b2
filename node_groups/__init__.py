"""Shader node groups of RT Lookdev (built from the numpy core's descriptions)."""
