"""Shader node groups of RT Lookdev: ``library`` lists them as node functions of the numpy core;
addon/node_emit.py builds them (``ensure_function_group``) and the operator "Add RT Lookdev Node
Groups" loads them all into the file (Add > Group)."""
