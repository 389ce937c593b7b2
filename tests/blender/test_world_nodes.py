"""The World term's node functions (core/materials/world_shading.py) rendered by Cycles equal numpy.

Every function of the world term, fed 48 x 48 grids of inputs (directions over the whole sphere
with the poles and the equirect seam, roughness 0 and 1 and between levels, V below the horizon,
rotations), is emitted as its node group and rendered; each output is compared with the traced
graph evaluated in float32 (validation.harness.conformance.check_function: 1e-4 relative, 1e-6 absolute near zero).  The
prefiltered environment is a random 9-level table written as an EXR like the bake's.
"""
from __future__ import annotations

import numpy as np
import pytest

from rt_lookdev.validation.harness.conformance import check_function
from rt_lookdev.validation.harness.grids import ENVIRONMENT_LEVELS as LEVELS
from rt_lookdev.validation.harness.grids import random_environment, smooth_environment, world_inputs

pytest.importorskip("OpenEXR")

pytestmark = pytest.mark.blender

SIZE = 48


@pytest.fixture(scope="module")
def environment(tmp_path_factory):
    from rt_lookdev.core.lut import exr_io
    from rt_lookdev.core.materials import world_shading as world

    table = random_environment()
    path = tmp_path_factory.mktemp("env") / "env_test_ggx_prefiltered.exr"
    exr_io.write_table(path, table, {"table": "env_test", "roughness_levels": "[" + ", ".join(map(str, LEVELS)) + "]"})
    return world.WorldEnvironment.load(path, "env_test_conformance"), path


def _check(fn, tables):
    vals = world_inputs()
    return check_function(fn, {k: np.asarray(vals[k], np.float32) for k in fn.input_sockets}, tables)


def test_prefiltered_lookup_group_matches_numpy(empty_scene, tables, environment):
    from rt_lookdev.core.materials import world_shading as world

    env, _ = environment
    tables = tables.with_tables(env.as_table())
    _check(world.prefiltered_function(env), tables)


def test_world_helper_groups_match_numpy(empty_scene, tables):
    from rt_lookdev.core.materials import world_shading as world

    for fn in (world.WORLD_ROTATION, world.SH_LOBE, world.SH_LTC_COD, world.SH_LTC_CLOTH, world.SH_LTC_SHEEN,
               world.SH_LTC_OREN_NAYAR, world.SH_LTC_ZELTNER, world.SH_LTC_DISNEY_FITTED, world.SH_MOMENTS):
        _check(fn, tables)
    for model in ("single", "turquin", "fdez_aguera", "kulla_conty"):
        for form in (("irradiance", "radiance") if model == "fdez_aguera" else ("irradiance",)):
            _check(world.specular_function(model, form), tables)


def test_shade_world_groups_match_numpy(empty_scene, tables, environment):
    from rt_lookdev.addon import node_emit
    from rt_lookdev.core.materials import world_shading as world
    from rt_lookdev.core.materials.rt_lit_interface import Features

    env, _ = environment
    tables = tables.with_tables(env.as_table())
    for features in (Features("fdez_aguera", "cod", sheen=True, cloth=True),
                     Features("kulla_conty", "wrapped"), Features("single", "lambert"),
                     Features("turquin", "oren_nayar"),
                     Features("turquin", "cod", sheen="zeltner"), Features("none", "lambert", sheen="disney_fitted"),
                     Features("turquin", "cod", cloth=True, sheen="zeltner", occlusion="cones_clipped"),
                     Features("fdez_aguera", "oren_nayar", occlusion="lagarde"), Features("single", "cod", occlusion="cones")):
        fn = world.shade_world_function(features, env)
        _check(fn, tables)
        counts = node_emit.tree_node_counts(node_emit.ensure_function_group(fn, tables))
        assert max(counts.values()) <= node_emit.MAX_GROUP_NODES, counts


def test_shade_world_computes_the_same_in_eevee(empty_scene, tables, tmp_path):
    """Identical inputs through the whole world group in both engines, on a smooth environment (a
    random table would turn Mesa's approximate arccosine, 3.1e-4 relative (docs/conventions.md), into
    texel-to-texel jumps): EEVEE's half-float film is the only difference allowed."""
    from rt_lookdev.validation.harness.engines import eevee_available

    ok, why = eevee_available()
    if not ok:
        pytest.skip(why)
    from rt_lookdev.validation.harness.conformance import render_group_outputs

    from rt_lookdev.addon import node_emit
    from rt_lookdev.core.lut import exr_io
    from rt_lookdev.core.materials import world_shading as world
    from rt_lookdev.core.materials.rt_lit_interface import Features

    table = smooth_environment()
    path = tmp_path / "env_smooth.exr"
    exr_io.write_table(path, table, {"table": "env_smooth", "roughness_levels": str(list(LEVELS))})
    env = world.WorldEnvironment.load(path, "env_smooth_eevee")
    tables = tables.with_tables(env.as_table())
    fn = world.shade_world_function(Features("fdez_aguera", "cod", sheen=True, cloth=True), env)
    vals = world_inputs()
    vals = {k: np.asarray(vals[k], np.float32) for k in fn.input_sockets}
    ng = node_emit.ensure_function_group(fn, tables)
    cycles = render_group_outputs(ng, vals, "Radiance")
    eevee = render_group_outputs(ng, vals, "Radiance", engine="BLENDER_EEVEE")
    big = (cycles > 1e-3) & (cycles < 65504.0)
    rel = np.abs(eevee[big] - cycles[big]) / cycles[big]
    print(f"{fn.name}: {big.sum()} values, EEVEE vs Cycles median {np.median(rel):.2e}, "
          f"p99 {np.percentile(rel, 99):.2e}, max {rel.max():.2e}")
    assert big.sum() > 1000 and rel.max() <= 1.5e-3
