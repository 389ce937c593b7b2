"""The scene's World as RT Lit sees it: find what it shows, bake it, expose it as a node group.

- ``world_setup(world)`` walks the active World Output and says where the world's radiance comes from
  (``WorldSetup.source``):
  - "image": Background <- Environment Texture (equirectangular, an image with pixels) [<- Mapping (Point or
    Vector, rotation only) <- Texture Coordinate > Generated]: the image's pixels are read;
  - "constant": a Background whose Color is a plain colour (every new Blender file's world), or a world without
    nodes (its Color): no render, the colour is the image;
  - "render": anything else Cycles can draw (a Sky Texture, a Mix, Object coordinates, a Mapping with scale, an
    8-bit image in another colour space, a Mix Shader of Backgrounds...): the world rendered by Cycles through an
    equirectangular panoramic camera (``render_world_array``) is the image, ``WorldSetup.note`` says why;
  only a world that shows nothing (none, no World Output, nothing or a muted Background into it) gives a
  ``reason`` and no World term.
- ``bake_world(scene)`` bakes that image (``world_array``: scene-linear RGB, top row first) with
  ``core.environment.prefilter.bake_environment_image`` into a cache folder (``default_cache_dir``), named by its
  content hash, so a re-sync of an unchanged world only hashes it (after the render, for a rendered world) and reads
  the cached headers.
- ``sync_world(scene)`` (re)builds the shared group "RTL World": the 9 baked SH coefficients as
  static Combine XYZ values, and the Background strength and the Mapping rotation as Value /
  Combine XYZ nodes driven by simple-expression drivers (SINGLE_PROP on the World), so the strength
  and rotation stay live without a re-bake and evaluate without Python after a reload (a rendered world whose
  strength is not the Background's own value is baked with it, and its strength is 1).

Measured with bpy 5.0.1 (small Cycles renders; tests/blender/test_world_setup.py checks the rest):
- ``World.use_nodes`` is deprecated in 5.0 and setting it to False is ignored (the world always
  renders its nodes); it is checked only before 5.0.
- An unlinked Mapping Vector input is the constant (0, 0, 0), not the view direction: the world then
  shows one texel everywhere, so it is not read as an image (it is rendered, one colour).  A muted link counts
  as no link.
- ``Image.pixels`` of a float image are already scene linear (Blender converts on load, whatever
  the colour space), and Cycles renders the same values, with negative values shown as 0 and alpha
  ignored; those of an 8-bit image are the raw bytes / 255 (Cycles applies the colour space at
  render time): sRGB is decoded here, Non-Color and the working space pass through, other spaces
  are rendered by Cycles instead.
- Drivers inside a node group are evaluated only while something in the view layer uses the group
  (an RT Lit material on an object); then ``view_layer.update()`` writes the driven values back
  to the original nodes.
"""
from __future__ import annotations

import contextlib
import dataclasses
import os
import re
import tempfile
from dataclasses import dataclass
from pathlib import Path

import bpy
import numpy as np

from ..core.environment import equirect, prefilter
from ..core.ir.expr import FLOAT, VECTOR
from ..core.materials.rt_lit_interface import world_input
from ..core.materials.world_shading import SH_NAMES, WORLD_PARAMETERS, WorldEnvironment
from . import compat
from .common import (IMAGE_PREFIX, NODE_GROUP_PREFIX, WORLD_GROUP, WORLD_RECORD_KEY, add_driver, ensure_interface,
                     remove_drivers, socket_by_identifier)

RECORD_KEY = WORLD_RECORD_KEY
CACHE_ENV = "RTL_ENVIRONMENT_CACHE"
SH_COUNT = len(SH_NAMES)

