"""Light shadows on RT Lit materials in Cycles renders: the ratio estimator of Heitz, Hill & McGuire 2018
("Combining Analytic Direct Illumination and Stochastic Shadows", I3D 2018).

RT Lit computes each light's radiance analytically and unshadowed ("Light i Radiance": core/materials/rt_lit.py).
The ratio estimator keeps that term and multiplies it by a stochastic visibility ratio: per light i,

    shadowed_i = analytic_i * S_i / U_i,

where S_i and U_i are Monte Carlo estimates of the light's direct illumination of a white diffuse surface with and
without shadows, computed with the same samples so that their noise cancels in the ratio (where nothing blocks the
light the ratio is 1 exactly) and, optionally, each denoised with the same filter (the paper's "denoise S and U, then
divide").  Here, in one F12 render (``bpy.ops.render.render``), measured by the spike of issue 29 (docs/shadows.md):

- the RT Lit Cycles tree writes each scene light's radiance to a Shader AOV "RTL Light <i>"
  (``common.light_aov_name``, emitted while the scene has shadows on: below); the beauty view layer (the user's)
  declares them;
- two probe view layers, "RTL Probe S" and "RTL Probe U", render every object with one material
  (``ViewLayer.material_override``: white diffuse for camera rays, black for the others, so the light-group passes
  hold direct light only); each holds one copy of every scene light, in its own collection: shadowed copies in
  light groups "s_<i>" (layer S), unshadowed ones (``Light.use_shadow = False``) in "u_<i>" (layer U).  The copies
  have their own light data (S's keeps the original's ``use_shadow``), whose size, cone, angle, spread, power and
  colour are driven from the original's (simple-expression drivers), and follow it with a Copy Transforms
  constraint.  Both layers hold the same lights in the same order and render with the scene's seed, so Cycles
  draws the same light samples in both (copies of a light in ONE layer are sampled independently: no
  cancellation).  Collections that hold only lights (the user's originals, the other layer's copies) are excluded
  from the probe layers, and the copies' collections from the user's layers (the copies light nothing there).
  Originals that share a collection with other objects stay in the probe layers: still correlated, but they take
  a share of the light samples (about twice the noise in the spike).  ``view_layer.samples`` of the probe layers
  (``samples``) is the knob between time and noise;
- the compositor computes ``final = beauty + sum_i AOV_i * (ratio_i - 1)`` with
  ``ratio_i = clamp((S_i + eps) / (U_i + eps), 0, 1)`` (``EPSILON``): where U_i is about 0 (the light below the
  horizon or outside its cone) the ratio falls back to 1, and a denoised S above U counts as unshadowed.

The World term (``world=True``, the default) takes the same idea with an analytic denominator: the scene's world
(``World.lightgroup`` = ``WORLD_LIGHT_GROUP``, declared in layer S only) lights the white probe, path traced, and the
RT Lit Cycles tree writes the World term's radiance ("RTL World") and the world's white-Lambert radiance as RT Lit
computes it, E_SH(N) / pi x Strength ("RTL World Irradiance": ``world_shading.world_irradiance``):

    final += AOV_world * (ratio_world - 1),  ratio_world = min((max(S_world, 0) + eps) / (max(E, 0) + eps), 4).

There is no U for the world (Cycles cannot light a probe by the world unoccluded), so the noise of S_world is not
cancelled (OIDN takes it) and the ratio is visibility times Cycles' irradiance over SH's: in Cycles, the world's light
on RT Lit surfaces is the path-traced irradiance (as an engine's ray-traced ambient occlusion and diffuse GI replace
its probe), no longer the L2 SH's, and its specular is scaled by the same (diffuse) ratio.  EEVEE and the shader
backend keep the SH and ``Features.occlusion``.  Measured in docs/shadows.md (the floor study, the spheres).

A scene that already has a compositor is refused (``ShadowError``): this module does not edit a graph it did not
make.  The AOV nodes are in the RT Lit Cycles trees only while shadows are on (the groups are rebuilt on enable and
disable): EEVEE compiles an AOV node's inputs whatever the Material Output's target (``materials.AOV_ENGINES``), so
while shadows are on, render with Cycles.  ``disable_shadows`` removes everything ``enable_shadows`` made; Sync
Lights rebuilds the copies (``light_sync.sync_lights`` calls ``refresh_shadows``).  Cycles only: EEVEE renders the probe layers but writes no
light-group passes (EEVEE's own Shadow pass is the way there, not built yet).
"""
from __future__ import annotations

from pathlib import Path

import bpy

from . import compat, materials, preferences, world_sync
from .common import SHADOW_COPY_KEY, SHADOWS_KEY, light_aov_name, node_groups_kept_on_error

