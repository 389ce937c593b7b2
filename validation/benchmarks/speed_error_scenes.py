"""The speed-vs-error benchmark's plan (its cases as data, ``plan``) and the scenes it builds for them
(validation suite cases, world-suite worlds, the demo scene), with the closures of their references."""
from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

from ..harness import closures
from ...core.environment import equirect
from ..checks import lookdev_twin
from ..checks import suite_cases as suite
from ..checks import suite_scene
from ..checks import world_cases as vw
from ..checks.world_suite import QUICK, ROTATED


REPO = Path(__file__).resolve().parents[2]

FLOOR = 0.1                      # the suite's floor: values above 0.1 x the sphere's maximum
LADDER_SEED = 7                  # the ladder's seed; the references use REF_SEEDS
REF_SEEDS = (0, 1)
CHEAP_SECONDS = 0.5              # rungs whose render takes less are timed TIMING_REPEATS times (median)
TIMING_REPEATS = 3
CYCLES_SLOPE_SPP = 128           # RT Lit in Cycles: a render at this many samples gives the per-sample time
EEVEE_SLOPE_SPP = 8              # the same for EEVEE (each of its samples redraws the frame)
EEVEE_REPEATS = 2                # EEVEE renders per timing (a render costs 1-3 s on llvmpipe)
GLSL_FRAMES = 5
GLSL_WIDTH = 256
BACKENDS = ("cycles", "eevee", "glsl", "numpy")
BACKEND_LABELS = {"cycles": "RT Lit in Cycles (1 spp)", "eevee": "RT Lit in EEVEE", "glsl": "GLSL at the passes",
                  "numpy": "numpy at the passes"}
FAMILIES = ("diffuse", "glossy", "rough", "world", "punctual", "demo")
METRICS = ("rel_rms", "flip")
GLOSSY_MAX_ROUGHNESS = 0.3


# --- the plan ------------------------------------------------------------------------------------------

@dataclass
class CaseSpec:
    """One scene of the benchmark: ``kind`` "suite" (a suite case's lights, ``variants`` (technique,
    roughness)), "world" (``world``: (HDRI, Euler rotation, strength)) or "demo"; reference samples per seed;
    the ladder's top (None: the plan's)."""
    name: str
    kind: str
    source: str = ""
    variants: tuple = ()
    ref_spp: int = 1024
    ladder_max: int | None = None
    world: tuple = ()
    columns: int = 4


@dataclass
class Plan:
    cases: list
    ladder_max: int
    cell: int
    demo_resolution: int = 160
    quick: bool = False
    eevee_repeats: int = EEVEE_REPEATS


AREA_VARIANTS = (("lambert", 0.5), ("ggx", 0.25), ("ggx", 0.5), ("turquin", 0.6))
WORLD_VARIANTS = (("lambert", 0.5), ("ggx", 0.25), ("ggx", 0.5), ("turquin", 0.6))
PUNCTUAL_VARIANTS = (("lambert", 0.5), ("ggx", 0.3), ("ggx", 0.7))