#: Output sockets of "RTL World", in order: (name, kind, spec): the RT Lit material's world inputs, as
#: Vector sockets (the SH coefficients are RGB triples fed to vector inputs, converted exactly).
WORLD_OUTPUTS = tuple((world_input(name), FLOAT, sock) if sock.kind == "float" else
                      (world_input(name), VECTOR, dataclasses.replace(sock, kind="vector", default=(0.0, 0.0, 0.0)))
                      for name, sock in WORLD_PARAMETERS.items())

_MAPPING_TYPES = ("POINT", "VECTOR")
_IMAGE_SOURCES = ("FILE", "GENERATED")


# --- the world's setup -------------------------------------------------------------------------------

#: The panoramic render of a world that is neither an image nor a constant (``render_world_array``): width (the
#: height is half; the bake's largest source width, ``PrefilterSettings.max_source_width``) and samples per pixel
#: over a one-pixel box filter (each pixel the average of the world over its area, as the bake's area averaging
#: wants).
RENDER_WIDTH = 1024
RENDER_SAMPLES = 16


@dataclass
class WorldSetup:
    """What ``world_setup`` found: where the world's radiance comes from (``source``: "image", "constant",
    "render", or "" when the world shows nothing), the image (source "image"), the colour (source "constant"),
    the Background and Mapping nodes (None when absent), why a rendered world is rendered (``note``), and why the
    world is not usable ("" when it is)."""
    image: object = None
    background: object = None
    mapping: object = None
    reason: str = ""
    source: str = ""
    colour: tuple = None
    note: str = ""
    world: object = None

    @property
    def usable(self):
        return bool(self.source) and not self.reason

    @property
    def live_strength(self):
        """The Background's Strength socket when the bake leaves it out (a live, driven value), else None."""
        bg = self.background
        if bg is None or not self.usable or _link_into(bg.inputs["Strength"]) is not None:
            return None
        return bg.inputs["Strength"]

    @property
    def label(self):
        """What RT Lit shades, in a few words (the panel, the reports, the group's record)."""
        if self.source == "image":
            return self.image.name
        if self.source == "constant":
            return "plain colour (" + ", ".join(f"{c:.3g}" for c in self.colour) + ")"
        if self.source == "render":
            return f"World '{self.world.name}' rendered"
        return ""


def _link_into(socket):
    """The enabled link into an input socket, following reroutes; None when unlinked (a muted or
    invalid link counts as none, as in Blender's evaluation)."""
    seen = 0
    while True:
        links = [lk for lk in socket.links if lk.is_valid and not lk.is_muted] if socket.is_linked else []
        if not links:
            return None
        link = links[0]
        node = link.from_node
        if node.bl_idname != "NodeReroute" or seen > 64:
            return link
        seen += 1
        socket = node.inputs[0]


def _describe(node):
    return f"{node.bl_idname.removeprefix('ShaderNode')} '{node.name}'"


def _uses_nodes(world):
    return compat.uses_nodes(world)


def working_space():
    """The scene-linear working colour space of the file ("Linear Rec.709" before Blender 5.0)."""
    colorspace = getattr(bpy.data, "colorspace", None)
    return getattr(colorspace, "working_space", None) or "Linear Rec.709"


def _byte_decoding(image):
    """How the raw bytes of an 8-bit image become scene linear: "raw", "srgb", or None (unsupported)."""
    settings = image.colorspace_settings
    name = settings.name
    if settings.is_data or name in ("Non-Color", "scene_linear", working_space()):
        return "raw"
    if name == "sRGB" and working_space() == "Linear Rec.709":
        return "srgb"
    return None


def _image_reason(image):
    """Why ``image`` cannot be baked ("" when it can)."""
    if image.source not in _IMAGE_SOURCES:
        return f"the Environment Texture's image '{image.name}' is a {image.source.lower()} image (a single image is needed)"
    width, height = image.size
    if width <= 0 or height <= 0:
        return f"the Environment Texture's image '{image.name}' has no pixels (missing file?)"
    if not image.is_float and _byte_decoding(image) is None:
        return (f"the 8-bit image '{image.name}' is in colour space {image.colorspace_settings.name!r}: RT Lit reads "
                f"8-bit images in sRGB, Non-Color or {working_space()} (or use a float image)")
    return ""


