"""What differs between the Blender releases RT Lookdev supports, in one place.

Each difference is named with the release where it changed (checked with the bpy wheels of each
release, tests run by ``bash scripts/test.sh --matrix``):

- 5.0: materials, worlds and lights always render their node tree; ``use_nodes`` is deprecated (setting it
  False is ignored: measured for a light with bpy 5.2.3, whose Emission strength 0.25 applied with
  ``use_nodes`` off, while 4.5.15 then renders the light without its tree).  Before 5.0 a new material or world has no node tree until ``use_nodes = True``, which
  creates the default one (Principled BSDF + Material Output; Background + World Output).
- 5.0: the EEVEE render engine is ``BLENDER_EEVEE`` again; 4.2 to 4.5 call it ``BLENDER_EEVEE_NEXT``.
- 5.0: the Math node's Power of a zero base with a negative exponent gives 0 (core/ir/semantics.py's rule);
  4.5 gives +inf (``POWER_OF_ZERO_IS_ZERO``).  The shading code never feeds Power a base that can be 0
  (tests/core/test_ir.py checks every traced Power node has a positive constant base), so no pixel
  differs between the releases.
- 5.0: Blender's sRGB -> scene linear decoding (OpenColorIO) is the IEC 61966-2-1 formula to 4e-7;
  in 4.5 it departs from it by up to 7.2e-6 (measured with the 4.5.15 wheel: ``SRGB_DECODING_ERROR``).
  ``world_sync`` decodes 8-bit world images with the formula in every release.
- 5.0: image output settings have a ``media_type`` ("IMAGE", "MULTI_LAYER_IMAGE") beside ``file_format``;
  before 5.0 the file format alone says it ("OPEN_EXR", "OPEN_EXR_MULTILAYER").
- 5.0: the compositor is a node group (``scene.compositing_node_group``, a "CompositorNodeTree" whose Group Output
  "Image" is the result) instead of the scene's embedded ``scene.node_tree`` switched on by ``scene.use_nodes``
  with a Composite node; the Mix RGB compositor node is gone (the shader Mix node, data type RGBA, serves), and
  the Denoise node's options became input sockets ("HDR").  Measured with the 4.5.15 and 5.2.3 wheels
  (addon/shadows.py, tests/blender/test_shadows.py): ``compositor_tree``, ``new_compositor``,
  ``remove_compositor``, ``mix_colors``, ``new_denoise``.

Renders of the same RT Lit scene (all five light kinds and a studio HDRI world) agree between releases
to the float32 level, measured 2026-12-01: 5.3.0 equals 5.2.3 bit for bit; 4.5.15 differs from 5.2.3 by
a median 7.8e-6 and at most 1.9e-4 relative, following its Position pass, which differs by up to 2.4e-7
(the numpy evaluation at each release's own passes matches that release's render to 1e-4: the matrix).
Python 3.11 (4.5) and 3.13 (5.2, 5.3) need no difference here: the LUT inputs hash reads code the same
way in both (``core.lut.catalog.code_text``), and numpy 1 (4.5) and 2 (5.2, 5.3) compute the float32 path
in float32 alike (``core.ir.semantics.float_dtype``).

Everything here is small and side-effect free apart from what its name says; other modules call these
instead of testing ``bpy.app.version`` themselves.
"""
from __future__ import annotations

import bpy

#: The oldest release this add-on is tested with (the manifest's ``blender_version_min``).
MINIMUM_VERSION = (4, 5, 0)

#: 5.0 made node trees of materials and worlds permanent and deprecated ``use_nodes``.
PERMANENT_NODE_TREES = (5, 0, 0)
#: 5.0 renamed EEVEE back from "EEVEE Next".
_EEVEE_RENAMED = (5, 0, 0)
#: 5.0 made the compositor a node group of its own (``scene.compositing_node_group``).
COMPOSITOR_NODE_GROUPS = (5, 0, 0)


#: Before 5.0 the bpy *module* (``import bpy`` in CPython, not the Blender program) hangs for ever at process exit
#: while any class or menu entry is still registered: its static destructor destroys the condition variable its
#: audio device's delayed-close thread waits on (measured with 4.5.15: one registered operator is enough;
#: 5.2 exits).  Unregistering first avoids it.
_MODULE_EXIT_HANG_FIXED = (5, 0, 0)


def srgb_decoding_error(release=None):
    """How far this release's sRGB decoding departs from IEC 61966-2-1 at most (measured)."""
    return 4e-7 if tuple(release or version()) >= (5, 0, 0) else 7.2e-6


def power_of_zero_is_zero(release=None):
    """Whether Power(0, negative) is 0 in this release's Cycles (5.0 and later), not +inf."""
    return tuple(release or version()) >= (5, 0, 0)


def version():
    return tuple(bpy.app.version)


def module_exit_hangs_while_registered():
    """True in a bpy module of a release whose process hangs at exit with classes still registered."""
    return bpy.app.binary_path == "" and version() < _MODULE_EXIT_HANG_FIXED


def supported(release=None):
    """True when ``release`` (default: the running Blender) is one this add-on supports."""
    return tuple(release or version()) >= MINIMUM_VERSION


