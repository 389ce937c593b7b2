"""The pure-numpy math core of RT Lookdev.  Nothing under ``core`` imports ``bpy``.

Modules (each names the paper or talk equation it implements):

- ``conventions``   roughness/alpha mapping and the numeric guards shared by all code
- ``shading_ops``   math with Blender shader-node semantics (safe divide, clamped acos, ...)
- ``microfacet``    GGX D, Smith G1 / height-correlated G2, single-scattering GGX BRDF, VNDF sampling
- ``fresnel``       Schlick Fresnel and its hemispherical average
- ``energy``        directional albedo E(mu, r), split-sum (scale, bias), E_avg integrators (baking)
- ``multiscatter``  Kulla-Conty lobe, Turquin compensation, Fdez-Aguera environment BRDF
- ``diffuse``       Lambert, Call of Duty WWII multiscattering diffuse, wrapped diffuse
- ``cloth``         Ashikhmin velvet with Neubelt-Pettineo visibility, Disney sheen
- ``falloff``       light falloffs from the talk's epilogue
- ``sampling``      low-discrepancy point sets
- ``lut``           lookup-table layout, EXR storage, baking and caching
"""