#: The probe view layers: (role, view layer name, collection of the light copies, light-group prefix, shadowed).
PROBES = (("S", "RTL Probe S", "RTL Shadow Lights S", "s_", True),
          ("U", "RTL Probe U", "RTL Shadow Lights U", "u_", False))
#: The material every object has in the probe layers (``ViewLayer.material_override``).
PROBE_MATERIAL = "RTL Shadow Probe"
#: The compositor's node group (Blender 5) or the marker name of its nodes (4.5).
COMPOSITOR_NAME = "RTL Shadows"
#: Added to S and U before the division: the ratio is 1 where both are 0.
EPSILON = 1e-6
#: The World term's shadows (``world=True``): the world's light group in probe layer S, and the guards of the ratio
#: S_world / E: (max(S, 0) + eps) / (max(E, 0) + eps), at most WORLD_RATIO_MAX.  E (the AOV
#: ``materials.WORLD_AOVS["World Irradiance"]``) is RT Lit's own SH irradiance, not an estimate from the same samples
#: as S: the ratio carries SH's error as well as the visibility (above 1 where SH is too dark; module docstring).
WORLD_LIGHT_GROUP = "s_world"
WORLD_EPSILON = 1e-4
WORLD_RATIO_MAX = 4.0
#: Light data properties of the copies driven from the original's (those the light has).
DRIVEN_PROPERTIES = ("energy", "shadow_soft_size", "size", "size_y", "spot_size", "spot_blend", "angle", "spread")


class ShadowError(RuntimeError):
    """Shadows could not be enabled (nothing was changed); the message says why."""


def shadows_enabled(scene):
    """Whether ``enable_shadows`` set up ``scene`` (and ``disable_shadows`` has not undone it)."""
    return SHADOWS_KEY in scene


def shadow_settings(scene):
    """{"samples", "denoise", "beauty", "world"} of a scene with shadows on, or None."""
    stored = scene.get(SHADOWS_KEY)
    if stored is None:
        return None
    stored = stored.to_dict() if hasattr(stored, "to_dict") else dict(stored)
    return {"samples": int(stored["samples"]), "denoise": bool(stored["denoise"]), "beauty": str(stored["beauty"]),
            "world": bool(stored.get("world", False))}


def shadowed_lights(scene):
    """Indices of the scene lights whose RT Lit term is shadowed (those synced; none with shadows off)."""
    return [index for index, _ in _synced_lights(scene)] if shadows_enabled(scene) else []


def light_group_name(role, index):
    """The light group of scene light ``index``'s copy in probe layer ``role`` ("S" or "U"): "s_<i>" / "u_<i>"."""
    prefix = next(p for r, _, _, p, _ in PROBES if r == role)
    return f"{prefix}{index}"


def enable_shadows(scene, samples=4, denoise=True, view_layer=None, lut_dir=None, world=True):
    """Shadow RT Lit materials in ``scene``'s Cycles renders (Heitz et al. 2018's ratio estimator; module docstring).

    ``samples``: the probe layers' samples per pixel; ``denoise``: Open Image Denoise on each S and U pass;
    ``view_layer``: the name of the view layer whose render is shadowed (default: the first one that renders).
    The lights are those of the last light sync (``materials.synced_light_kinds``, the AOVs' indices).  ``world``:
    shadow the World term too (when the scene has a world and RT Lit a World term; its part of the module docstring): the Cycles trees then
    leave out ``Features.occlusion`` (the ratio is the world's occlusion there).  The RT Lit groups are rebuilt with
    the AOVs in their Cycles trees (``materials.AOV_ENGINES``; ``lut_dir``: the tables, default the preferences').
    Enabling again rebuilds everything (the same result).  Raises ``ShadowError`` (changing nothing) when the scene
    renders with another engine, has nothing to shadow (no synced light, and no world or ``world`` False), or has a
    compositor of its own."""
    _enable(scene, samples, denoise, view_layer, lut_dir, rebuild_groups=True, world=world)


