"""The worlds of nodes of the world validation (``scripts/validate_world.py --node-world``, issue 33): worlds that
RT Lit bakes as a constant or from Cycles' render of them, not from an image.  Each builder fills a new world's
tree in front of its Background node."""
from __future__ import annotations


def _plain_world(nt, background):
    """A plain colour (every new Blender file's world, brighter and tinted): RT Lit bakes it as a constant."""
    background.inputs["Color"].default_value = (0.6, 0.7, 0.9, 1.0)


def _sky_world(nt, background):
    """Blender's Sky Texture with its defaults (its sun disk included): RT Lit bakes Cycles' render of it."""
    sky = nt.nodes.new("ShaderNodeTexSky")
    nt.links.new(sky.outputs["Color"], background.inputs["Color"])


def _sky_dome_world(nt, background):
    """The Sky Texture without its sun disk (the sky's own light)."""
    _sky_world(nt, background)
    nt.nodes["Sky Texture"].sun_disc = False


def _mix_world(nt, background):
    """A ground-to-sky gradient: Mix of two colours by the Generated direction's height (Separate XYZ, Map Range):
    RT Lit bakes Cycles' render of it."""
    coords = nt.nodes.new("ShaderNodeTexCoord")
    split = nt.nodes.new("ShaderNodeSeparateXYZ")
    ramp = nt.nodes.new("ShaderNodeMapRange")
    ramp.inputs["From Min"].default_value = -0.2
    ramp.inputs["From Max"].default_value = 0.6
    mix = nt.nodes.new("ShaderNodeMix")
    mix.data_type = "RGBA"
    mix.inputs["A"].default_value = (0.25, 0.18, 0.1, 1.0)
    mix.inputs["B"].default_value = (0.4, 0.6, 1.0, 1.0)
    nt.links.new(coords.outputs["Generated"], split.inputs[0])
    nt.links.new(split.outputs["Z"], ramp.inputs["Value"])
    nt.links.new(ramp.outputs["Result"], mix.inputs["Factor"])
    nt.links.new(mix.outputs["Result"], background.inputs["Color"])


#: The worlds of nodes the world validation runs beside the HDRIs (``--node-world``, issue 33): kind -> (builder
#: of the Background's input, description).
NODE_WORLDS = {"plain": (_plain_world, "plain colour (0.6, 0.7, 0.9)"),
               "sky": (_sky_world, "Sky Texture (defaults)"),
               "sky_dome": (_sky_dome_world, "Sky Texture without its sun disk"),
               "mix": (_mix_world, "Mix of two colours by height")}
