"""The RT Lit material as one core function: material inputs, every scene light and the world in,
radiance out.

``build_rt_lit(features, light_kinds, environment)`` traces the whole material for a feature set, the
scene's light kinds (in order) and its baked environment (or None) into one ``expr.Function`` with
named inputs and outputs (``rt_lit_interface``: material, geometry, "Light i <param>", "World <param>";
"Radiance" and its parts).  Every backend evaluates that function: the node backend emits it as the
"RT Lit (...)" group (the bpy layer only wires the Geometry node, the lights' and the world's driver
groups to its inputs), the numpy backend evaluates it for the validation and the tests
(``RtLitMaterial.evaluate``).

Structure (each box a node function, so a nested node group in Blender; core/ir/functions.py):

    RTL Surface                     material inputs + geometry -> N, V, F0, albedo, ... (the guards)
    per light:
      RTL <Kind> Light data         driver values -> world-space light geometry and colour (core/lights.py)
      RTL Shade <Kind> (features)   lobes of the enabled techniques, combined with colours (light_shading.py)
        RTL <Kind> <Lobe>           one lobe (lobes.py)
          RTL LTC ... Integral      (area lights) the LTC integral over the light
    RTL Shade World (features)      the World term (world_shading.py)

Light units (core/lights.py): area lights give emitted radiance, punctual lights irradiance at normal
incidence; lobes are per unit of either, cosine included.
"""
from __future__ import annotations

import functools
import hashlib
from dataclasses import dataclass

import numpy as np

from .. import lights
from ..ir.expr import FLOAT, VECTOR, define, folding, folding_enabled, table_filter_mode
from ..ir.functions import NodeFunction
from ..ir.interface import color
from ..ir.numpy_backend import evaluate, flat_node_count
from ..ir.tables import table_names
from ..lut.lookup import REFERENCES
from . import light_shading, world_shading
from .rt_lit_interface import (EMISSION_OUTPUT, GEOMETRY_INPUTS, LIGHT_KINDS, OCCLUSION_INPUT, OCCLUSION_SOCKET,
                               RADIANCE_OUTPUT, RT_LIT_INPUTS, RT_LIT_OUTPUTS, SURFACE_OUTPUTS, WORLD_OUTPUT, Features,
                               light_input, light_output, world_input)
from .surface import SURFACE


#: Extra output of the material function built with ``world_irradiance=True`` (not a part of the radiance): the
#: world's white-Lambert radiance E_SH(N) / pi x Strength, the denominator of the World term's ratio estimator
#: (addon/shadows.py, ``world=True``).
WORLD_IRRADIANCE_OUTPUT = "World Irradiance"


def light_parameters(kind):
    """The driver parameters of one light of ``kind`` ("Location X", ..., "Power", ...), in order."""
    return [n for n in lights.light_data(kind).input_sockets if n not in lights.SHADING_POINT_INPUTS]


def compose(tables, features, material, geometry, lights_in_scene, world=None, extras=None):
    """[the material's emission, radiance from light 0, from light 1, ..., (the world)]: the terms of
    the material's radiance (in nodes, one Emission closure each); the world's term comes last.

    ``material``: RT_LIT_INPUTS name -> value; ``geometry``: GEOMETRY_INPUTS name -> value;
    ``lights_in_scene``: [(kind, {parameter -> value})]; ``world``: None or (``WorldEnvironment``,
    {``WORLD_PARAMETERS`` name -> value}); with ``features.occlusion`` on, ``geometry`` also holds the
    renderer's ambient occlusion (``OCCLUSION_INPUT``).  Values are arrays (``tables`` holding data, the
    environment's table included) or Exprs (``tables`` = ``REFERENCES``).  ``extras``: None, or a dict that
    receives ``WORLD_IRRADIANCE_OUTPUT`` (the world's white-Lambert radiance, not a part of the sum) when there
    is a world."""
    surface = SURFACE(**{k: material[k] for k in RT_LIT_INPUTS},
                      **{k: geometry[k] for k in ("Geometry Normal", "Incoming")})
    parts = [surface["Emission"]]
    parts += _shade_lights(tables, features, surface, geometry["Position"], list(lights_in_scene))
    if world is not None:
        env, params = world
        parts.append(world_shading.shade_world(tables, features, env, surface, params, geometry.get(OCCLUSION_INPUT)))
        if extras is not None:
            extras[WORLD_IRRADIANCE_OUTPUT] = world_shading.world_irradiance(surface, params)
    return parts


def _shade_light(tables, features, surface, position, kind, params):
    """Radiance from one scene light of ``kind`` with driver ``params``: its data function, then its shading."""
    data_fn = lights.light_data(kind)
    args = dict(params)
    if "Position" in data_fn.input_sockets:
        args["Position"] = position
    return light_shading.shade_light(tables, kind, features, surface, position, data_fn(**args))


