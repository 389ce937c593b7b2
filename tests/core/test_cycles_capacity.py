"""The Cycles light capacities the add-on warns with are the measured ones (docs/benchmarks/rt_lit.json)."""
import json
from pathlib import Path

from rt_lookdev.core.materials import cycles_capacity
from rt_lookdev.core.materials.rt_lit_interface import Features

BENCHMARK = Path(__file__).resolve().parents[2] / "docs" / "benchmarks" / "rt_lit.json"


def _features(label):
    parts = [p.strip() for p in label.split(",")]
    return Features(parts[0].replace("-", "_"), parts[1], sheen="sheen" in parts[2:], cloth="cloth" in parts[2:])


def test_table_is_the_benchmarks_measurement():
    rows = json.loads(BENCHMARK.read_text())["rows"]
    measured = {_features(r["features"]): (r["max_quad_lights"], r["world_max_quad_lights"]) for r in rows}
    assert measured == cycles_capacity.MEASURED


def test_unmeasured_sets_get_a_costlier_measured_bound(monkeypatch):
    # the mechanism, on a table where the sets differ (the measurement of 2026-11-22; today every set reaches the
    # search's cap)
    monkeypatch.setattr(cycles_capacity, "MEASURED", {
        Features("single", "lambert"): (15, 15), Features("turquin", "cod"): (13, 13),
        Features("fdez_aguera", "lambert"): (15, 14), Features("kulla_conty", "lambert"): (8, 7),
        Features("turquin", "cod", sheen=True): (10, 8), Features("single", "cod", cloth=True): (10, 8),
        Features("kulla_conty", "wrapped", sheen=True, cloth=True): (3, 3)})
    assert cycles_capacity.light_capacity(Features("kulla_conty", "lambert")) == (8, True)
    assert cycles_capacity.light_capacity(Features("kulla_conty", "lambert"), world=True) == (7, True)
    # turquin + lambert: the best bound among sets at least as costly is fdez-aguera + lambert's 15
    assert cycles_capacity.light_capacity(Features("turquin", "lambert")) == (15, False)
    # turquin + lambert + cloth: only the all-on set is at least as costly (single + cod + cloth has a cheaper
    # specular): the warning errs on the safe side
    assert cycles_capacity.light_capacity(Features("turquin", "lambert", cloth=True)) == (3, False)
    # everything on but CoD instead of wrapped: the all-on row bounds it
    assert cycles_capacity.light_capacity(Features("kulla_conty", "cod", sheen=True, cloth=True)) == (3, False)


def test_every_model_of_every_switch_gets_a_capacity():
    """Sync Lights asks for the capacity of every RT Lit group's switches: no model may be missing from the cost
    order (an unknown diffuse model made Sync Lights fail)."""
    from itertools import product

    from rt_lookdev.core.materials.rt_lit_interface import DIFFUSE_MODELS, SHEEN_MODELS, SPECULAR_MODELS

    for spec, diffuse, sheen, cloth, world in product(SPECULAR_MODELS, DIFFUSE_MODELS, SHEEN_MODELS, (False, True),
                                                      (False, True)):
        lights, measured = cycles_capacity.light_capacity(Features(spec, diffuse, sheen=sheen, cloth=cloth), world)
        assert lights >= 1 and isinstance(measured, bool)


def test_a_capacity_at_the_searchs_cap_is_a_lower_bound():
    assert cycles_capacity.is_lower_bound(cycles_capacity.SEARCHED_UP_TO)
    assert not cycles_capacity.is_lower_bound(cycles_capacity.SEARCHED_UP_TO - 1)


def test_blender_4_spread_table_bounds_unmeasured_sets():
    """Blender 4.x under an area light with spread: the measured sets as measured; an unmeasured set renders where a
    measured one at least as costly does, and is warned about otherwise (the warning errs on the safe side)."""
    fits = cycles_capacity.renders_under_spread_in_4
    assert fits(Features("turquin", "cod")) and not fits(Features("kulla_conty", "wrapped", sheen=True, cloth=True))
    assert fits(Features("single", "lambert"))                  # bounded by Turquin + CoD (and Kulla-Conty + Lambert)
    assert fits(Features("fdez_aguera", "cod"))                 # Turquin + CoD: specular and diffuse as costly
    assert fits(Features("turquin", "cod", sheen="disney_fitted"))    # Turquin + CoD + Zeltner's sheen
    assert not fits(Features("turquin", "cod", cloth=True))     # no measured set with cloth is as costly
    assert not fits(Features("kulla_conty", "cod"))             # neither measured set bounds both switches


def test_blender_4_exact_horizon_table():
    """Blender 4.x with an exact horizon: every switch on is warned about, the measured sets that fit are not, nor a
    set a costlier measured one bounds; the horizon itself plays no part in the lookup."""
    fits = cycles_capacity.renders_with_exact_horizon_in_4
    assert not fits(Features("kulla_conty", "wrapped", sheen=True, cloth=True, horizon="exact"))
    assert fits(Features("turquin", "cod", horizon="exact_quads")) and fits(Features("kulla_conty", "lambert"))
    assert fits(Features("fdez_aguera", "wrapped"))             # Fernandez-Aguera + CoD wrapped bounds it
    assert not fits(Features("kulla_conty", "wrapped"))         # no measured set bounds Kulla-Conty with a wrap