def _mapping_reason(mapping):
    """Why a Mapping node in front of the Environment Texture is unsupported ("" when supported)."""
    what = f"unsupported Mapping node '{mapping.name}'"
    if mapping.mute:
        return f"{what}: it is muted"
    if mapping.vector_type not in _MAPPING_TYPES:
        return f"{what}: type {mapping.vector_type} (Point or Vector only)"
    checked = ("Rotation", "Scale") if mapping.vector_type == "VECTOR" else ("Location", "Rotation", "Scale")
    for name in checked:
        if _link_into(mapping.inputs[name]) is not None:
            return f"{what}: its {name} input is linked (rotation values only)"
    if mapping.vector_type == "POINT" and any(abs(v) > 1e-6 for v in mapping.inputs["Location"].default_value):
        return f"{what}: Location is not 0 (rotation only)"
    if any(abs(v - 1.0) > 1e-6 for v in mapping.inputs["Scale"].default_value):
        return f"{what}: Scale is not 1 (rotation only)"
    link = _link_into(mapping.inputs["Vector"])
    if link is None:
        return (f"{what}: its Vector input is unlinked, so the world shows one fixed direction "
                "(link Texture Coordinate > Generated into it)")
    reason = _coordinates_reason(link, "the Mapping node's Vector")
    return f"{what}: {reason}" if reason else ""


def _coordinates_reason(link, into):
    if link.from_node.bl_idname != "ShaderNodeTexCoord" or link.from_socket.identifier != "Generated":
        return f"{into} comes from {_describe(link.from_node)} > {link.from_socket.name}, not Texture Coordinate > Generated"
    if link.from_node.mute:
        return f"{into} comes from a muted Texture Coordinate node"
    return ""


def world_setup(world):
    """The ``WorldSetup`` of ``world`` (a bpy World or None): an image where the active World Output's Surface
    comes from a Background whose Color comes directly from an equirectangular Environment Texture with an image
    that has pixels, its Vector unlinked, Texture Coordinate > Generated, or a Mapping node (Point or Vector,
    rotation only) fed by Texture Coordinate > Generated; a constant where the Background's Color is unlinked (or
    the world has no nodes); a render for anything else that shows something."""
    if world is None:
        return WorldSetup(reason="the scene has no World")
    if not _uses_nodes(world) or world.node_tree is None:
        return WorldSetup(source="constant", colour=tuple(float(c) for c in world.color[:3]), world=world,
                          note=f"World '{world.name}' does not use nodes: its Color")
    tree = world.node_tree
    output = tree.get_output_node("CYCLES")
    if output is None:
        return WorldSetup(reason=f"World '{world.name}' has no active World Output node")
    link = _link_into(output.inputs["Surface"])
    if link is None:
        return WorldSetup(reason=f"the World Output of '{world.name}' has nothing linked to its Surface")
    background = link.from_node
    if background.bl_idname != "ShaderNodeBackground":
        return _rendered(world, None, f"the World Output's Surface comes from {_describe(background)}")
    if background.mute:
        return WorldSetup(background=background,
                          reason=f"the Background node '{background.name}' is muted (the world shows nothing)")
    if _link_into(background.inputs["Strength"]) is not None:
        return _rendered(world, background, "the Background node's Strength is linked")
    link = _link_into(background.inputs["Color"])
    if link is None:
        colour = tuple(float(c) for c in background.inputs["Color"].default_value[:3])
        return WorldSetup(source="constant", colour=colour, background=background, world=world)
    setup = _environment_image(background, link)
    if setup.reason:
        return _rendered(world, background, setup.reason)
    setup.source, setup.world = "image", world
    return setup