def unsupported_message(release=None):
    release = tuple(release or version())
    have = ".".join(map(str, release))
    need = ".".join(map(str, MINIMUM_VERSION))
    return f"RT Lookdev needs Blender {need} or newer (tested with 4.5 LTS, 5.2 LTS and 5.3); this is {have}"


def ensure_node_tree(id_block):
    """The node tree of a material, world or light, created and switched on (``use_nodes = True``) where the
    release needs it."""
    if version() < PERMANENT_NODE_TREES and (id_block.node_tree is None or not id_block.use_nodes):
        id_block.use_nodes = True
    return id_block.node_tree


def new_material(name):
    """A new material with its default node tree (Principled BSDF -> Material Output)."""
    material = bpy.data.materials.new(name)
    ensure_node_tree(material)
    return material


def new_world(name):
    """A new world with its default node tree (Background -> World Output)."""
    world = bpy.data.worlds.new(name)
    ensure_node_tree(world)
    return world


def uses_nodes(id_block):
    """Whether a material, world or light renders its node tree (always from 5.0, when it has one)."""
    if version() >= PERMANENT_NODE_TREES:
        return id_block.node_tree is not None
    return bool(id_block.use_nodes) and id_block.node_tree is not None


def set_exr_output(image_settings, multilayer=False):
    """32-bit float OpenEXR output (one layer, or every pass of a multilayer file)."""
    if hasattr(image_settings, "media_type"):
        image_settings.media_type = "MULTI_LAYER_IMAGE" if multilayer else "IMAGE"
    image_settings.file_format = "OPEN_EXR_MULTILAYER" if multilayer else "OPEN_EXR"
    image_settings.color_depth = "32"


def eevee_engine():
    """The ``scene.render.engine`` identifier of EEVEE in this release."""
    return "BLENDER_EEVEE" if version() >= _EEVEE_RENAMED else "BLENDER_EEVEE_NEXT"


def compositor_tree(scene):
    """The scene's compositor node tree, or None: the node group (5.0 on) or the embedded tree (before), the latter
    only when it has nodes or is switched on."""
    if version() >= COMPOSITOR_NODE_GROUPS:
        return scene.compositing_node_group
    tree = scene.node_tree
    if tree is None or (not scene.use_nodes and not len(tree.nodes)):
        return None
    return tree


def new_compositor(scene, name):
    """An empty compositor for ``scene``, made the one it uses: (tree, the input socket of the final image).
    5.0 on: a new node group ``name`` with a Group Output "Image"; before: the scene's embedded tree, switched on,
    emptied, with a Composite node."""
    if version() >= COMPOSITOR_NODE_GROUPS:
        tree = bpy.data.node_groups.new(name, "CompositorNodeTree")
        tree.interface.new_socket("Image", in_out="OUTPUT", socket_type="NodeSocketColor")
        scene.compositing_node_group = tree     # Render Layers nodes can only be added after this
        output = tree.nodes.new("NodeGroupOutput")
        return tree, output.inputs[0]
    scene.use_nodes = True
    tree = scene.node_tree
    tree.nodes.clear()
    output = tree.nodes.new("CompositorNodeComposite")
    return tree, output.inputs["Image"]


def remove_compositor(scene, tree):
    """Undo ``new_compositor``: the node group removed (5.0 on), or the embedded tree emptied and switched off."""
    if version() >= COMPOSITOR_NODE_GROUPS:
        if scene.compositing_node_group == tree:
            scene.compositing_node_group = None
        bpy.data.node_groups.remove(tree)
        return
    tree.nodes.clear()
    scene.use_nodes = False


def mix_colors(tree, a, b, blend, clamp=False):
    """A compositor node computing ``a <blend> b`` per channel (blend "ADD", "SUBTRACT", "MULTIPLY", "DIVIDE"),
    clamped to [0, 1] when ``clamp``; ``a`` is a socket, ``b`` a socket or a constant (r, g, b).  Returns the output
    socket.  The result's alpha is ``a``'s."""
    if version() >= COMPOSITOR_NODE_GROUPS:
        node = tree.nodes.new("ShaderNodeMix")
        node.data_type = "RGBA"
        node.blend_type = blend
        node.clamp_result = clamp
        node.clamp_factor = True
        first, second, out = node.inputs[6], node.inputs[7], node.outputs[2]   # A, B (colour), Result (colour)
    else:
        node = tree.nodes.new("CompositorNodeMixRGB")
        node.blend_type = blend
        node.use_clamp = clamp
        first, second, out = node.inputs[1], node.inputs[2], node.outputs[0]
    node.inputs[0].default_value = 1.0                                        # Factor
    tree.links.new(a, first)
    if isinstance(b, tuple):
        second.default_value = (*b, 1.0)
    else:
        tree.links.new(b, second)
    return out


def new_denoise(tree, image):
    """An Open Image Denoise node (HDR input, no albedo or normal) on ``image``; returns its output socket."""
    node = tree.nodes.new("CompositorNodeDenoise")
    if "HDR" in node.inputs:
        node.inputs["HDR"].default_value = True
    else:
        node.use_hdr = True
    tree.links.new(image, node.inputs["Image"])
    return node.outputs["Image"]
