"""Every emitted shader compiles with glslang's reference compiler: each technique, every node group
offered to artists and the World-term functions (each with a probe entry point), and the whole RT Lit
material for several feature sets and light lists (fragment and vertex shader), in GLSL 4.50, GLSL ES
3.00 and HLSL.  A refused shader fails with glslang's log and the source lines it names."""
from __future__ import annotations

import importlib.util
import itertools
import json
import subprocess
import sys
from pathlib import Path

import pytest

from rt_lookdev.core.ir import shader_text, trace
from rt_lookdev.core.ir.expr import Function
from rt_lookdev.validation.harness import glslang
from rt_lookdev.validation.harness.grids import TECHNIQUES

pytestmark = pytest.mark.glsl

DIALECTS = ("glsl450", "glsl300es", "hlsl")


def _compile_function(fn, dialect):
    module = shader_text.emit(fn, dialect)
    glslang.compile_source(shader_text.probe_entry(module), "frag", dialect)
    return module


@pytest.mark.parametrize("dialect", DIALECTS)
def test_every_technique_compiles(glslang_path, dialect):
    for name, (fn, names) in sorted(TECHNIQUES.items()):
        _, out = trace(fn, dict.fromkeys(names, "float"))
        _compile_function(Function(f"RTL {name}", dict.fromkeys(names, "float"), {"out": out}), dialect)


@pytest.mark.parametrize("dialect", DIALECTS)
def test_every_library_function_compiles(glslang_path, dialect):
    from rt_lookdev.core.materials import world_shading as world
    from rt_lookdev.node_groups import library

    functions = list(library.all_functions()) + [world.WORLD_ROTATION, world.SH_LOBE, world.SH_LTC_COD,
                                                 world.SH_LTC_CLOTH, world.SH_LTC_SHEEN, world.SH_LTC_OREN_NAYAR,
                                                 world.SH_LTC_ZELTNER, world.SH_LTC_DISNEY_FITTED,
                                                 world.SH_MOMENTS]
    for fn in functions:
        module = _compile_function(fn, dialect)
        # readable output: one function per node function, named after it, with its description
        assert f"// {fn.name}" in module.source
        assert module.entry.ident.startswith("rtl_")


MATERIALS = {
    "all features, every light kind, world": (dict(specular="kulla_conty", diffuse="wrapped", sheen=True, cloth=True),
                                              ("quad", "disk", "point", "spot", "sun"), True),
    "demo: turquin + CoD, quad and disk, world": (dict(specular="turquin", diffuse="cod"), ("quad", "disk"), True),
    "fdez-aguera (radiance form), two suns and a spot": (dict(specular="fdez_aguera", diffuse="lambert",
                                                              environment_ms="radiance"), ("sun", "sun", "spot"), True),
    "minimal: single + Lambert, one point, no world": (dict(specular="single", diffuse="lambert"), ("point",), False),
    "no lights, world only": (dict(specular="turquin", diffuse="cod", sheen=True), (), True),
    "zeltner sheen, every light kind, world": (dict(specular="turquin", diffuse="cod", sheen="zeltner"),
                                               ("quad", "disk", "point", "spot", "sun"), True),
    "fitted disney sheen, quad and sun": (dict(specular="single", diffuse="lambert", sheen="disney_fitted"),
                                          ("quad", "sun"), False),
}
#: The rough diffuse (Oren-Nayar as Cycles): every light kind and the world.
MATERIALS["turquin + Oren-Nayar, every light kind, world"] = (dict(specular="turquin", diffuse="oren_nayar"),
                                                             ("quad", "disk", "point", "spot", "sun"), True)
#: World occlusion: the engine's AO as a uniform (issue 29).
MATERIALS["turquin + CoD, clipped-cones occlusion, quad, world"] = (
    dict(specular="turquin", diffuse="cod", occlusion="cones_clipped"), ("quad",), True)