def _rendered(world, background, why):
    """A world drawn by Cycles (``render_world_array``); ``why`` it is not read as an image or a colour."""
    return WorldSetup(source="render", background=background, world=world, note=f"{why}: rendered by Cycles")


def _environment_image(background, link):
    """The ``WorldSetup`` of a Background whose Color comes through ``link``: its image, or why it is not one
    equirectangular image read as it is."""
    setup = WorldSetup(background=background)
    env = link.from_node
    if env.bl_idname != "ShaderNodeTexEnvironment":
        setup.reason = f"the Background's Color comes from {_describe(env)}, not an Environment Texture"
        return setup
    if link.from_socket.identifier != "Color":
        setup.reason = f"the Background's Color comes from the Environment Texture's {link.from_socket.name} output"
        return setup
    if env.mute:
        setup.reason = f"the Environment Texture '{env.name}' is muted"
        return setup
    if env.projection != "EQUIRECTANGULAR":
        setup.reason = f"the Environment Texture uses {env.projection.replace('_', ' ').lower()} projection"
        return setup
    if env.image is None:
        setup.reason = "the Environment Texture has no image"
        return setup
    link = _link_into(env.inputs["Vector"])
    if link is not None:
        if link.from_node.bl_idname == "ShaderNodeMapping":
            setup.mapping = link.from_node
            setup.reason = _mapping_reason(setup.mapping)
        else:
            setup.reason = _coordinates_reason(link, "the Environment Texture's Vector")
        if setup.reason:
            return setup
    setup.reason = _image_reason(env.image)
    if not setup.reason:
        setup.image = env.image
    return setup


# --- pixels and baking --------------------------------------------------------------------------------

def _srgb_to_linear(x):
    """The sRGB decoding (IEC 61966-2-1), equal to Blender's sRGB -> Linear Rec.709 to 4e-7."""
    return np.where(x <= 0.04045, x / 12.92, ((x + 0.055) / 1.055) ** 2.4).astype(np.float32)


def world_image_array(image):
    """(H, W, 3) float32 scene-linear RGB of ``image``, top scanline first (``equirect`` orientation);
    alpha dropped, non-finite and negative values set to 0 (Cycles shows negative radiance as 0)."""
    width, height = image.size
    channels = image.channels
    buf = np.empty(width * height * channels, dtype=np.float32)
    image.pixels.foreach_get(buf)
    pix = buf.reshape(height, width, channels)
    if channels >= 3:
        rgb = pix[::-1, :, :3]
    else:
        rgb = np.repeat(pix[::-1, :, :1], 3, axis=2)
    rgb = np.ascontiguousarray(rgb, dtype=np.float32)
    if not image.is_float and _byte_decoding(image) == "srgb":
        rgb = _srgb_to_linear(rgb)
    rgb = np.nan_to_num(rgb, nan=0.0, posinf=0.0, neginf=0.0)
    np.maximum(rgb, 0.0, out=rgb)
    return rgb


def world_array(setup):
    """(H, W, 3) float32 scene-linear RGB, top scanline first, of what a usable ``setup`` shows at strength 1
    where its strength is live (``WorldSetup.live_strength``): the image's pixels, the constant colour as one
    texel (the bake replicates it), or Cycles' render of the world."""
    if setup.source == "image":
        return world_image_array(setup.image)
    if setup.source == "constant":
        colour = np.nan_to_num(np.asarray(setup.colour, np.float32), nan=0.0, posinf=0.0, neginf=0.0)
        return np.maximum(colour, 0.0).reshape(1, 1, 3)
    if setup.source == "render":
        unit = setup.live_strength is not None
        return render_world_array(setup.world, setup.background.name if unit else None, RENDER_WIDTH, RENDER_SAMPLES)
    raise ValueError(f"the world is not usable: {setup.reason}")


