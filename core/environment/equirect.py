"""Equirectangular environment images as Blender's World samples them (numpy, no bpy).

Blender's mapping (Cycles, ``intern/cycles/kernel/camera/projection.h``,
``direction_to_equirectangular`` = ``direction_to_equirectangular_range(dir, (-2 pi, pi, -pi, pi))``,
called by ``svm_node_tex_environment`` in ``intern/cycles/kernel/svm/image.h`` after
``safe_normalize`` of the Vector input; blender/blender on GitHub).  For a unit direction
d = (x, y, z) in world space (Z up):

    u = 0.5 - atan2(y, x) / (2 pi)        (u grows *clockwise* seen from above: +X at u = 0.5,
                                           +Y at u = 0.25, -Y at u = 0.75, -X at the seam u = 0 / 1)
    v = 1 - acos(z) / pi                  (v = 1 at the zenith +Z, v = 0 at the nadir -Z)

and the inverse ``equirectangular_to_direction``: phi = pi - 2 pi u, theta = pi (1 - v),
d = (sin theta cos phi, sin theta sin phi, cos theta).  Blender's image v is counted from the
bottom row, so the *top* scanline of the file (its first) holds the zenith.  With the World's
Environment Texture on its default Vector (generated coordinates = the view direction) the
radiance seen in direction d is the texel at (u(d), v(d)).

Arrays here keep the file's orientation: ``image[row, col, c]`` with row 0 the top scanline.
Texel (row, col) covers theta in [pi row / H, pi (row + 1) / H] and its centre is at
theta = pi (row + 1/2) / H, u = (col + 1/2) / W (phi = pi - 2 pi u).

World rotation and strength follow the usual node setup: Texture Coordinate (Generated) ->
Mapping (type Point, Rotation Z = ``rotation_z``) -> Environment Texture -> Background
(Strength = ``strength``).  A Point Mapping node outputs R_z(rotation_z) d (Blender's Mapping
node: rotate then translate), so L_world(d) = strength * image(R_z(rotation_z) d).
"""
from __future__ import annotations

import hashlib
import importlib.util
from dataclasses import dataclass
from pathlib import Path

import numpy as np

PI = np.pi


def studio_lights_dir():
    """Blender's bundled studio HDRIs (CC0) inside the installed bpy wheel: ``datafiles/studiolights/world``."""
    spec = importlib.util.find_spec("bpy")
    roots = []
    if spec is not None and spec.submodule_search_locations:
        roots = [Path(p) for p in spec.submodule_search_locations]
    for root in roots:
        for d in sorted(root.glob("*/datafiles/studiolights/world")):
            if d.is_dir():
                return d
    raise FileNotFoundError("Blender's studio lights (bpy/<version>/datafiles/studiolights/world) not found; "
                            "install the pinned bpy wheel (requirements.lock)")


def studio_hdris():
    """{name: path} of the studio HDRIs shipped with Blender (city, courtyard, ..., sunset)."""
    return {p.stem: p for p in sorted(studio_lights_dir().glob("*.exr"))}


def resolve_hdri(name_or_path):
    """A studio HDRI name ("forest") or a path to an equirectangular EXR."""
    p = Path(name_or_path)
    if p.suffix.lower() == ".exr" and p.is_file():
        return p
    hdris = studio_hdris()
    if str(name_or_path) in hdris:
        return hdris[str(name_or_path)]
    raise FileNotFoundError(f"{name_or_path!r}: neither an EXR file nor one of Blender's studio HDRIs "
                            f"({', '.join(hdris)})")


def read_equirect(path):
    """(H, W, 3) float32 RGB of an equirectangular EXR, top scanline first (row 0 = zenith).

    Uses the OpenEXR package (the studio HDRIs are DWAB-compressed, which the repository's
    pure-numpy reader core/lut/exr_reader.py does not decode).  Missing G/B channels repeat R
    (a luminance-only "Y" image is read as grey)."""
    import OpenEXR

    with OpenEXR.File(str(path), separate_channels=True) as exr:
        channels = {name: np.array(ch.pixels, dtype=np.float32) for name, ch in exr.channels().items()}
    first = channels.get("R", channels.get("Y"))
    if first is None:
        raise ValueError(f"{path}: no R or Y channel (channels: {sorted(channels)})")
    rgb = [channels.get(c, first) for c in ("R", "G", "B")]
    image = np.stack(rgb, axis=-1).astype(np.float32)
    if image.ndim != 3 or image.shape[1] != 2 * image.shape[0]:
        # Equirectangular images are 2:1; anything else is still read, its texels just are not square.
        pass
    return np.nan_to_num(image, nan=0.0, posinf=0.0, neginf=0.0)