@pytest.fixture(scope="module")
def environment(tmp_path_factory):
    from rt_lookdev.core.lut import exr_io
    from rt_lookdev.core.materials import world_shading as world
    from rt_lookdev.validation.harness import grids

    path = tmp_path_factory.mktemp("env") / "env_compile.exr"
    exr_io.write_table(path, grids.smooth_environment(), {"table": "env_compile",
                                                          "roughness_levels": str(list(grids.ENVIRONMENT_LEVELS))})
    return world.WorldEnvironment.load(path, "env_compile")


@pytest.mark.parametrize("dialect", DIALECTS)
@pytest.mark.parametrize("case", sorted(MATERIALS))
def test_material_shader_compiles(glslang_path, environment, dialect, case):
    from rt_lookdev.core.materials import rt_lit, rt_lit_shader
    from rt_lookdev.core.materials.rt_lit_interface import Features

    features, kinds, world = MATERIALS[case]
    material = rt_lit.build_rt_lit(Features(**features), kinds, environment if world else None)
    shader = rt_lit_shader.material_shader(material, dialect)
    glslang.compile_source(shader.fragment, "frag", dialect)
    glslang.compile_source(shader.vertex, "vert", dialect)
    # the interface names every input the material function takes, and nothing is left unbound
    assert set(shader.bindings) >= {n for n, _ in material.function.inputs}
    for kind in set(kinds):
        assert f"u_{kind}_lights[{kinds.count(kind)}]" in shader.fragment
    assert ("u_world_sh[9]" in shader.fragment) == world
    assert ("uniform float u_ambient_occlusion;" in shader.fragment or "float u_ambient_occlusion;" in shader.fragment) \
        == ("occlusion" in features)
    # papers named in the comments of the functions they implement
    if features.get("specular") == "kulla_conty":
        assert "Kulla" in shader.fragment
    if "quad" in kinds:
        assert "Heitz" in shader.fragment


def test_a_refused_shader_names_its_line(glslang_path):
    source = "#version 450 core\nlayout(location = 0) out vec4 o;\nvoid main()\n{\n    o = vec4(undefined_name);\n}\n"
    with pytest.raises(glslang.GlslangError) as err:
        glslang.compile_source(source, "frag", "glsl450")
    message = str(err.value)
    assert "undefined_name" in message and "    5      o = vec4(undefined_name);" in message


EXPORT_SHADER = Path(__file__).parents[2] / "scripts" / "export_shader.py"
#: The files of each dialect scripts/export_shader.py writes: (fragment, vertex).
EXPORTED = {"glsl450": ("glsl450.frag", "glsl450.vert"), "glsl300es": ("glsl300es.frag", "glsl300es.vert"),
            "hlsl": ("ps.hlsl", "vs.hlsl")}


def _export_shader_script():
    spec = importlib.util.spec_from_file_location("export_shader", EXPORT_SHADER)
    script = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(script)
    return script


def _compile_export(out):
    for dialect, (frag, vert) in EXPORTED.items():
        glslang.compile_source((out / f"rt_lit.{frag}").read_text(), "frag", dialect)
        glslang.compile_source((out / f"rt_lit.{vert}").read_text(), "vert", dialect)


def test_export_shader_script_writes_what_compiles(glslang_path, tmp_path, lut_dir):
    """scripts/export_shader.py: shaders in every dialect, interface.json and the LUT files they sample."""
    out = tmp_path / "shaders"
    assert _export_shader_script().main(["--out", str(out), "--lights", "quad,sun", "--specular", "kulla_conty",
                                         "--cloth", "--lut-dir", str(lut_dir)]) == 0
    data = json.loads((out / "interface.json").read_text())
    assert [s["uniform"] for s in data["light_slots"]] == ["u_quad_lights[0]", "u_sun_lights[0]"]
    for name, entry in data["tables"].items():
        assert (out / entry["file"]).is_file(), name
    _compile_export(out)


