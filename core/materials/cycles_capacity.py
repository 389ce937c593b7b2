"""How many lights one RT Lit material can shade in Cycles before its shader runs out of SVM stack.

Cycles' SVM keeps every live value of a material on a stack of 255 floats; an RT Lit material carries
each light's terms, so past a number of lights that depends on its switches the compile fails and the
surface renders black.  The numbers are measured by ``scripts/benchmark_rt_lit.py`` (quad lights, the
costliest kind; docs/benchmarks/rt_lit.md, "Capacity") and checked against its JSON by
tests/core/test_cycles_capacity.py.  Measured 2026-12-02, every feature set, every technique on included, renders the
search's cap of 64 quad lights; the warning then says how far it was tested.  EEVEE has no such limit.
"""
from __future__ import annotations

from .rt_lit_interface import Features

#: The benchmark searches up to this many lights: a capacity equal to it means "at least this many" (the search
#: stopped there with the material still rendering).
SEARCHED_UP_TO = 64

#: feature set -> (max quad lights, max quad lights with the World term), measured.
MEASURED = {
    Features("single", "lambert"): (64, 64),
    Features("turquin", "cod"): (64, 64),
    Features("fdez_aguera", "lambert"): (64, 64),
    Features("kulla_conty", "lambert"): (64, 64),
    Features("turquin", "cod", sheen=True): (64, 64),
    Features("single", "cod", cloth=True): (64, 64),
    Features("kulla_conty", "wrapped", sheen=True, cloth=True): (64, 64),
}

# Rough cost order of the switches, for feature sets that were not measured: a measured set at least as
# costly in every switch bounds the capacity from below.
_SPECULAR_COST = {"none": 0, "single": 0, "turquin": 1, "fdez_aguera": 1, "kulla_conty": 2}
#: cod_wrapped: the CoD lobe over the light's image under the wrap, costlier than either; oren_nayar: its LTC
#: integral plus the multiple scattering's Lambert form factor, one integral more than CoD.  No measured set bounds
#: them, so they take the smallest measured capacity; checked with ``rt_lit_benchmark.capacity`` (2026-12-02),
#: turquin + each renders 64 quad lights with and without the World term, as do turquin + CoD with the Zeltner and
#: the fitted Disney sheen.
_DIFFUSE_COST = {"lambert": 0, "cod": 1, "wrapped": 1, "cod_wrapped": 2, "oren_nayar": 2}
#: The fitted Disney sheen has the talk's structure (one LTC integral, another table); Zeltner's is bounded by the
#: talk's sheen's measured set too (docs/sheen.md, "Cost").
_SHEEN_COST = {"none": 0, "disney_talk": 1, "disney_fitted": 1, "zeltner": 1}


def _at_least_as_costly(measured, features):
    return (_SPECULAR_COST[measured.specular] >= _SPECULAR_COST[features.specular]
            and _DIFFUSE_COST[measured.diffuse] >= _DIFFUSE_COST[features.diffuse]
            and _SHEEN_COST[measured.sheen] >= _SHEEN_COST[features.sheen] and measured.cloth >= features.cloth)


def light_capacity(features, world=False):
    """(lights, measured): the most lights a material with ``features`` shades in Cycles; ``measured`` is
    False when the set was not measured and the number is the bound from a costlier measured set (or the
    smallest measured capacity)."""
    column = 1 if world else 0
    key = Features(features.specular, features.diffuse, features.sheen, features.cloth)
    if key in MEASURED:
        return MEASURED[key][column], True
    bounds = [caps[column] for measured, caps in MEASURED.items() if _at_least_as_costly(measured, key)]
    return (max(bounds) if bounds else min(caps[column] for caps in MEASURED.values())), False


#: Blender 4.x only (Cycles 4.5): whether a material with these switches renders under an area light with spread, or
#: runs out of SVM stack and renders black; quads and disks gave the same verdicts.  Measured 2026-12-07 on the plane of
#: tests/blender/test_light_model.py under one 1.5 m light with a 40-degree spread, Sheen and Cloth Weight 0.5 (at 0
#: Cycles folds those lobes away), peaks from Cycles 4.5's log (GLOG_v=5) of its 255 floats, quad / disk: Lambert
#: 99 / 51 (151 before Lambert's disk rule exact along rays, light_spread.LAMBERT_DISK), Lambert + cloth 145 / 182
#: (208), Turquin + CoD 153 / 231, Turquin + CoD + Zeltner sheen 161 / 236, Kulla-Conty + Lambert 159 / 225 (234),
#: every switch on out of stack under both.  Blender 5.x renders every set.
SPREAD_IN_4 = {
    **dict.fromkeys((Features("none", "lambert"), Features("none", "lambert", cloth=True), Features("turquin", "cod"),
                     Features("turquin", "cod", sheen="zeltner"), Features("kulla_conty", "lambert")), True),
    Features("kulla_conty", "wrapped", sheen=True, cloth=True): False,
}


def _renders(table, features):
    """``table`` (measured switches -> renders) for ``features``; an unmeasured set renders where a measured set at
    least as costly renders."""
    key = Features(features.specular, features.diffuse, features.sheen, features.cloth)
    if key in table:
        return table[key]
    return any(ok and _at_least_as_costly(measured, key) for measured, ok in table.items())


def renders_under_spread_in_4(features):
    """Whether Blender 4.x renders a material with ``features`` under an area light with spread (``SPREAD_IN_4``)."""
    return _renders(SPREAD_IN_4, features)


#: Blender 4.x only: whether a material with these switches renders once its lobes clip quad lights exactly at the
#: horizon (Features.horizon "exact_quads" or "exact"; issue 30), measured as ``SPREAD_IN_4`` (a plane under one
#: 1.5 m light, no spread, 2026-12-07): under a quad 102-180 floats for eight sets, every switch on out of stack; under
#: an exact disk all nine sets fit (64-141), so the quads decide.  Blender 5.x renders every set.
EXACT_HORIZON_IN_4 = {
    **dict.fromkeys((Features("turquin", "cod"), Features("none", "cod", sheen=True, cloth=True),
                     Features("fdez_aguera", "cod_wrapped"), Features("turquin", "oren_nayar"),
                     Features("turquin", "cod", sheen="zeltner"), Features("single", "lambert", sheen="disney_fitted"),
                     Features("single", "lambert"), Features("kulla_conty", "lambert")), True),
    Features("kulla_conty", "wrapped", sheen=True, cloth=True): False,
}


def renders_with_exact_horizon_in_4(features):
    """Whether Blender 4.x renders a material with ``features`` and an exact horizon (``EXACT_HORIZON_IN_4``)."""
    return _renders(EXACT_HORIZON_IN_4, features)


def is_lower_bound(capacity):
    """True when ``capacity`` is where the benchmark's search stopped, not where the material failed."""
    return capacity >= SEARCHED_UP_TO