#: The panoramic camera's rotation that gives Cycles' equirectangular render the Environment Texture's layout
#: (core/environment/equirect.py: row 0 at the zenith, u = 0.5 - atan2(y, x) / 2 pi): Euler XYZ (90, 0, -90) deg,
#: measured (a world showing its Generated direction: tests/blender/test_world_setup.py).
PANORAMA_ROTATION = (0.5 * np.pi, 0.0, -0.5 * np.pi)


#: The slot of "Render Result" that world renders go to (``render_world_array``): the user's renders stay in theirs.
RENDER_SLOT = "RT Lookdev world"


@contextlib.contextmanager
def _spare_render_slot():
    """Render into a slot of its own (made once, then reused; Blender's API adds slots but cannot remove them), so
    that the user's last render in "Render Result" is not overwritten; the active slot is restored afterwards."""
    result = bpy.data.images.get("Render Result")
    slots = getattr(result, "render_slots", None) if result is not None else None
    if not slots:
        yield
        return
    active = slots.active_index
    names = [slot.name for slot in slots]                # the collection has no lookup by name
    if RENDER_SLOT not in names:
        slots.new(name=RENDER_SLOT)
        names.append(RENDER_SLOT)
    slots.active_index = names.index(RENDER_SLOT)
    try:
        yield
    finally:
        slots.active_index = active


def render_world_array(world, unit_background=None, width=RENDER_WIDTH, samples=RENDER_SAMPLES):
    """Cycles' equirectangular render of ``world`` (``width`` x ``width / 2``, ``samples`` per pixel over a
    one-pixel box, no bounces: each pixel the world's mean over its area) as ``world_image_array`` returns
    an image, in a scene of its own that is removed afterwards.  ``unit_background``: the name of a Background
    node whose Strength is set to 1 in the copy rendered (its strength then stays a live value)."""
    copy = world.copy()
    scene = bpy.data.scenes.new("RTL world render")
    camera = bpy.data.cameras.new("RTL world render")
    obj = bpy.data.objects.new("RTL world render", camera)
    image = None
    try:
        if unit_background is not None:
            copy.node_tree.nodes[unit_background].inputs["Strength"].default_value = 1.0
        camera.type = "PANO"
        camera.panorama_type = "EQUIRECTANGULAR"
        obj.rotation_euler = PANORAMA_ROTATION
        scene.collection.objects.link(obj)
        scene.camera, scene.world = obj, copy
        render = scene.render
        render.engine = "CYCLES"
        render.resolution_x, render.resolution_y, render.resolution_percentage = width, width // 2, 100
        render.film_transparent = False
        cycles = scene.cycles
        cycles.device, cycles.samples, cycles.seed = "CPU", samples, 0
        cycles.use_adaptive_sampling = cycles.use_denoising = False
        cycles.max_bounces = 0
        cycles.pixel_filter_type, cycles.filter_width = "BOX", 1.0
        compat.set_exr_output(render.image_settings)
        with tempfile.TemporaryDirectory(prefix="rtl-world-") as folder, _spare_render_slot():
            render.filepath = str(Path(folder) / "world.exr")
            bpy.ops.render.render(write_still=True, scene=scene.name)
            image = bpy.data.images.load(render.filepath)
            image.reload()
            return world_image_array(image)
    finally:
        if image is not None:
            bpy.data.images.remove(image)
        bpy.data.scenes.remove(scene)
        bpy.data.objects.remove(obj)
        bpy.data.cameras.remove(camera)
        bpy.data.worlds.remove(copy)


def default_cache_dir():
    """The bake cache: the preference "Environment Cache" when set, else ``$RTL_ENVIRONMENT_CACHE``, else
    ``$XDG_CACHE_HOME/rt_lookdev/environments`` (``~/.cache`` when XDG_CACHE_HOME is unset); created here."""
    from . import preferences

    chosen = preferences.environment_cache_directory()
    env = os.environ.get(CACHE_ENV)
    if chosen is not None:
        path = chosen
    elif env:
        path = Path(env).expanduser()
    else:
        base = os.environ.get("XDG_CACHE_HOME")
        base = Path(base).expanduser() if base else Path.home() / ".cache"
        path = base / "rt_lookdev" / "environments"
    path.mkdir(parents=True, exist_ok=True)
    return path