#: A scene with more lights than this shades them in blocks of this many, each block one nested function
#: ("RTL Lights", ``light_block``).  The values are the same (a block nests the same calls); the node trees are
#: not: Blender re-validates a whole tree at every node or link an add-on makes, so a flat tree builds in time
#: quadratic in its size (docs/blender.md, "Node groups"), and a 100-light RT Lit tree took 17 s per engine.
LIGHT_BLOCK = 8


def _shade_lights(tables, features, surface, position, lights_in_scene):
    """[radiance from each light] of ``lights_in_scene`` [(kind, params)], in blocks when there are many."""
    if len(lights_in_scene) <= LIGHT_BLOCK:
        return [_shade_light(tables, features, surface, position, kind, params) for kind, params in lights_in_scene]
    parts = []
    for start in range(0, len(lights_in_scene), LIGHT_BLOCK):
        block = lights_in_scene[start:start + LIGHT_BLOCK]
        fn = light_block(features, tuple(kind for kind, _ in block))
        args = {name: surface[name] for name in SURFACE_OUTPUTS}
        args["Position"] = position
        args.update({_block_input(j, param): value for j, (_, params) in enumerate(block) for param, value in params.items()})
        out = fn(tables, **args)
        parts += [out[_block_output(j)] for j in range(len(block))]
    return parts


def _block_input(j, param):
    return f"Light {j} {param}"


def _block_output(j):
    return f"Light {j}"


@functools.lru_cache(maxsize=None)
def light_block(features, kinds):
    """``RTL Lights <n> [<hash>]``: the radiance from ``kinds`` (consecutive scene lights) for ``features``: the
    surface's outputs, the shading point and each light's driver parameters in, "Light j" out.  Named by a hash of
    what it shades: blocks of the same kinds share one node group."""
    inputs = dict(SURFACE_OUTPUTS, Position=GEOMETRY_INPUTS["Position"])
    for j, kind in enumerate(kinds):
        inputs.update({_block_input(j, param): lights.light_data(kind).input_sockets[param]
                       for param in light_parameters(kind)})
    outputs = {_block_output(j): color((0.0, 0.0, 0.0), f"Radiance from light {j} of the block") for j in range(len(kinds))}

    def body(tables, **kw):
        surface = {name: kw[name] for name in SURFACE_OUTPUTS}
        return {_block_output(j): _shade_light(tables, features, surface, kw["Position"], kind,
                                               {param: kw[_block_input(j, param)] for param in light_parameters(kind)})
                for j, kind in enumerate(kinds)}

    digest = hashlib.sha1(repr((features, kinds)).encode()).hexdigest()[:8]
    return NodeFunction(f"RTL Lights {len(kinds)} [{digest}]", body, inputs, outputs,
                        f"Radiance from {len(kinds)} lights ({', '.join(kinds)}; {features.label()})", tables=REFERENCES)


def rt_lit_radiance(tables, features, material, geometry, lights_in_scene, world=None):
    """The material's total radiance towards the viewer (3-vector): the sum of ``compose``."""
    parts = compose(tables, features, material, geometry, lights_in_scene, world)
    total = parts[0]
    for part in parts[1:]:
        total = total + part
    return total


@dataclass(frozen=True, eq=False)
class RtLitMaterial:
    """The traced RT Lit material for one feature set, light list and environment.

    ``function``: the ``expr.Function``; its inputs are ``material_inputs`` (RT_LIT_INPUTS),
    ``geometry_inputs`` (GEOMETRY_INPUTS), ``light_inputs`` (per light: parameter -> input name) and
    ``world_inputs`` (world parameter -> input name) and ``occlusion_inputs`` (``OCCLUSION_INPUT`` when the
    World term is occluded, else none); its outputs ``RADIANCE_OUTPUT`` and the parts ``part_outputs``
    (emission, each light, the world) that sum to it."""
    features: Features
    light_kinds: tuple
    environment: object
    function: object
    material_inputs: tuple
    geometry_inputs: tuple
    light_inputs: tuple
    world_inputs: dict
    part_outputs: tuple
    occlusion_inputs: tuple = ()

    @property
    def name(self):
        return self.function.name

    @property
    def internal_inputs(self):
        """Inputs that a node tree feeds from inside (geometry, lights, world, occlusion), not from its interface."""
        names = list(self.geometry_inputs)
        for per_light in self.light_inputs:
            names += list(per_light.values())
        return names + list(self.world_inputs.values()) + list(self.occlusion_inputs)

    def table_names(self):
        return table_names(self.function.outputs)

    def tables(self, luts):
        """The table set to evaluate with: ``luts`` (a ``lookup.LutSet`` holding data) plus the
        environment's prefiltered table."""
        if self.environment is None:
            return luts
        return luts.with_tables(self.environment.as_table())

    def evaluate(self, values, luts, dtype=np.float32, outputs=(RADIANCE_OUTPUT,)):
        """{output name -> array}: the function evaluated by the numpy backend for ``values`` (input
        name -> array, broadcast), reading ``luts`` and the environment's table."""
        missing = [n for n, _ in self.function.inputs if n not in values]
        if missing:
            raise KeyError(f"{self.name}: no values for inputs {missing}")
        exprs = tuple(self.function.outputs[name] for name in outputs)
        result = evaluate(exprs, values, dtype, self.tables(luts))
        return dict(zip(outputs, result))