def _enable(scene, samples, denoise, view_layer, lut_dir, rebuild_groups, world):
    settings = shadow_settings(scene)
    if scene.render.engine != "CYCLES":
        raise ShadowError(f"RT Lit shadows need Cycles (the scene renders with {scene.render.engine})")
    tree = compat.compositor_tree(scene)
    if tree is not None and not tree.get(SHADOWS_KEY):
        raise ShadowError("The scene has a compositor of its own; RT Lit shadows build theirs and do not edit another "
                          "one: remove it (or its nodes) first")
    requested, world = bool(world), bool(world) and scene.world is not None and world_sync.world_synced()
    lights = _synced_lights(scene, allow_none=world)
    beauty = _beauty_layer(scene, view_layer or (settings["beauty"] if settings is not None else None))
    use_compositing = bool(scene[SHADOWS_KEY]["use_compositing"]) if settings is not None \
        else bool(scene.render.use_compositing)
    if settings is not None:
        _remove_parts(scene)
    scene[SHADOWS_KEY] = {"samples": int(samples), "denoise": bool(denoise), "beauty": beauty.name,
                          "use_compositing": use_compositing, "aovs": [], "world": world, "world_requested": requested}
    if world:
        scene[SHADOWS_KEY]["world_lightgroup"] = str(scene.world.lightgroup)
    try:
        _build(scene, beauty, lights, int(samples), bool(denoise), world)
        if rebuild_groups:              # the AOVs in the RT Lit Cycles trees (kept when they are there)
            _rebuild_groups(scene, lut_dir)
    except BaseException:
        disable_shadows(scene, lut_dir)
        raise


def refresh_shadows(scene, lut_dir=None):
    """After a light sync (which built the RT Lit groups with the AOVs) or a world sync (before the groups are
    rebuilt): rebuild the light copies and the compositor for the synced lights and world when shadows are on;
    returns whether it did."""
    settings = shadow_settings(scene)
    if settings is None:
        return False
    requested = bool(scene[SHADOWS_KEY].get("world_requested", settings["world"]))
    _enable(scene, settings["samples"], settings["denoise"], settings["beauty"], lut_dir, rebuild_groups=False,
            world=requested)
    return True


def disable_shadows(scene, lut_dir=None):
    """Remove what ``enable_shadows`` made: the probe view layers, the light copies and their data, collections and
    light groups, the AOVs it declared, the probe material and the compositor, and the AOV nodes of the RT Lit
    Cycles trees (the groups rebuilt; ``lut_dir`` as ``enable_shadows``); the scene is as before."""
    if SHADOWS_KEY not in scene:
        return
    _remove_parts(scene)
    del scene[SHADOWS_KEY]
    material = bpy.data.materials.get(PROBE_MATERIAL)
    if material is not None and not any(shadows_enabled(other) for other in bpy.data.scenes):
        bpy.data.materials.remove(material)
    _rebuild_groups(scene, lut_dir)


def _rebuild_groups(scene, lut_dir):
    """Rebuild the RT Lit groups (all or nothing, as a light sync): with the lights' AOVs while ``scene`` has shadows
    on, without them after."""
    if not materials.has_rt_lit_groups():
        return
    lut_dir = Path(lut_dir) if lut_dir is not None else preferences.lut_directory()
    with node_groups_kept_on_error():
        materials.rebuild_rt_lit_groups(scene, lut_dir)


def _remove_parts(scene):
    """Remove the view layers, light copies, AOVs and compositor of ``enable_shadows`` (not the settings)."""
    stored = scene[SHADOWS_KEY]
    tree = compat.compositor_tree(scene)
    if tree is not None and tree.get(SHADOWS_KEY):
        del tree[SHADOWS_KEY]
        compat.remove_compositor(scene, tree)
    scene.render.use_compositing = bool(stored.get("use_compositing", True))
    if "world_lightgroup" in stored and scene.world is not None:
        scene.world.lightgroup = str(stored["world_lightgroup"])
    beauty = scene.view_layers.get(str(stored.get("beauty", "")))
    if beauty is not None:
        for name in list(stored.get("aovs", [])):
            aov = beauty.aovs.get(name)
            if aov is not None:
                beauty.aovs.remove(aov)
    for _, layer_name, collection_name, _, _ in PROBES:
        layer = scene.view_layers.get(layer_name)
        if layer is not None:
            scene.view_layers.remove(layer)
    copies = [obj for obj in bpy.data.objects if obj.get(SHADOW_COPY_KEY) == scene.name]
    data = [obj.data for obj in copies if obj.data is not None and SHADOW_COPY_KEY in obj.data]
    bpy.data.batch_remove(copies)
    bpy.data.batch_remove(data)
    bpy.data.batch_remove([c for c in bpy.data.collections if c.get(SHADOW_COPY_KEY) == scene.name])


# --- the parts ----------------------------------------------------------------------------------------------------

def _beauty_layer(scene, name):
    probes = {layer_name for _, layer_name, _, _, _ in PROBES}
    if name is not None:
        layer = scene.view_layers.get(name)
        if layer is None or layer.name in probes:
            raise ShadowError(f"The scene has no view layer {name!r} to shadow")
        return layer
    layer = next((vl for vl in scene.view_layers if vl.use and vl.name not in probes), None)
    if layer is None:
        raise ShadowError("The scene has no view layer that renders")
    return layer