def image_hash(image):
    """SHA-256 of an image as little-endian float32 (the environment's cache key)."""
    return hashlib.sha256(np.ascontiguousarray(np.asarray(image, dtype="<f4")).tobytes()).hexdigest()


# --- the mapping ---------------------------------------------------------------------------------

def direction_to_uv(d):
    """Blender's equirectangular (u, v) of directions d (..., 3) (need not be unit).  See the module
    docstring: u = 0.5 - atan2(y, x)/(2 pi), v = 1 - acos(z/|d|)/pi."""
    d = np.asarray(d, dtype=np.float64)
    length = np.linalg.norm(d, axis=-1)
    u = 0.5 - np.arctan2(d[..., 1], d[..., 0]) / (2.0 * PI)
    v = 1.0 - np.arccos(np.clip(d[..., 2] / np.maximum(length, 1e-300), -1.0, 1.0)) / PI
    return u, v


def uv_to_direction(u, v):
    """Inverse of ``direction_to_uv``: phi = pi - 2 pi u, theta = pi (1 - v) (Cycles
    ``equirectangular_to_direction``)."""
    phi = PI - 2.0 * PI * np.asarray(u, dtype=np.float64)
    theta = PI * (1.0 - np.asarray(v, dtype=np.float64))
    s = np.sin(theta)
    return np.stack([s * np.cos(phi), s * np.sin(phi), np.cos(theta)], axis=-1)


def rotation_z(angle):
    """3x3 rotation about +Z by ``angle`` (right-handed, as Blender's Mapping node's Z rotation)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def texel_angles(h, w):
    """(theta (H,), phi (W,)) of the texel centres: theta = pi (row + 1/2)/H, phi = pi - 2 pi (col + 1/2)/W."""
    theta = PI * (np.arange(h) + 0.5) / h
    phi = PI - 2.0 * PI * (np.arange(w) + 0.5) / w
    return theta, phi


def texel_directions(h, w, rows=slice(None)):
    """(H, W, 3) unit directions of the texel centres (image orientation, row 0 at the zenith); only
    the ``rows`` (a slice) when given."""
    theta, phi = texel_angles(h, w)
    theta = theta[rows]
    st, ct = np.sin(theta)[:, None], np.cos(theta)[:, None]
    return np.stack(np.broadcast_arrays(st * np.cos(phi)[None, :], st * np.sin(phi)[None, :], ct), axis=-1)


def texel_solid_angles(h, w):
    """(H, W) exact solid angle of each texel: (2 pi / W)(cos theta_top - cos theta_bottom).
    Sums to 4 pi (to rounding)."""
    edges = np.cos(PI * np.arange(h + 1) / h)
    row = (edges[:-1] - edges[1:]) * (2.0 * PI / w)
    return np.broadcast_to(row[:, None], (h, w)).copy()


def fejer_weights(n):
    """Fejer's first quadrature rule on [-1, 1] at the Chebyshev nodes x_j = cos(pi (j + 1/2)/n):

        w_j = (2/n) (1 - 2 sum_{k=1}^{floor(n/2)} cos(2 k theta_j) / (4 k^2 - 1)),  theta_j = pi (j + 1/2)/n

    (Fejer 1933; Davis & Rabinowitz, "Methods of Numerical Integration", 2nd ed., sec. 2.5.5;
    Waldvogel 2006, BIT 46, eq. 2.5).  Exact for polynomials in x of degree < n; positive weights.
    The nodes are exactly the cosines of the equirect rows' centre angles, so int f(cos theta)
    sin theta dtheta = sum_j w_j f(cos theta_j)."""
    theta = PI * (np.arange(n) + 0.5) / n
    k = np.arange(1, n // 2 + 1)
    s = np.cos(2.0 * np.outer(theta, k)) / (4.0 * k * k - 1.0)
    return (2.0 / n) * (1.0 - 2.0 * s.sum(axis=1))


def quadrature_weights(h, w, rule="fejer"):
    """(H, W) weights of a point-sample quadrature on the sphere at the texel centres; both rules
    sum to 4 pi.

    ``rule="fejer"`` (default): Fejer's first rule in cos(theta) (``fejer_weights``) times the
    midpoint rule 2 pi / W in phi.  Exact for every function that is a polynomial of degree < H in z
    times a trigonometric polynomial of degree < W in phi, so the SH projection of any band-limited
    environment (bands < H/2 ... every L2 product needs degree <= 4) sampled at the texel centres
    is exact to rounding.
    ``rule="area"``: the exact solid angle of each texel (``texel_solid_angles``), second-order
    accurate for smooth functions.  The two differ by O(1/H^2)."""
    if rule == "area":
        return texel_solid_angles(h, w)
    if rule != "fejer":
        raise ValueError(f"unknown quadrature rule {rule!r} (fejer, area)")
    return np.broadcast_to((fejer_weights(h) * (2.0 * PI / w))[:, None], (h, w)).copy()


# --- the environment -----------------------------------------------------------------------------

@dataclass
class Environment:
    """An equirectangular image as the World shows it: L(d) = strength * image(R_z(rotation_z) d).

    ``image`` (H, W, 3) float, top scanline first (``read_equirect``).  ``rotation_z`` in radians
    (Mapping node, type Point, Rotation Z), ``strength`` the Background node's Strength."""
    image: np.ndarray
    rotation_z: float = 0.0
    strength: float = 1.0
    name: str = ""

    @classmethod
    def load(cls, name_or_path, rotation_z=0.0, strength=1.0):
        path = resolve_hdri(name_or_path)
        return cls(read_equirect(path), rotation_z, strength, Path(path).stem)

    @property
    def shape(self):
        return self.image.shape[:2]

    def content_hash(self):
        return image_hash(self.image)

    def lookup_directions(self, d):
        """Image-space directions R_z(rotation_z) d of world directions d (..., 3)."""
        if self.rotation_z == 0.0:
            return np.asarray(d, dtype=np.float64)
        return np.asarray(d, dtype=np.float64) @ rotation_z(self.rotation_z).T

    def world_texel_directions(self, rows=slice(None)):
        """(H, W, 3) world directions of the texel centres: R_z(-rotation_z) applied to the image's
        (only the ``rows``, a slice, when given)."""
        d = texel_directions(*self.shape, rows=rows)
        if self.rotation_z == 0.0:
            return d
        return d @ rotation_z(-self.rotation_z).T

    def radiance(self, d, interpolation="linear"):
        """Radiance in world directions d (..., 3): strength x the image looked up as Blender does
        (``sample_equirect``)."""
        return self.strength * sample_equirect(self.image, self.lookup_directions(d), interpolation)

    def downsampled(self, factor):
        """The same environment with the image area-averaged by ``factor`` (a power of two)."""
        return Environment(downsample(self.image, factor), self.rotation_z, self.strength, self.name)