def _kinds_with_options():
    """Every light kind with each combination of the options it takes (core/lights.py OPTION_KINDS)."""
    from rt_lookdev.core import lights

    combos = [c for n in range(1, len(lights.LIGHT_OPTIONS) + 1) for c in itertools.combinations(lights.LIGHT_OPTIONS, n)]
    kinds = dict.fromkeys(lights.kind_name(base, c) for base in lights.LIGHT_DATA for c in combos)
    return [k for k in kinds if lights.split_kind(k)[1]]


def test_export_shader_script_exports_every_light_kind_with_options(glslang_path, tmp_path, lut_dir):
    """--lights quad+range, disk+cone+range, ... (what --help and the error for a bad kind suggest): each kind with
    options has its own struct and array, in the shaders and in interface.json, and the shaders compile."""
    from rt_lookdev.core import lights
    from rt_lookdev.core.materials import rt_lit_shader

    kinds = _kinds_with_options()
    assert {"quad+range", "quad+cone+range", "disk+cone", "point+range", "spot+range", "quad_spot+range"} <= set(kinds)
    out = tmp_path / "shaders"
    assert _export_shader_script().main(["--out", str(out), "--lights", ",".join(["quad"] + kinds),
                                         "--lut-dir", str(lut_dir)]) == 0
    data = json.loads((out / "interface.json").read_text())
    assert [s["kind"] for s in data["light_slots"]] == ["quad"] + kinds
    fragment = (out / "rt_lit.glsl450.frag").read_text()
    for slot in data["light_slots"][1:]:
        kind = slot["kind"]
        base, options = lights.split_kind(kind)
        assert slot["struct"] == rt_lit_shader.light_struct(kind) != rt_lit_shader.light_struct(base)
        assert slot["uniform"] == f"{rt_lit_shader.light_array(kind)}[0]"
        assert f"struct {slot['struct']} {{" in fragment and f" {rt_lit_shader.light_array(kind)}[1];" in fragment
        parameters = {p for f in slot["fields"] for p in f["parameters"]}
        assert ("Range" in parameters) == ("range" in options)
        assert {"Cone Inner", "Cone Outer"} <= parameters or "cone" not in options
    _compile_export(out)


def test_export_shader_script_takes_every_model(tmp_path, lut_dir):
    """--sheen takes a sheen model; alone it is the Zeltner sheen, as Convert gives a Principled material (the old
    bare --sheen, the talk's Disney sheen, is disney_talk); --diffuse and --specular take every model."""
    from rt_lookdev.core.export import shaders
    from rt_lookdev.core.materials import rt_lit_interface as iface

    def parsed(*args):
        return shaders.parse_args(["--out", str(tmp_path / "x"), *args])

    assert iface.PRINCIPLED_SHEEN == "zeltner"
    assert parsed().sheen == "none"
    assert parsed("--sheen").sheen == parsed("--sheen", "--cloth").sheen == "zeltner"
    assert parsed("--sheen", "--cloth").cloth
    for name, models in (("sheen", iface.SHEEN_MODELS), ("diffuse", iface.DIFFUSE_MODELS),
                         ("specular", iface.SPECULAR_MODELS)):
        for model in models:
            assert getattr(parsed(f"--{name}", model), name) == model
    out = tmp_path / "sheen"
    assert _export_shader_script().main(["--out", str(out), "--sheen", "--lights", "quad", "--dialects", "glsl450",
                                         "--lut-dir", str(lut_dir)]) == 0
    data = json.loads((out / "interface.json").read_text())
    assert data["features"]["sheen"] == "zeltner" and "zeltner sheen" in data["material"]
    assert "zeltner_sheen.exr" in {entry["file"] for entry in data["tables"].values()}