def _file_stem(setup):
    if setup.source == "constant":
        return "plain"
    name = setup.image.name if setup.source == "image" else setup.world.name
    stem = Path(name).stem if "." in name and setup.source == "image" else name
    stem = re.sub(r"[^A-Za-z0-9_-]+", "_", stem).strip("_")[:48]
    return stem or "world"


def _source(setup):
    if setup.source == "constant":
        return "constant:" + ",".join(repr(float(c)) for c in setup.colour)
    if setup.source == "render":
        return f"render:{setup.world.name}"
    image = setup.image
    if image.packed_file is not None:
        return f"packed:{image.name}"
    if image.source == "GENERATED" or not image.filepath:
        return f"generated:{image.name}"
    return bpy.path.abspath(image.filepath, library=image.library)


@dataclass
class BakeJob:
    """The bake of a world as a function of ``progress(stage, done, total)`` alone, touching no ``bpy``, so it can
    run in a background thread (``background_task``): ``array`` is what the world shows (``world_array``, read or
    rendered on the calling thread), the rest where and how it is baked."""
    array: np.ndarray
    name: str
    source: str
    out_dir: Path
    settings: object
    force: bool = False

    def __call__(self, progress=None):
        return prefilter.bake_environment_image(self.array, self.name, self.source, self.out_dir, self.settings,
                                                progress, self.force)


def bake_job(scene, cache_dir=None, force=False, settings=None):
    """The ``BakeJob`` of ``scene``'s World (the image read, or the world rendered, here); None when the world
    shows nothing (``world_setup`` says why)."""
    setup = world_setup(scene.world)
    if not setup.usable:
        return None
    array = world_array(setup)
    out_dir = Path(cache_dir) if cache_dir is not None else default_cache_dir()
    return BakeJob(array, f"{_file_stem(setup)}_{equirect.image_hash(array)[:12]}", _source(setup), out_dir,
                   settings or prefilter.PrefilterSettings(), force)


def bake_world(scene, cache_dir=None, progress=None, force=False, settings=None):
    """Bake (or find cached) the environment of ``scene``'s World: an ``EnvironmentBake``, or None when
    the world shows nothing (``world_setup`` says why).  Files ``<image>_<hash12>_*`` in
    ``cache_dir`` (default ``default_cache_dir()``); ``progress(stage, done, total)`` as in core;
    ``settings``: ``PrefilterSettings`` (default: the measured defaults)."""
    job = bake_job(scene, cache_dir, force, settings)
    return job(progress) if job is not None else None


# --- the "RTL World" group ----------------------------------------------------------------------------

def remove_world_group():
    """Remove "RTL World" if present; True when one was removed."""
    ng = bpy.data.node_groups.get(WORLD_GROUP)
    if ng is None:
        return False
    bpy.data.node_groups.remove(ng)
    return True


def _input_path(node, socket):
    index = list(node.inputs).index(socket)
    return f'node_tree.nodes["{bpy.utils.escape_identifier(node.name)}"].inputs[{index}].default_value'


def _drive(socket, world, data_path):
    """A simple-expression driver on socket.default_value reading ``world``'s ``data_path``."""
    return add_driver(socket, world, ("data", data_path), "WORLD")