def plan(quick=False, cell=None):
    """The scenes, sized for 2 cores.  Full (about 16 minutes, estimated): three quad and two disk cases of the suite
    (Lambert, GGX r = 0.25 and 0.5, Turquin r = 0.6 against Multiscatter GGX; 24 px cells), its point light, two
    worlds (forest rotated and scaled, the world validation's quick world; sunrise rotated, its small sun the hard
    case for path tracing) and the demo scene at 160 x 160; references 4096 spp x 2 (the demo 1024 x 2), ladder to
    4096 spp (the demo 1024).  Quick (about 2 minutes): one quad case, one disk case and the forest world with
    two or three spheres each, ladder to 256 spp, references 1024 x 2, EEVEE timed once per sample count."""
    if quick:
        cases = [CaseSpec("quad1", "suite", "quad1_closures", AREA_VARIANTS[:3], ref_spp=1024),
                 CaseSpec("disk4", "suite", "disk4_closures", (("lambert", 0.5), ("ggx", 0.5)), ref_spp=1024),
                 CaseSpec("world_forest", "world", world=QUICK, variants=(("lambert", 0.5), ("ggx", 0.5)),
                          ref_spp=1024)]
        return Plan(cases, ladder_max=256, cell=cell or 24, quick=True, eevee_repeats=1)
    cases = [CaseSpec("quad0", "suite", "quad0_closures", AREA_VARIANTS, ref_spp=4096),
             CaseSpec("quad1", "suite", "quad1_closures", AREA_VARIANTS, ref_spp=4096),
             CaseSpec("quad3", "suite", "quad3_closures", AREA_VARIANTS, ref_spp=4096),
             CaseSpec("disk4", "suite", "disk4_closures", AREA_VARIANTS, ref_spp=4096),
             CaseSpec("disk5", "suite", "disk5_closures", AREA_VARIANTS, ref_spp=4096),
             CaseSpec("point", "suite", "point", PUNCTUAL_VARIANTS, ref_spp=4, ladder_max=4, columns=3),
             CaseSpec("world_forest", "world", world=QUICK, variants=WORLD_VARIANTS, ref_spp=4096),
             CaseSpec("world_sunrise", "world", world=ROTATED, variants=WORLD_VARIANTS, ref_spp=4096),
             CaseSpec("demo", "demo", ref_spp=1024, ladder_max=1024)]
    return Plan(cases, ladder_max=4096, cell=cell or 24)


def family(kind, technique, roughness, light_kinds=()):
    """diffuse (Lambert), glossy (GGX r <= 0.3), rough (GGX r > 0.3) under area lights; world; punctual
    (a single point / spot / sun: Cycles is exact at 1 spp); demo (against Principled twins)."""
    if kind in ("world", "demo"):
        return kind
    if light_kinds and all(k in ("point", "spot", "sun") for k in light_kinds):
        return "punctual"
    if technique == "lambert":
        return "diffuse"
    return "glossy" if roughness <= GLOSSY_MAX_ROUGHNESS else "rough"


# --- scenes ------------------------------------------------------------------------------------------

@dataclass
class Prepared:
    """A built scene: the RT Lit spheres (pass index i + 1), their closure materials, where path tracing
    renders (``pt_scene``; the same scene with the closures swapped in, or the demo's twin)."""
    spec: CaseSpec
    scene: object
    pt_scene: object
    objects: list
    variants: list               # per sphere: {"label", "technique", "roughness", "features", "family"}
    rt_materials: list
    pt_materials: list
    world: object = None         # (WorldEnvironment, numpy parameters) or None
    floor_mode: str = "max"      # "max": FLOOR x the sphere's max; "median": world_cases.max_fraction
    build_seconds: float = 0.0
    light_kinds: tuple = ()

    @property
    def resolution(self):
        r = self.scene.render
        return (r.resolution_x, r.resolution_y)

    def use_rt(self):
        """The RT Lit materials; the world without an importance map (as the demo scene: an emission-only
        material needs none, and Cycles builds it for every render: 3 s for a 1024 x 512 HDRI here)."""
        for ob, mat in zip(self.objects, self.rt_materials):
            ob.data.materials[0] = mat
        if self.scene.world is not None:
            self.scene.world.cycles.sampling_method = "NONE"

    def use_pt(self):
        """The closures (the demo: its twin scene); the world importance-sampled, as path tracing needs."""
        if self.scene.world is not None:
            self.scene.world.cycles.sampling_method = "AUTOMATIC"
        if self.spec.kind != "demo":
            for ob, mat in zip(self.objects, self.pt_materials):
                ob.data.materials[0] = mat


def _variant_record(kind, technique, roughness, label, features, light_kinds=()):
    return {"label": label, "technique": technique, "roughness": float(roughness), "features": features,
            "family": family(kind, technique, roughness, light_kinds)}


