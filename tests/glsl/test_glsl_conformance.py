"""The shader-text backend run on a GPU API: every IR operation, every technique, every table channel and
the RT Lit functions up to the whole material, emitted as GLSL 4.50, evaluated per texel on a headless
OpenGL context (Mesa's llvmpipe here), equal the numpy backend in float32: <= 1e-5 relative, <= 1e-7
absolute where |numpy| < 1e-2, and finite everywhere.  Where a function amplifies float32 rounding itself
(numpy's float32 evaluation is off its float64 evaluation by a tenth of the tolerance or more), GLSL must be
no farther from float64 than twice numpy's float32 (validation.harness.glsl_runner.Conformance)."""
from __future__ import annotations

import numpy as np
import pytest

from rt_lookdev.core.ir import trace
from rt_lookdev.validation.harness.glsl_runner import ATOL, RTOL, compare_function
from rt_lookdev.validation.harness import grids

pytestmark = pytest.mark.glsl

SIZE = 64


def _assert_conforms(name, report):
    for output, c in report.items():
        print(f"{name} / {output}: {c.summary()}")
        assert c.finite, f"{name} / {output}: NaN or Inf in the GLSL result"
        assert c.ok, f"{name} / {output}: {c.summary()} (tolerance {RTOL:g} relative, {ATOL:g} absolute)"


def _function(name, outputs, inputs):
    from rt_lookdev.core.ir.expr import Function

    return Function(name, inputs, outputs)


def test_every_ir_operation_computes_like_numpy(gl):
    outputs = grids.ir_operation_graph()
    vals = grids.ir_operation_inputs(SIZE)
    fn = _function("RTL IR Operations", outputs, {"a": "float", "b": "float", "u": "vector", "v": "vector"})
    _assert_conforms("ir", compare_function(fn, vals, runner=gl))


@pytest.mark.parametrize("name", sorted(grids.TECHNIQUES))
def test_technique_computes_like_numpy(gl, name):
    fn, names = grids.TECHNIQUES[name]
    _, out = trace(fn, dict.fromkeys(names, "float"))
    vals = {k: v.astype(np.float32).reshape(SIZE, SIZE) for k, v in grids.technique_inputs(names, n=SIZE * SIZE).items()}
    _assert_conforms(name, compare_function(_function(f"RTL {name}", {"out": out}, dict.fromkeys(names, "float")),
                                            vals, runner=gl))


def test_table_reads_every_channel(gl, tables):
    """Closest fetches, Linear (``lut``) and the bilinear node function, in every channel, inside and
    outside the texel-centre range and at the edges."""
    from rt_lookdev.core import shading_ops as op

    lut = tables["ltc_ggx_inv"]

    def lookups(u, v):
        g = u.graph
        raw = {f"{kind}{c}": g.read_table(lut, u, v, c, op=kind) for kind in ("lut", "texel") for c in range(4)}
        raw.update({f"bilinear{c}": op.lut_sample(lut, u, v, c) for c in range(4)})
        return raw

    _, outs = trace(lookups, {"u": "float", "v": "float"})
    rng = np.random.default_rng(11)
    vals = {n: rng.uniform(-0.05, 1.05, (SIZE, SIZE)).astype(np.float32) for n in ("u", "v")}
    vals["u"][0, :6] = [0.5 / 64, 63.5 / 64, 0.0, 1.0, -1.0, 2.0]
    vals["v"][0, :6] = [0.5 / 64, 63.5 / 64, 1.0, 0.0, 2.0, -1.0]
    fn = _function("RTL Table Reads", outs, {"u": "float", "v": "float"})
    _assert_conforms("tables", compare_function(fn, vals, tables, runner=gl))


def test_library_functions_compute_like_numpy(gl, tables):
    """Every node group offered to artists (node_groups/library.py): surface, techniques, lobes for every
    light kind, LTC integrals, light conversions."""
    from rt_lookdev.core import lights
    from rt_lookdev.core.materials import lobes
    from rt_lookdev.core.materials.surface import SURFACE
    from rt_lookdev.node_groups import library

    inputs = {}
    inputs.update(grids.technique_function_inputs(size=SIZE))
    for fn in library.all_functions():
        if fn is SURFACE:
            vals = grids.surface_inputs(SURFACE.input_sockets, size=SIZE)
        elif fn in lights.NODE_FUNCTIONS:
            vals = grids.light_data_inputs(fn, size=SIZE)
        elif fn.name.startswith("RTL LTC"):
            vals = grids.ltc_integral_inputs(tables.array("ltc_ggx_inv"), size=SIZE)
        elif any(fn is lobe.function(kind) for lobe in lobes.LOBES.values() for kind in lobes.AREA_KINDS):
            vals = grids.area_lobe_inputs("disk" if "Disk" in fn.name else "quad", size=SIZE)
        elif any(fn is lobe.function("point") for lobe in lobes.LOBES.values()):
            vals = grids.punctual_lobe_inputs(size=SIZE)
        else:
            vals = inputs
        _assert_conforms(fn.name, compare_function(fn, {k: vals[k] for k in fn.input_sockets}, tables, runner=gl))