def sync_world(scene, cache_dir=None, progress=None, settings=None, bake=None):
    """(Re)build "RTL World" for ``scene``'s World and return its record ({"table", "prefiltered", "sh",
    "source_hash", "image" (``WorldSetup.label``), "source"}); when the world shows nothing, remove the group and
    return None.

    ``bake``: an ``EnvironmentBake`` of this world already made by ``bake_world`` (else it is made here
    with ``cache_dir``, ``progress``, ``settings``).  The group's interface is kept when unchanged, so
    RT Lit groups using it keep their links."""
    world = scene.world
    setup = world_setup(world)
    if not setup.usable:
        remove_world_group()
        return None
    if bake is None:
        bake = bake_world(scene, cache_dir, progress, settings=settings)
    ng = bpy.data.node_groups.get(WORLD_GROUP)
    if ng is None or ng.bl_idname != "ShaderNodeTree":
        ng = bpy.data.node_groups.new(WORLD_GROUP, "ShaderNodeTree")
    remove_drivers(ng)
    ng.nodes.clear()
    ng.description = ("The World's environment for RT Lit: baked SH coefficients and driven strength and rotation "
                      "(rebuilt by RT Lookdev > Sync World)")
    items = ensure_interface(ng, [(name, "OUTPUT", kind, spec) for name, kind, spec in WORLD_OUTPUTS])
    out = ng.nodes.new("NodeGroupOutput")
    out.location = (400.0, 0.0)

    def output(name):
        return socket_by_identifier(out.inputs, items[(name, "OUTPUT")].identifier)

    def combine(name, values, row):
        node = ng.nodes.new("ShaderNodeCombineXYZ")
        node.name = node.label = name
        node.location = (0.0, -row * 140.0)
        for sock, value in zip(node.inputs, values):
            sock.default_value = float(value)
        ng.links.new(node.outputs[0], output(world_input(name)))
        return node

    for i, name in enumerate(SH_NAMES):
        combine(name, bake.sh_image[i], i)

    strength_socket = setup.live_strength
    value = ng.nodes.new("ShaderNodeValue")
    value.name = value.label = "Strength"
    value.location = (0.0, -SH_COUNT * 140.0)
    value.outputs[0].default_value = 1.0 if strength_socket is None else float(strength_socket.default_value)
    if strength_socket is not None:
        _drive(value.outputs[0], world, _input_path(setup.background, strength_socket))
    ng.links.new(value.outputs[0], output(world_input("Strength")))

    mapping = setup.mapping
    rotation = combine("Rotation", _rotation(setup), SH_COUNT + 1)
    if mapping is not None:
        path = _input_path(mapping, mapping.inputs["Rotation"])
        for axis in range(3):
            _drive(rotation.inputs[axis], world, f"{path}[{axis}]")

    record = {"table": bake.table_name, "prefiltered": str(bake.prefiltered_path),
              "sh": str(bake.sh_path), "source_hash": bake.source_hash, "image": setup.label, "source": setup.source,
              "roughness_levels": _roughness_levels(bake)}
    ng[RECORD_KEY] = record
    return record


def world_synced():
    """Whether RT Lit has a World term (a synced world: "RTL World" with its record), without loading it."""
    ng = bpy.data.node_groups.get(WORLD_GROUP)
    return ng is not None and bool(ng.get(RECORD_KEY))


def world_environment():
    """(WorldEnvironment, record) of the synced world, or None when "RTL World" is absent.  The
    environment is read from the bake's cache file, or from the image packed in this .blend when the
    cache is gone (another machine, a cleaned cache)."""
    ng = bpy.data.node_groups.get(WORLD_GROUP)
    record = ng[RECORD_KEY].to_dict() if ng is not None and RECORD_KEY in ng.keys() else None
    if not record:
        return None
    try:
        env = WorldEnvironment.load(record["prefiltered"], record["table"])
    except Exception as exc:
        env = _packed_environment(record)
        if env is None:
            raise RuntimeError(f"the baked world environment {record['prefiltered']} cannot be read ({exc}) and "
                               "is not packed in this file; run RT Lookdev > Sync RT Lit World again") from exc
    return env, record