def _synced_lights(scene, allow_none=False):
    """[(scene light index, object)] of the last light sync (the indices of the RT Lit trees' AOVs)."""
    out = []
    for index, (name, _) in enumerate(materials.synced_light_kinds()):
        obj = scene.objects.get(name)
        if obj is not None and obj.type == "LIGHT":
            out.append((index, obj))
    if not out and not allow_none:
        raise ShadowError("No light is synced with the RT Lit materials: run Sync Lights first")
    return out


def _build(scene, beauty, lights, samples, denoise, world):
    stored = scene[SHADOWS_KEY]
    names = [light_aov_name(index) for index, _ in lights] + (list(materials.WORLD_AOVS.values()) if world else [])
    added = [name for name in names if beauty.aovs.get(name) is None]
    for name in added:
        aov = beauty.aovs.add()
        aov.name = name
        aov.type = "COLOR"
    stored["aovs"] = added
    material = _probe_material()
    collections = {}
    for role, _, collection_name, _, shadowed in PROBES:
        collection = bpy.data.collections.new(collection_name)
        collection[SHADOW_COPY_KEY] = scene.name
        scene.collection.children.link(collection)
        collections[role] = collection
        for index, original in lights:
            _light_copy(scene, original, collection, light_group_name(role, index), shadowed)
    ours = {c.name for c in collections.values()}
    for layer in scene.view_layers:             # the copies light nothing in the user's layers
        for child in _layer_collections(_root_collection(layer)):
            if child.name in ours:
                child.exclude = True
    layers = {}
    for role, layer_name, _, _, _ in PROBES:
        layer = scene.view_layers.new(layer_name)
        layers[role] = layer
        layer.samples = samples
        layer.material_override = material
        layer.cycles.use_denoising = False
        excluded = _excluded_names(beauty)
        for child in _layer_collections(_root_collection(layer)):
            name = child.name
            if name in ours:
                child.exclude = name != collections[role].name
            elif name in excluded or _only_lights(child.collection):
                child.exclude = True
        for index, _ in lights:
            layer.lightgroups.add(name=light_group_name(role, index))
        if world and role == "S":
            layer.lightgroups.add(name=WORLD_LIGHT_GROUP)
    if world:
        scene.world.lightgroup = WORLD_LIGHT_GROUP
    scene.render.use_compositing = True
    scene.render.use_single_layer = False
    _build_compositor(scene, beauty, layers, [index for index, _ in lights], denoise, world)


def _root_collection(layer):
    """The scene collection's layer collection of view ``layer``.  A view layer of a scene made in this session
    (``bpy.data.scenes.new``) has none until it is synced (``ViewLayer.update``; measured with 5.2.3)."""
    if layer.layer_collection is None:
        layer.update()
    return layer.layer_collection


def _layer_collections(layer_collection):
    """Every layer collection under ``layer_collection`` (depth first; not the scene collection itself)."""
    for child in layer_collection.children:
        yield child
        yield from _layer_collections(child)


def _excluded_names(layer):
    return {child.name for child in _layer_collections(_root_collection(layer)) if child.exclude}


def _only_lights(collection):
    """Whether ``collection`` holds objects, all of them lights (the user's light collections)."""
    objects = collection.all_objects
    return len(objects) > 0 and all(obj.type == "LIGHT" for obj in objects)


def _probe_material():
    """White diffuse for camera rays, no closure (black, opaque) for the others: the probe layers' light-group
    passes then hold the direct light alone, which is what the ratio estimator's S and U are."""
    material = bpy.data.materials.get(PROBE_MATERIAL)
    if material is not None:
        return material
    material = compat.new_material(PROBE_MATERIAL)
    nodes, links = material.node_tree.nodes, material.node_tree.links
    nodes.clear()
    output = nodes.new("ShaderNodeOutputMaterial")
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    path = nodes.new("ShaderNodeLightPath")
    mix = nodes.new("ShaderNodeMixShader")
    links.new(path.outputs["Is Camera Ray"], mix.inputs["Fac"])
    links.new(diffuse.outputs[0], mix.inputs[2])
    links.new(mix.outputs[0], output.inputs["Surface"])
    path.location, diffuse.location, mix.location = (-400.0, 200.0), (-400.0, -100.0), (-150.0, 0.0)
    return material