@pytest.mark.parametrize("kind", ["quad", "disk", "point", "spot", "sun"])
def test_shade_functions_compute_like_numpy(gl, tables, kind):
    from rt_lookdev.core.materials import light_shading
    from rt_lookdev.core.materials.rt_lit_interface import Features

    vals = grids.shade_inputs(kind, size=SIZE)
    for features in (Features("kulla_conty", "wrapped", sheen=True, cloth=True), Features("turquin", "cod"),
                     Features("fdez_aguera", "lambert"), Features("single", "cod")):
        fn = light_shading.shade_function(kind, features)
        _assert_conforms(fn.name, compare_function(fn, {k: vals[k] for k in fn.input_sockets}, tables, runner=gl))


@pytest.fixture(scope="module")
def environment(tmp_path_factory):
    """A smooth prefiltered environment (grids.smooth_environment), as a bake gives: with a random table,
    a one-ulp difference in the direction-to-texel angles (GLSL's and numpy's arccosine and atan2 round
    differently) is multiplied by the contrast of two random texels (measured: up to 5.4e-5 relative in
    the World term, where the smooth table gives the bound below)."""
    from rt_lookdev.core.lut import exr_io
    from rt_lookdev.core.materials import world_shading as world

    path = tmp_path_factory.mktemp("env") / "env_glsl_prefiltered.exr"
    levels = "[" + ", ".join(map(str, grids.ENVIRONMENT_LEVELS)) + "]"
    exr_io.write_table(path, grids.smooth_environment(), {"table": "env_glsl", "roughness_levels": levels})
    return world.WorldEnvironment.load(path, "env_glsl_conformance")


def test_world_functions_compute_like_numpy(gl, tables, environment):
    from rt_lookdev.core.materials import world_shading as world
    from rt_lookdev.core.materials.rt_lit_interface import Features

    vals = grids.world_inputs(size=SIZE)
    tables = tables.with_tables(environment.as_table())
    functions = [world.prefiltered_function(environment), world.WORLD_ROTATION, world.SH_LOBE, world.SH_LTC_COD,
                 world.SH_LTC_CLOTH, world.SH_LTC_SHEEN, world.SH_LTC_ZELTNER, world.SH_LTC_DISNEY_FITTED,
                 world.SH_MOMENTS]
    functions += [world.specular_function(model, form) for model in ("single", "turquin", "fdez_aguera", "kulla_conty")
                  for form in (("irradiance", "radiance") if model == "fdez_aguera" else ("irradiance",))]
    functions += [world.shade_world_function(f, environment) for f in (
        Features("fdez_aguera", "cod", sheen=True, cloth=True), Features("kulla_conty", "wrapped"),
        Features("single", "lambert"))]
    for fn in functions:
        _assert_conforms(fn.name, compare_function(fn, {k: vals[k] for k in fn.input_sockets}, tables, runner=gl))


@pytest.mark.parametrize("features", ["all", "demo", "occluded"])
def test_whole_material_computes_like_numpy(gl, tables, environment, features):
    """The RT Lit material for every light kind and the world, as one emitted function (with the world occluded:
    the AO input, the clipped cones)."""
    from rt_lookdev.core.materials import rt_lit
    from rt_lookdev.core.materials.rt_lit_interface import OCCLUSION_INPUT, Features

    chosen = {"all": Features("kulla_conty", "wrapped", sheen=True, cloth=True), "demo": Features("turquin", "cod"),
              "occluded": Features("turquin", "cod", cloth=True, occlusion="cones_clipped")}[features]
    material = rt_lit.build_rt_lit(chosen, ("quad", "disk", "point", "spot", "sun"), environment)
    vals = grids.material_inputs(material, size=SIZE)
    assert (OCCLUSION_INPUT in vals) == (features == "occluded")
    report = compare_function(material.function, vals, material.tables(tables), runner=gl)
    _assert_conforms(material.name, report)
