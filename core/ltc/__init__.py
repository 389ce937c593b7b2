"""Linearly Transformed Cosines (Heitz, Dupuy, Hill & Neubelt 2016) for area lights.

- ``matrix``        LTC matrices in the local shading frame: packing, density, sampling
- ``lobes``         the BRDF x cos lobes that get LTC tables (GGX, CoD WWII diffuse, Ashikhmin cloth)
- ``fit``           the batched fitter and the magnitude / Fresnel integrals
- ``sphere_table``  horizon-clipped spherical-cap form factor (Snyder 1996) and its table
- ``polygon``       quad integration: clipless vector form factor + sphere table, exact clipping
- ``disk``          disk / ellipse integration (Heitz & Hill 2017 closed form)
- ``reference``     brute-force BRDF x cos integrals over polygons and disks (ground truth)

Local frame: N = +Z; the view vector lies in the XZ plane, V = (sin theta, 0, cos theta).
Tables store the inverse matrix normalised so that Minv[1][1] = 1 with four free entries
(the layout of selfshadow/ltc_code, docs/area_lights.md, "Table layout"):
    Minv = [[c0, 0, c2],
            [0,  1, 0 ],
            [c1, 0, c3]]
"""