def _prepare_suite(spec, cell, lut_dir):
    base = {c.name: c for c in suite.build_cases(seed=0)}[spec.source]
    variants = [suite.Variant(t, r) for t, r in spec.variants]
    case = suite.Case(spec.name, base.lights, variants, columns=min(spec.columns, len(variants)),
                      description=base.description, tags=base.tags)
    scene, spheres = suite_scene.build_scene(case, cell, 192, 96, lut_dir)
    kinds = tuple(case.light_kinds)
    records = [_variant_record("suite", v.technique, v.roughness, v.label, v.features, kinds) for v in variants]
    truth_closures = [closures.closure_material(v, f"RTL_se_closure_{i}") for i, v in enumerate(variants)]
    return Prepared(spec, scene, scene, spheres, records, [o.data.materials[0] for o in spheres], truth_closures,
                    light_kinds=kinds, floor_mode="max")


def _prepare_world(spec, cell, lut_dir, cache_dir):
    hdri, rotation, strength = spec.world
    wspec = vw.WorldSpec(spec.name, str(equirect.resolve_hdri(hdri)), rotation, strength, hdri=hdri)
    scene = vw.new_scene()
    world = vw.setup_world(scene, wspec)
    env, params, _, _ = vw.sync_world(scene, cache_dir, lut_dir)
    world.cycles_visibility.camera = False          # a black background: only the spheres are measured
    variants = [vw.WorldVariant(t, r) for t, r in spec.variants]
    block = vw.add_node_block(scene, variants, cell, min(spec.columns, len(variants)), 0.0, lut_dir,
                              vw.sphere_mesh(192, 96))
    vw.frame(scene, block, [block])
    records = [_variant_record("world", v.technique, v.roughness, v.label, v.features) for v in variants]
    truth_closures = [vw.closure_material(v.closure, f"RTL_se_closure_{i}") for i, v in enumerate(variants)]
    return Prepared(spec, scene, scene, block.objects, records, [o.data.materials[0] for o in block.objects],
                    truth_closures, world=(env, vw.world_params_numpy(params)), floor_mode="median",
                    light_kinds=("world",))


def _prepare_demo(spec, resolution, lut_dir):
    from ...addon import demo_scene, lookdev_scene
    from ...addon import world_sync

    features = demo_scene.build_demo_scene(lut_dir, resolution)
    import bpy

    scene = bpy.context.scene
    twin = lookdev_scene.add_path_traced_twin(scene, bounces=0)
    spheres = lookdev_scene.lookdev_spheres(scene)
    copies = {o[lookdev_scene.TWIN_SOURCE_KEY]: o for o in twin.objects if lookdev_scene.TWIN_SOURCE_KEY in o.keys()}
    for o in copies.values():            # seen by the camera only: RT Lit casts no shadows and sees no object
        for attr in lookdev_twin.RAY_VISIBILITY:
            setattr(o, attr, False)
    records = []
    for i, ob in enumerate(spheres, start=1):
        ob.pass_index = i
        copies[ob.name].pass_index = i
        f = features[ob.name]
        records.append(_variant_record("demo", "demo", 0.0, ob.name, f))
    found = world_sync.world_environment()
    params = world_sync.world_parameters(scene)
    world = (found[0], vw.world_params_numpy(params)) if found is not None and params is not None else None
    return Prepared(spec, scene, twin, spheres, records, [o.data.materials[0] for o in spheres], [], world=world,
                    floor_mode="max", light_kinds=("demo",))


def prepare(spec, plan_, lut_dir=None, cache_dir=None):
    t0 = time.perf_counter()
    if spec.kind == "suite":
        prep = _prepare_suite(spec, plan_.cell, lut_dir)
    elif spec.kind == "world":
        prep = _prepare_world(spec, plan_.cell, lut_dir, cache_dir)
    elif spec.kind == "demo":
        prep = _prepare_demo(spec, plan_.demo_resolution, lut_dir)
    else:
        raise ValueError(f"unknown case kind {spec.kind!r}")
    for i, ob in enumerate(prep.objects, start=1):
        ob.pass_index = i
    prep.build_seconds = time.perf_counter() - t0
    return prep
