"""Lookdev materials composed from the shading techniques (pure Python; no bpy).

- ``rt_lit_interface``  inputs, outputs, names and build-time switches (``Features``) of RT Lit
- ``surface``           "RTL Surface": the material's inputs guarded and turned into shading terms
- ``lobes``             every lobe as one unit: its punctual and area forms
- ``light_shading``     one light on the material: the enabled lobes combined with colours
- ``world_shading``     the World term: SH diffuse, split-sum specular, SH-LTC cloth and sheen
- ``rt_lit``            the whole material as one traced function (``build_rt_lit``)
"""
