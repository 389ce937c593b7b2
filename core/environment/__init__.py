"""World environment baking in numpy (issue 6, part 1): equirectangular images, L2 spherical
harmonics, GGX-prefiltered specular radiance.  No bpy.

* ``equirect``  -- reading the World's equirectangular image, Blender's direction <-> (u, v)
  mapping, world rotation about Z and strength, per-texel quadrature weights, mip chain and
  bilinear lookups.
* ``sh``        -- real L2 SH (Ramamoorthi & Hanrahan 2001): projection, radiance, irradiance,
  clamped-cosine and wrapped-cosine lobes.
* ``prefilter`` -- split-sum (Karis 2013) GGX prefiltered radiance by importance sampling with
  filtered lookups (Colbert & Krivanek 2007), cached EXR output.
"""