def sample_equirect(image, d, interpolation="linear"):
    """Look up an equirect image (top row first) at directions d (..., 3).

    "linear": bilinear between the four nearest texel centres, wrapping in u (the image is periodic
    in longitude) and clamping in v (EXTEND at the poles), as Cycles' Linear interpolation of the
    Environment Texture; "closest": the texel containing (u, v)."""
    image = np.asarray(image)
    h, w = image.shape[:2]
    u, v = direction_to_uv(d)
    x = u * w - 0.5                 # column coordinate, texel centres at integers
    y = (1.0 - v) * h - 0.5         # row coordinate from the top
    if interpolation == "closest":
        col = np.mod(np.floor(x + 0.5).astype(np.int64), w)
        row = np.clip(np.floor(y + 0.5).astype(np.int64), 0, h - 1)
        return image[row, col]
    return bilinear(image, x, y)


def bilinear(image, x, y):
    """Bilinear reconstruction of image (H, W, C) at (column x, row y) in texel-centre units:
    wraps x (longitude), clamps y (latitude)."""
    h, w = image.shape[:2]
    x0 = np.floor(x)
    y0 = np.floor(y)
    fx = (x - x0)[..., None].astype(image.dtype)
    fy = (y - y0)[..., None].astype(image.dtype)
    x0 = x0.astype(np.int64)
    y0 = y0.astype(np.int64)
    c0 = np.mod(x0, w)
    c1 = np.mod(x0 + 1, w)
    r0 = np.clip(y0, 0, h - 1)
    r1 = np.clip(y0 + 1, 0, h - 1)
    top = image[r0, c0] * (1 - fx) + image[r0, c1] * fx
    bottom = image[r1, c0] * (1 - fx) + image[r1, c1] * fx
    return top * (1 - fy) + bottom * fy


#: The smallest equirect grid the bake integrates on (rows; columns = 2 x rows).  An image with fewer rows
#: (a 1 x 1 constant world, a 2 x 1 gradient) is replicated up to it first: with one row, the quadrature
#: has a single node at the equator and a constant world came out with Y_2,0 = -3.4 (docs/robustness.md).
MIN_BAKE_HEIGHT = 16