def _light_copy(scene, original, collection, group, shadowed):
    """A copy of the light ``original`` in ``collection`` and light group ``group``: its own light data (a copy,
    shadows off unless ``shadowed``), driven from the original's, and a Copy Transforms constraint on it."""
    data = original.data.copy()
    data.name = f"{original.data.name} ({group})"
    data[SHADOW_COPY_KEY] = scene.name
    data.use_shadow = bool(original.data.use_shadow) if shadowed else False
    if data.animation_data is not None:
        data.animation_data_clear()
    for prop in DRIVEN_PROPERTIES:
        if hasattr(data, prop):
            _drive(data, prop, original.data, prop)
    for i in range(3):
        _drive(data, "color", original.data, f"color[{i}]", i)
    obj = bpy.data.objects.new(f"{original.name} ({group})", data)
    obj[SHADOW_COPY_KEY] = scene.name
    obj.lightgroup = group
    obj.matrix_world = original.matrix_world
    constraint = obj.constraints.new("COPY_TRANSFORMS")
    constraint.target = original
    linking = original.light_linking
    obj.light_linking.receiver_collection = linking.receiver_collection
    obj.light_linking.blocker_collection = linking.blocker_collection
    collection.objects.link(obj)
    return obj


def _drive(data, prop, source, path, index=-1):
    """A simple-expression driver ``var`` on ``data.<prop>[index]`` reading ``source``'s ``path`` (runs without
    Python, so after a reload with auto-run off too)."""
    fc = data.driver_add(prop, index) if index >= 0 else data.driver_add(prop)
    driver = fc.driver
    driver.type = "SCRIPTED"
    driver.expression = "var"
    var = driver.variables.new()
    var.name = "var"
    var.type = "SINGLE_PROP"
    var.targets[0].id_type = "LIGHT"
    var.targets[0].id = source
    var.targets[0].data_path = path


def _build_compositor(scene, beauty, layers, indices, denoise, world):
    """final = beauty + sum_i AOV_i * (clamp((S_i + eps) / (U_i + eps), 0, 1) - 1) (+ the World term's
    AOV_world * (ratio_world - 1) with ``world``), each S_i, U_i (S_world) denoised when ``denoise``; written as
    beauty - AOV + AOV * ratio, so the result keeps the beauty's alpha."""
    tree, result = compat.new_compositor(scene, COMPOSITOR_NAME)
    tree[SHADOWS_KEY] = True
    render = {}
    for row, (role, layer) in enumerate([("beauty", beauty), *layers.items()]):
        node = tree.nodes.new("CompositorNodeRLayers")
        node.scene = scene
        node.layer = layer.name
        node.location = (-900.0, -row * 400.0)
        render[role] = node
    image = render["beauty"].outputs["Image"]
    for index in indices:
        parts = {}
        for role in ("S", "U"):
            socket = render[role].outputs[f"Combined_{light_group_name(role, index)}"]
            if denoise:
                socket = compat.new_denoise(tree, socket)
            parts[role] = compat.mix_colors(tree, socket, (EPSILON,) * 3, "ADD")
        ratio = compat.mix_colors(tree, parts["S"], parts["U"], "DIVIDE", clamp=True)
        aov = render["beauty"].outputs[light_aov_name(index)]
        image = compat.mix_colors(tree, image, aov, "SUBTRACT")
        image = compat.mix_colors(tree, image, compat.mix_colors(tree, aov, ratio, "MULTIPLY"), "ADD")
    if world:       # the World term: AOV_world * (S_world / E - 1), guarded (WORLD_EPSILON, WORLD_RATIO_MAX)
        socket = render["S"].outputs[f"Combined_{WORLD_LIGHT_GROUP}"]
        if denoise:
            socket = compat.new_denoise(tree, socket)
        s_world = compat.mix_colors(tree, compat.mix_colors(tree, socket, (0.0,) * 3, "LIGHTEN"),
                                    (WORLD_EPSILON,) * 3, "ADD")
        irradiance = render["beauty"].outputs[materials.WORLD_AOVS["World Irradiance"]]
        e_world = compat.mix_colors(tree, compat.mix_colors(tree, irradiance, (0.0,) * 3, "LIGHTEN"),
                                    (WORLD_EPSILON,) * 3, "ADD")
        ratio = compat.mix_colors(tree, compat.mix_colors(tree, s_world, e_world, "DIVIDE"),
                                  (WORLD_RATIO_MAX,) * 3, "DARKEN")
        aov = render["beauty"].outputs[materials.WORLD_AOVS["World Radiance"]]
        image = compat.mix_colors(tree, image, aov, "SUBTRACT")
        image = compat.mix_colors(tree, image, compat.mix_colors(tree, aov, ratio, "MULTIPLY"), "ADD")
    tree.links.new(image, result)
    return tree
