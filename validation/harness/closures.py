"""The Cycles closures that are the ground truth of an RT Lit technique (the validation suite's and the world
suite's (c), the speed-vs-error ladder's reference).  Like every module that builds Blender data, it imports
``bpy`` (and the addon modules that import it) inside its functions, so that numpy-only code can import it."""
from __future__ import annotations

import numpy as np

from ...core.materials.surface import dielectric_f0


def closure_material(variant, name):
    """A Cycles material of the closure that is ``variant``'s ground truth (``variant.technique`` and
    ``variant.material()``: the RT Lit inputs): Diffuse, Glossy, Metallic, Sheen, Principled or their mix."""
    from ...addon import compat    # bpy: imported when Blender is there, not when a module imports this one

    mat = compat.new_material(name)
    nt = mat.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    m = variant.material()
    t = variant.technique

    def glossy(dist):
        g = nt.nodes.new("ShaderNodeBsdfGlossy")
        g.distribution = dist
        g.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
        g.inputs["Roughness"].default_value = m["Roughness"]
        g.inputs["Anisotropy"].default_value = 0.0
        return g

    def metallic(f0, dist="GGX"):
        g = nt.nodes.new("ShaderNodeBsdfMetallic")
        g.distribution = dist
        g.fresnel_type = "F82"
        g.inputs["Base Color"].default_value = tuple(f0) + (1.0,)
        g.inputs["Edge Tint"].default_value = (1.0, 1.0, 1.0, 1.0)
        g.inputs["Roughness"].default_value = m["Roughness"]
        g.inputs["Anisotropy"].default_value = 0.0
        return g

    def diffuse(color):
        d = nt.nodes.new("ShaderNodeBsdfDiffuse")
        d.inputs["Color"].default_value = tuple(color) + (1.0,)
        d.inputs["Roughness"].default_value = 0.0
        return d

    if t == "lambert":
        shader = diffuse(m["Base Color"])
    elif t in ("oren_nayar", "cod_cycles"):
        shader = diffuse(m["Base Color"])
        shader.inputs["Roughness"].default_value = m["Diffuse Roughness"]
    elif t == "ggx":
        shader = glossy("GGX")
    elif t in ("turquin", "fdez_aguera", "kulla_conty_white"):
        shader = glossy("MULTI_GGX")
    elif t == "metal":
        shader = metallic(m["Base Color"])
    elif t == "zeltner":
        shader = nt.nodes.new("ShaderNodeBsdfSheen")
        shader.distribution = "MICROFIBER"
        shader.inputs["Color"].default_value = tuple(np.multiply(m["Sheen Tint"], m["Sheen Weight"])) + (1.0,)
        shader.inputs["Roughness"].default_value = m["Sheen Roughness"]
    elif t == "zeltner_principled":
        shader = nt.nodes.new("ShaderNodeBsdfPrincipled")
        values = {"Base Color": tuple(m["Base Color"]) + (1.0,), "Metallic": 0.0, "Specular IOR Level": 0.0,
                  "Sheen Weight": m["Sheen Weight"], "Sheen Roughness": m["Sheen Roughness"],
                  "Sheen Tint": tuple(m["Sheen Tint"]) + (1.0,), "Coat Weight": 0.0, "Transmission Weight": 0.0,
                  "Subsurface Weight": 0.0, "Diffuse Roughness": 0.0}
        for name, value in values.items():
            if name in shader.inputs:              # Diffuse Roughness: Blender 4.3+
                shader.inputs[name].default_value = value
    elif t == "dielectric" or t.startswith("mix_"):
        dist = "MULTI_GGX" if t.startswith("mix_") else "GGX"
        f0 = float(dielectric_f0(np.float64(m["IOR"]), np.float64(m["Specular IOR Level"])))
        add = nt.nodes.new("ShaderNodeAddShader")
        nt.links.new(metallic((f0, f0, f0), dist).outputs[0], add.inputs[0])
        nt.links.new(diffuse(m["Base Color"]).outputs[0], add.inputs[1])
        shader = add
        if t.startswith("mix_"):
            mix = nt.nodes.new("ShaderNodeMixShader")
            mix.inputs["Fac"].default_value = m["Metallic"]
            nt.links.new(add.outputs[0], mix.inputs[1])
            nt.links.new(metallic(m["Base Color"], dist).outputs[0], mix.inputs[2])
            shader = mix
    else:
        raise ValueError(f"{t} has no Cycles closure")
    nt.links.new(shader.outputs[0], out.inputs["Surface"])
    return mat