def _function_inputs(features, light_kinds, environment):
    """(input name -> kind, sockets, light inputs, world inputs, occlusion inputs) of the material function."""
    kinds, sockets = {}, {}
    for name, sock in {**RT_LIT_INPUTS, **GEOMETRY_INPUTS}.items():
        kinds[name] = FLOAT if sock.kind == "float" else VECTOR
        sockets[name] = sock
    per_light = []
    for index, kind in enumerate(light_kinds):
        try:
            lights.split_kind(kind)
        except ValueError as exc:
            raise ValueError(f"unknown light kind {kind!r}; RT Lit shades {LIGHT_KINDS} ({exc})") from None
        names = {}
        for param in light_parameters(kind):
            names[param] = light_input(index, param)
            kinds[names[param]] = FLOAT
            sockets[names[param]] = lights.light_data(kind).input_sockets[param]
        per_light.append(names)
    world = {}
    if environment is not None:
        for param, sock in world_shading.WORLD_PARAMETERS.items():
            world[param] = world_input(param)
            kinds[world[param]] = FLOAT if sock.kind == "float" else VECTOR
            sockets[world[param]] = sock
    occlusion = ()
    if environment is not None and features.occlusion != "none":     # only the World term is occluded
        occlusion = (OCCLUSION_INPUT,)
        kinds[OCCLUSION_INPUT], sockets[OCCLUSION_INPUT] = FLOAT, OCCLUSION_SOCKET
    return kinds, sockets, tuple(per_light), world, occlusion


def build_rt_lit(features=Features(), light_kinds=(), environment=None, world_irradiance=False):
    """The whole RT Lit material traced for ``features``, the light kinds in order and the world's
    ``WorldEnvironment`` (None: no World term, nothing of it built).  ``world_irradiance``: with a world, one more
    output ``WORLD_IRRADIANCE_OUTPUT`` (the World shadows' denominator).  Cached (per folding setting)."""
    return _build(features, tuple(light_kinds), environment, folding_enabled(), table_filter_mode(),
                  bool(world_irradiance and environment is not None))


def op_counts(features, light_kinds=(), environment=None):
    """IR operations of the material with every call expanded (what one flat tree would hold), as traced
    (constants folded, dead branches removed) and without folding: {"ir_ops_folded", "ir_ops_unfolded"}."""
    folded = flat_node_count(tuple(build_rt_lit(features, light_kinds, environment).function.outputs.values()))
    with folding(False):
        unfolded = flat_node_count(tuple(build_rt_lit(features, light_kinds, environment).function.outputs.values()))
    return {"ir_ops_folded": folded, "ir_ops_unfolded": unfolded}


@functools.lru_cache(maxsize=32)
def _build(features, light_kinds, environment, folded, table_filter, world_irradiance=False):
    kinds, sockets, per_light, world, occlusion = _function_inputs(features, light_kinds, environment)
    part_names = [EMISSION_OUTPUT] + [light_output(i) for i in range(len(light_kinds))]
    if environment is not None:
        part_names.append(WORLD_OUTPUT)

    def body(**kw):
        material = {k: kw[k] for k in RT_LIT_INPUTS}
        geometry = {k: kw[k] for k in (*GEOMETRY_INPUTS, *occlusion)}
        in_scene = [(kind, {p: kw[n] for p, n in names.items()}) for kind, names in zip(light_kinds, per_light)]
        world_in = (environment, {p: kw[n] for p, n in world.items()}) if environment is not None else None
        extras = {} if world_irradiance else None
        parts = compose(REFERENCES, features, material, geometry, in_scene, world_in, extras)
        total = parts[0]
        for part in parts[1:]:
            total = total + part
        return {RADIANCE_OUTPUT: total, **dict(zip(part_names, parts)), **(extras or {})}

    out_sockets = {RADIANCE_OUTPUT: RT_LIT_OUTPUTS[RADIANCE_OUTPUT]}
    out_sockets.update({n: color((0.0, 0.0, 0.0), f"{n} towards the viewer") for n in part_names})
    if world_irradiance:
        out_sockets[WORLD_IRRADIANCE_OUTPUT] = color((0.0, 0.0, 0.0), "The world's white-Lambert radiance (SH)")
    env_label = f"; {environment.name}" if environment is not None else ""
    name = f"RT Lit ({features.label()}; {len(light_kinds)} lights{env_label}{'; irradiance' if world_irradiance else ''})"
    function = define(name, body, kinds, f"RT Lit lookdev material ({features.label()})", (sockets, out_sockets))
    return RtLitMaterial(features, light_kinds, environment, function, tuple(RT_LIT_INPUTS), tuple(GEOMETRY_INPUTS),
                         per_light, world, tuple(part_names), occlusion)