def _packed_environment(record):
    image = bpy.data.images.get(IMAGE_PREFIX + record["table"])
    levels = record.get("roughness_levels")
    if image is None or not levels:
        return None
    w, h = image.size
    if w * h == 0 or len(image.pixels) != w * h * 4:
        return None
    table = np.empty(w * h * 4, np.float32)
    image.pixels.foreach_get(table)               # bottom row first: the table's row order
    return WorldEnvironment(record["table"], table.reshape(h, w, 4), tuple(float(r) for r in levels))


def remove_stale_environment_images(keep=None):
    """Remove the node groups and packed prefiltered images of earlier bakes (named after a table
    ``env_*`` other than ``keep``) that nothing uses any more: the images carry a fake user, so they
    would otherwise stay in the .blend forever.
    Call it after the RT Lit groups were rebuilt (``materials.rebuild_rt_lit_groups``)."""
    removed = []
    # the groups of earlier bakes first ("RTL Shade World (...; env_<old>)" uses "RTL Environment
    # env_<old>", which uses the image): unused ones go, repeatedly, innermost last
    changed = True
    while changed:
        changed = False
        for ng in list(bpy.data.node_groups):
            name = ng.name
            if name.startswith(NODE_GROUP_PREFIX) and "env_" in name and not (keep and keep in name) and ng.users == 0:
                removed.append(name)
                bpy.data.node_groups.remove(ng)
                changed = True
    for image in list(bpy.data.images):
        if not image.name.startswith(IMAGE_PREFIX + "env_") or image.name == IMAGE_PREFIX + str(keep):
            continue
        if image.users - int(image.use_fake_user) == 0:
            removed.append(image.name)
            bpy.data.images.remove(image)
    return removed


def _roughness_levels(bake):
    """The roughness of each prefiltered level, from the file's metadata (recorded so the packed image
    alone can serve when the cache file is gone: addon/materials.py)."""
    import json

    from ..core.lut import exr_io

    _, meta = exr_io.read_table(bake.prefiltered_path)
    return [float(r) for r in json.loads(meta["roughness_levels"])]


def _rotation(setup):
    if setup.mapping is None:
        return (0.0, 0.0, 0.0)
    return tuple(float(v) for v in setup.mapping.inputs["Rotation"].default_value)


def world_parameters(scene, cache_dir=None, settings=None):
    """The values "RTL World" delivers, read from the current world (not from drivers): {"SH 0" ...
    "SH 8": (3,) arrays, "Strength": float, "Rotation": (3,) array}; None when the world is not usable.
    The SH coefficients are those of the synced group (its static values) when it exists, else the
    (cached) bake of the current image."""
    setup = world_setup(scene.world)
    if not setup.usable:
        return None
    ng = bpy.data.node_groups.get(WORLD_GROUP)
    if ng is not None and all(name in ng.nodes for name in SH_NAMES):
        sh = np.array([[float(s.default_value) for s in ng.nodes[name].inputs[:3]] for name in SH_NAMES])
    else:
        sh = bake_world(scene, cache_dir, settings=settings).sh_image
    params = {name: np.asarray(sh[i], dtype=np.float64) for i, name in enumerate(SH_NAMES)}
    strength = setup.live_strength
    params["Strength"] = 1.0 if strength is None else float(strength.default_value)
    params["Rotation"] = np.array(_rotation(setup), dtype=np.float64)
    return params


def bake_summary(bake):
    """One line: "baked in 3.2 s (sh baked, prefiltered baked)" / "cached (0.02 s)"."""
    states = bake.states
    seconds = bake.seconds.get("total", 0.0)
    if all(s == "cached" for s in states.values()):
        return f"cached ({seconds:.2f} s)"
    return f"baked in {seconds:.1f} s (" + ", ".join(f"{k} {v}" for k, v in states.items()) + ")"


__all__ = ["WORLD_GROUP", "WorldSetup", "BakeJob", "bake_job", "world_setup", "world_image_array", "world_array", "render_world_array",
           "default_cache_dir", "bake_world",
           "sync_world", "world_environment", "world_parameters", "remove_world_group", "bake_summary"]