#: Bad values of scripts/export_shader.py and what its one-line error must name.
BAD_EXPORT_ARGS = {
    "unknown dialect": (["--dialects", "glsl,hlsl"], "argument --dialects: unknown dialects glsl; choose from "
                                                     "glsl450, glsl300es, hlsl"),
    "no dialect": (["--dialects", ","], "argument --dialects: no dialect; choose from glsl450, glsl300es, hlsl"),
    "unknown light kind": (["--lights", "quad,tube"], "argument --lights: unknown light kind 'tube' (known: quad, "),
    "option a kind lacks": (["--lights", "sun+range"], "light kind 'sun' has no option 'range'; the options, in this "
                                                       "order: +cone on quad, disk; +range on quad, disk, point"),
    "sheen model": (["--sheen", "velvet"], "argument --sheen: invalid choice: 'velvet'"),
    "missing world": (["--world", "{tmp}/none.exr"], "argument --world: {tmp}/none.exr does not exist; it takes a "
                                                     "world bake's prefiltered EXR"),
    "world not an EXR": (["--world", "{tmp}/text.exr"], "argument --world: {tmp}/text.exr is not a world bake's "
                                                         "prefiltered EXR"),
    "world a LUT": (["--world", "{luts}/ggx_one_minus_E.exr"], "holds the table 'ggx_one_minus_E', not prefiltered "
                                                                "levels"),
}


@pytest.mark.parametrize("case", sorted(BAD_EXPORT_ARGS))
def test_export_shader_script_refuses_bad_values_in_one_line(case, tmp_path, lut_dir):
    """A bad --dialects, --lights, --sheen or --world: argparse's one-line error naming the valid values or what
    is wrong with the file, exit code 2, no traceback and nothing written."""
    args, message = BAD_EXPORT_ARGS[case]
    (tmp_path / "text.exr").write_text("not an image")
    fill = {"tmp": tmp_path, "luts": lut_dir}
    proc = subprocess.run([sys.executable, str(EXPORT_SHADER), "--out", str(tmp_path / "out"),
                           *(a.format(**fill) for a in args)], capture_output=True, text=True, timeout=60)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr
    assert lines[-1].startswith("export_shader.py: error: ") and message.format(**fill) in lines[-1], lines[-1]
    assert not (tmp_path / "out").exists()


def test_interface_table_names_the_struct_of_each_light_kind():
    """rt_lit_shader.interface_markdown (docs/realtime.md's table) for kinds with options: their structs' fields."""
    from rt_lookdev.core.materials import rt_lit, rt_lit_shader
    from rt_lookdev.core.materials.rt_lit_interface import Features

    kinds = _kinds_with_options()
    shader = rt_lit_shader.material_shader(rt_lit.build_rt_lit(Features(), kinds, None))
    table = rt_lit_shader.interface_markdown(shader)
    for kind in kinds:
        assert f"| `{rt_lit_shader.light_struct(kind)}` | `color` | `vec3` |" in table, kind
    assert "| `RtlAreaLightConeRange` | `range` | `float` | Range |" in table


def test_docs_show_the_interface_the_code_emits(tmp_path):
    """docs/realtime.md's uniform table is the one rt_lit_shader.interface_markdown writes for the
    reference material (a world table of the bake's size named env_0123456789ab)."""
    from pathlib import Path

    from rt_lookdev.core.lut import exr_io
    from rt_lookdev.core.materials import rt_lit_shader
    from rt_lookdev.core.materials import world_shading as world
    from rt_lookdev.validation.harness import grids

    path = tmp_path / "env.exr"
    exr_io.write_table(path, grids.smooth_environment(64, 128), {"table": "env_0123456789ab",
                                                                "roughness_levels": str(list(grids.ENVIRONMENT_LEVELS))})
    env = world.WorldEnvironment.load(path, "env_0123456789ab")
    table = rt_lit_shader.interface_markdown(rt_lit_shader.material_shader(rt_lit_shader.reference_material(env)))
    doc = (Path(__file__).parents[2] / "docs" / "realtime.md").read_text()
    begin, end = "<!-- interface:begin -->\n", "<!-- interface:end -->"
    assert doc[doc.index(begin) + len(begin):doc.index(end)].strip() == table.strip(), (
        "docs/realtime.md's interface table is out of date; paste rt_lit_shader.interface_markdown(...) between "
        "the interface markers:\n" + table)