def replicate_to_minimum(image, min_height=MIN_BAKE_HEIGHT):
    """``image`` with each texel repeated k x k times (k the smallest power of two bringing the height to
    ``min_height`` and the width to 2 x that): the same piecewise-constant world, on a grid the bake's
    quadrature integrates.  Larger images are returned as they are."""
    image = np.asarray(image)
    h, w = image.shape[:2]
    k = 1
    while h * k < min_height or w * k < 2 * min_height:
        k *= 2
    return image if k == 1 else np.repeat(np.repeat(image, k, axis=0), k, axis=1)


def downsample(image, factor=2):
    """Area average of an equirect image over factor x factor blocks, each texel weighted by its
    exact solid angle (so the integral of the image over every block is preserved exactly)."""
    image = np.asarray(image)
    f = int(factor)
    if f == 1:
        return image.copy()
    if f < 1 or f & (f - 1):
        raise ValueError(f"downsample factor must be a power of two, got {factor}")
    h, w = image.shape[:2]
    if h % f or w % f:
        raise ValueError(f"image {w}x{h} is not divisible by {f}")
    return resample_area(image, h // f, w // f)


def _rebin_segments(in_edges, out_edges):
    """Split [in_edges[0], in_edges[-1]] (= the out_edges range) at both sets of bin edges: for each
    piece, its input bin, its output bin and its length; and where each output bin's pieces start."""
    knots = np.union1d(in_edges, out_edges)
    mids = 0.5 * (knots[:-1] + knots[1:])
    src = np.clip(np.searchsorted(in_edges, mids) - 1, 0, len(in_edges) - 2)
    dst = np.clip(np.searchsorted(out_edges, mids) - 1, 0, len(out_edges) - 2)
    starts = np.flatnonzero(np.r_[True, dst[1:] != dst[:-1]])
    return src, np.diff(knots), starts


def _rebin_axis(a, in_edges, out_edges, axis, chunk=1024):
    """Means of the piecewise-constant ``a`` (bins ``in_edges`` along ``axis``) over the bins
    ``out_edges``: each output is a positive-weight sum of the input bins it overlaps (no cumulative
    sums, so a bright sun does not cost dark neighbours their precision).  Chunked along the other
    image axis to bound memory."""
    src, length, starts = _rebin_segments(in_edges, out_edges)
    widths = np.diff(out_edges)
    a = np.moveaxis(a, axis, 0)
    out = np.empty((len(widths),) + a.shape[1:], dtype=np.float64)
    for s in range(0, a.shape[1], chunk):
        part = a[:, s:s + chunk].astype(np.float64)[src] * length[:, None, None]
        out[:, s:s + chunk] = np.add.reduceat(part, starts, axis=0) / widths[:, None, None]
    return np.moveaxis(out, 0, axis)


def resample_area(image, height, width):
    """Area average of an equirect image onto a ``height`` x ``width`` grid of any size: every output
    texel is the solid-angle-weighted mean of the parts of the input texels it covers, so the image's
    integral over every output texel is preserved exactly (rows are binned in cos(theta), in which a
    texel's solid angle is linear).  ``downsample`` is the special case of power-of-two factors."""
    image = np.asarray(image)
    h, w = image.shape[:2]
    if height < 1 or width < 1:
        raise ValueError(f"cannot resample to {width}x{height}")
    if (h, w) == (height, width):
        return image.copy()
    s_in, s_out = 1.0 - np.cos(PI * np.arange(h + 1) / h), 1.0 - np.cos(PI * np.arange(height + 1) / height)
    s_in[-1] = s_out[-1] = 2.0                          # the same end point for both grids
    rows = _rebin_axis(image, s_in, s_out, axis=0)
    cols = _rebin_axis(rows, np.arange(w + 1) / w, np.arange(width + 1) / width, axis=1)
    return cols.astype(image.dtype)


def mip_chain(image, min_height=1):
    """[level 0 = image, level 1 = downsample(image, 2), ...] down to ``min_height`` rows."""
    levels = [np.asarray(image)]
    while levels[-1].shape[0] % 2 == 0 and levels[-1].shape[0] // 2 >= min_height and levels[-1].shape[1] % 2 == 0:
        levels.append(downsample(levels[-1], 2))
    return levels


def integrate(image, fn_of_directions=None, rule="fejer"):
    """int L(d) g(d) dd over the sphere for an image (H, W, C) sampled at texel centres, with
    ``quadrature_weights``; g = 1 when not given.  Returns (C,)."""
    image = np.asarray(image, dtype=np.float64)
    h, w = image.shape[:2]
    wts = quadrature_weights(h, w, rule)
    if fn_of_directions is not None:
        wts = wts * fn_of_directions(texel_directions(h, w))
    return np.einsum("hw,hwc->c", wts, image)
