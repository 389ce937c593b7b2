"""Every command the README shows is run by a test or by the main job; every script's --help works, and every
command a script's docstring or --help shows works.

``RUN_BY`` names, for each script the README mentions, the test (file::function) or the main job that runs
it; the first test checks the README names nothing else and that each place really mentions the script.
The commands no other test runs are run here, small (``test_readme_command_runs``).  The examples of the
scripts' docstrings and --help texts are run or parsed here (``test_script_help_and_examples``)."""
import argparse
import ast
import functools
import importlib.util
import itertools
import json
import re
import shlex
import subprocess
import sys
from pathlib import Path

import pytest

pytestmark = pytest.mark.blender

REPO = Path(__file__).resolve().parents[2]
MAIN_JOB = "validation/main_job.py"

RUN_BY = {
    "scripts/main.sh": "the main job",              # the README's first command: the main job itself
    "scripts/test.sh": ".ci/run",
    "scripts/env.sh": "scripts/test.sh",
    "scripts/run_main.py": "scripts/main.sh",
    "scripts/bake_luts.py": "tests/core/test_luts.py",
    "scripts/bake_environment.py": "tests/core/test_environment.py::test_readme_bake_environment_commands",
    "scripts/benchmark_light_sync.py": "tests/blender/test_bad_input.py::test_light_sync_benchmark_writes_its_report",
    "scripts/benchmark_three_ltc.py": "tests/browser/test_three_tables.py::test_the_benchmark_script_writes_its_report",
    "scripts/build_three_area.py": "tests/core/test_three_area.py::test_the_committed_module_is_what_the_ir_gives",
    "scripts/robustness_sweep.py": MAIN_JOB,
    "scripts/validate_energy.py": MAIN_JOB,
    "scripts/build_demo_scene.py": MAIN_JOB,
    "scripts/demo_report.py": MAIN_JOB,
    "scripts/validate.py": MAIN_JOB,
    "scripts/validate_world.py": MAIN_JOB,
    "scripts/export_luts.py": MAIN_JOB,
    "scripts/benchmark_realtime.py": MAIN_JOB,
    "scripts/benchmark_speed_error.py": MAIN_JOB,
    "scripts/export_shader.py": "tests/glsl/test_shader_compile.py",
    "scripts/build_extension.py": "tests/blender/test_extension_install.py",
    "scripts/benchmark_luts.py": "here",
    "scripts/benchmark_ltc.py": "here",
    "scripts/benchmark_lut_export.py": "here",
    "scripts/benchmark_ltc_code_export.py": "here",
    "scripts/benchmark_environment.py": "here",
    "scripts/benchmark_rt_lit.py": "here",
    "scripts/build_presets.py": "here",
    "scripts/benchmark_wrapped_diffuse.py": "here",
    "scripts/benchmark_light_fallback.py": "here",
    "scripts/benchmark_horizon.py": "here",
    "scripts/benchmark_spread.py": "here",
    "scripts/benchmark_light_culling.py": "here",
    "scripts/validate_rough_diffuse.py": "here",
    "scripts/measure_sheen_table.py": "here",
    "scripts/benchmark_metal_split.py": "here",
    "scripts/benchmark_specular_occlusion.py": "here",
    "scripts/benchmark_floor_shadows.py": "here",
    "scripts/benchmark_concave_shadows.py": "here",
    "scripts/benchmark_eevee_shadows.py": "here",
}

#: The commands run here: (script, arguments, files it must write under the output folder).
SMOKE = {
    "scripts/benchmark_luts.py": (["--quick", "--skip-bake", "--repeats", "1", "--out", "{out}"], ["luts.md", "luts.json"]),
    "scripts/benchmark_ltc.py": (["--quick", "--skip-bake", "--repeats", "1", "--out", "{out}"], ["ltc.md", "ltc.json"]),
    "scripts/benchmark_lut_export.py": (["--quads", "10", "--disks", "5", "--out", "{out}/lut_export.md"],
                                        ["lut_export.md", "lut_export.json"]),
    "scripts/benchmark_ltc_code_export.py": (["--quads", "8", "--out", "{out}/ltc_code_export.md"],
                                             ["ltc_code_export.md", "ltc_code_export.json"]),
    "scripts/benchmark_environment.py": (["--quick", "--hdris", "studio", "--normals", "100", "--dirs", "20",
                                          "--out", "{out}/environment.md"], ["environment.md", "environment.json"]),
    "scripts/benchmark_rt_lit.py": (["--quick", "--out", "{out}"], ["rt_lit.md", "rt_lit.json"]),
    "scripts/build_presets.py": (["--out", "{out}"], ["rt_lookdev_presets.blend", "blender_assets.cats.txt"]),
    "scripts/benchmark_wrapped_diffuse.py": (["--quick", "--lights", "4", "--out", "{out}"],
                                             ["wrapped_diffuse.md", "wrapped_diffuse.json"]),
    "scripts/benchmark_light_fallback.py": (["--quick", "--out", "{out}"], ["light_fallback.md", "light_fallback.json"]),
    "scripts/benchmark_horizon.py": (["--quick", "--out", "{out}"], ["horizon.md", "horizon.json"]),
    "scripts/benchmark_spread.py": (["--quick", "--out", "{out}"], ["spread.md", "spread.json"]),
    "scripts/benchmark_light_culling.py": (["--quick", "--scenes", "grid", "--out", "{out}"],
                                           ["light_culling.md", "light_culling.json"]),
    "scripts/validate_rough_diffuse.py": (["--resolution", "24", "--samples", "8", "--out", "{out}"],
                                          ["rough_diffuse_furnace.json"]),
    "scripts/measure_sheen_table.py": (["--lut-dir", "{out}"], ["zeltner_sheen.exr", "zeltner_sheen_sh1.exr"]),
    "scripts/benchmark_metal_split.py": (["--quick", "--out", "{out}"], ["metal_split.md", "metal_split.json"]),
    "scripts/benchmark_specular_occlusion.py": (["--quick", "--out", "{out}"],
                                                ["specular_occlusion.md", "specular_occlusion.json"]),
    "scripts/benchmark_floor_shadows.py": (["--quick", "--out", "{out}"], ["floor_shadows.md", "floor_shadows.json"]),
    "scripts/benchmark_concave_shadows.py": (["--quick", "--out", "{out}"],
                                             ["concave_shadows.md", "concave_shadows.json", "concave_shadows.png"]),
    "scripts/benchmark_eevee_shadows.py": (["--quick", "--out", "{out}"], ["eevee_shadows.md", "eevee_shadows.json"]),
}


def readme_scripts():
    text = (REPO / "README.md").read_text()
    return sorted(set(re.findall(r"scripts/[a-z_0-9]+\.(?:py|sh)", text)))


def test_every_readme_command_has_a_runner():
    scripts = readme_scripts()
    assert scripts and set(scripts) <= set(RUN_BY), sorted(set(scripts) - set(RUN_BY))
    for script, where in RUN_BY.items():
        assert (REPO / script).is_file(), script
        if where == "here":
            assert script in SMOKE
            continue
        if where == "the main job":
            continue
        path, _, function = where.partition("::")
        text = (REPO / path).read_text()
        stem = Path(script).stem
        module = {"validate": "suite", "validate_energy": "energy_render", "build_demo_scene": "demo_scene",
                  "demo_report": "demo_measure", "validate_world": "world_suite", "export_luts": "lut_export",
                  "robustness_sweep": "robustness", "benchmark_realtime": "realtime_benchmark"}.get(stem, stem)
        assert stem in text or module in text, f"{where} does not run {script}"
        if function:
            assert f"def {function}(" in text, where


#: Run once, in the development environment (.ci/run): each command is the README's documentation of a script, and the
#: machinery it drives is tested on every supported release by the suite's own tests of it.
@pytest.mark.development_release_only
@pytest.mark.parametrize("script", sorted(SMOKE))
def test_readme_command_runs(script, tmp_path):
    args, outputs = SMOKE[script]
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, script, *(a.format(out=out) for a in args)], cwd=REPO,
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    for name in outputs:
        assert (out / name).stat().st_size > 0, name
    if script == "scripts/benchmark_metal_split.py":
        # its two shadings are two measurements: the child's switch reaches the cases it runs (it did not while the
        # suite ran them in Dask worker processes)
        result = json.loads((out / "metal_split.json").read_text())
        assert result["mixed_f0"]["pooled"] != result["apart"]["pooled"]


def test_every_script_named_exists():
    """Every scripts/<name>.py or .sh that the README, the docs, CI, the code or the tests name exists (the --help
    texts are the code's docstrings; validate.py's named a suite script that had moved into validation/)."""
    texts = [REPO / "README.md", REPO / ".ci" / "run", *sorted((REPO / "docs").rglob("*.md")),
             *sorted((REPO / "scripts").glob("*.sh"))]
    texts += [p for folder in ("core", "addon", "node_groups", "validation", "scripts", "tests")
              for p in sorted((REPO / folder).rglob("*.py"))]
    named = {}
    for path in texts:
        for name in re.findall(r"scripts/[A-Za-z_0-9]+\.(?:py|sh)", path.read_text()):
            named.setdefault(name, set()).add(path.relative_to(REPO).as_posix())
    missing = {name: sorted(where) for name, where in named.items() if not (REPO / name).is_file()}
    assert named and not missing, missing


# --- every script's --help, and the commands its docstring and --help show ------------------------------------

SCRIPTS = sorted(p.relative_to(REPO).as_posix() for p in (REPO / "scripts").glob("*.py"))
#: A command line in a script's docstring or --help: an interpreter (python, a venv's python, Blender with
#: --python), a script and its arguments, which end at a backtick or at two spaces before a comment ("# ...",
#: "(...)"); at the line's end, more indented lines that start with an option ("[--x", "--x") continue them.
_COMMAND = re.compile(r"(python|blender --background --python|\.venvs/\S+/bin/python) (scripts/[a-z_0-9]+\.py)(.*)")
_ARGUMENTS_END = re.compile(r"`| {2,}[#(]")
_CONTINUATION = re.compile(r"^ +(\[?--.*)$")
#: Placeholders the examples use, and the values the test gives them ({tmp}: the test's folder, {world}: a
#: prefiltered environment EXR).  The value of --out / --output-dir is always in the test's folder (a file there
#: when the example names a file), and --lut-dir is the test's LUT folder, whatever the example shows.
PLACEHOLDERS = {"DIR": "{tmp}/dir", "N": "2", "S": "4", "NAME": "example", "REV": "HEAD", "LABEL": "single",
                "ENV.exr": "{world}", "/path/to/image.exr": "{world}", "BEFORE_DIR": "{tmp}/before",
                "AFTER_DIR": "{tmp}/after"}
OUTPUT_OPTIONS = ("--out", "--output-dir")
#: The examples that run, in a subprocess: seconds each, every output redirected.  The others are parsed by the
#: script's own parser, through its main (``_parse_through_main``): they run for minutes (benchmarks, validations,
#: bakes, the main job), write into the checkout (build_extension.py without --output-dir), need earlier runs'
#: output (compare_validation.py) or are Blender's command line; the README's commands run those scripts small
#: (``SMOKE`` above; ``RUN_BY``: their own tests and the main job).
RUN_EXAMPLES = {
    "python scripts/bake_environment.py --list",
    "python scripts/bake_luts.py [--lut-dir DIR] [--force] [--status]",
    "python scripts/build_extension.py --output-dir /tmp/out",
    "python scripts/export_luts.py --out DIR [--formats exr,ktx2,dds,npz,c,glsl,hlsl] [--precision f32,f16] "
    "[--layout rtl|ltc_code] [--lut-dir DIR] [--rebake]",
    "python scripts/export_shader.py --out DIR [--specular turquin] [--diffuse cod] [--sheen [zeltner]] [--cloth] "
    "[--lights quad+cone+range,disk,point,spot,sun] [--dialects glsl450,glsl300es,hlsl] "
    "[--world ENV.exr --world-table NAME] [--no-precise] [--lut-dir DIR]",
}


@functools.lru_cache(maxsize=None)
def help_text(script):
    """``python <script> --help``: its output (exit code 0)."""
    proc = subprocess.run([sys.executable, script, "--help"], cwd=REPO, capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0 and "usage: " in proc.stdout, proc.stdout[-2000:] + proc.stderr[-2000:]
    return proc.stdout[proc.stdout.index("usage: "):]          # after what importing bpy logs


def commands_in(text):
    """The command lines ``text`` shows (``_COMMAND``), continuation lines joined, spaces collapsed."""
    found, lines = [], text.splitlines()
    for i, line in enumerate(lines):
        for match in _COMMAND.finditer(line):
            parts = [match.group(0)]
            for more in lines[i + 1:]:
                continued = _CONTINUATION.match(more)
                if _ARGUMENTS_END.search(parts[-1]) or not continued:
                    break
                parts.append(continued.group(1))
            found.append(" ".join(" ".join(_ARGUMENTS_END.split(p)[0] for p in parts).split()))
    return found


def examples_of(script):
    """The commands ``script``'s docstring and --help show, in order (each once)."""
    doc = ast.get_docstring(ast.parse((REPO / script).read_text())) or ""
    return list(dict.fromkeys(commands_in(doc) + commands_in(help_text(script))))


def example_argvs(command, fill):
    """The argument lists of one example: every optional part given ("[--x V]" -> "--x V"), one list per
    alternative ("rtl|ltc_code"), placeholders and outputs as ``PLACEHOLDERS`` says, "[same options]" the script's
    first example's; Blender's own arguments kept (the script's main drops what precedes "--")."""
    interpreter, script, rest = _COMMAND.match(command).groups()
    if "[same options]" in rest:
        first = next(c for c in examples_of(script) if c.startswith("python "))
        rest = rest.replace("[same options]", _COMMAND.match(first).group(3))
    tokens = [t.strip("[]") for t in shlex.split(rest)]
    tokens = [t for t in tokens if t and t != "..."]
    prefix = ["--background", "--python", script] if interpreter.startswith("blender") else []
    argvs = []
    for choice in itertools.product(*(t.split("|") for t in tokens)):
        argvs.append(prefix + [_value(token, previous, fill) for previous, token in zip(("",) + choice, choice)])
    return argvs


def _value(token, option, fill):
    if option in OUTPUT_OPTIONS:
        return str(Path(fill["tmp"]) / "out" / (Path(token).name if Path(token).suffix else ""))
    if option == "--lut-dir":
        return str(fill["luts"])
    if re.fullmatch(r"[A-Z][A-Z_]*(\.[a-z]+)?|/path/to/.*", token):
        assert token in PLACEHOLDERS, f"an example's placeholder {token!r} has no value in PLACEHOLDERS"
        return PLACEHOLDERS[token].format(**fill)
    return token


class _Parsed(Exception):
    """Raised by ``ArgumentParser.parse_args`` under ``_parse_through_main``: the arguments were parsed."""


def _parse_through_main(script, argv, monkeypatch):
    """Run ``script``'s main on ``argv`` up to its parser and stop there: the namespace it parsed (an argparse
    error fails the test with argparse's message)."""
    original = argparse.ArgumentParser.parse_args

    def parse_and_stop(parser, args=None, namespace=None):
        raise _Parsed(original(parser, args, namespace))

    module = _script_module(script)
    monkeypatch.setattr(argparse.ArgumentParser, "parse_args", parse_and_stop)
    with pytest.raises(_Parsed) as parsed:
        module.main(argv)
    return parsed.value.args[0]


def _script_module(script):
    spec = importlib.util.spec_from_file_location(Path(script).stem, REPO / script)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def world_exr(tmp_path_factory):
    """A small prefiltered environment EXR (what --world and --hdri of the examples read)."""
    from rt_lookdev.core.lut import exr_io
    from rt_lookdev.validation.harness import grids

    path = tmp_path_factory.mktemp("world") / "env_example.exr"
    exr_io.write_table(path, grids.smooth_environment(), {"table": "env_example",
                                                          "roughness_levels": str(list(grids.ENVIRONMENT_LEVELS))})
    return path


def _check_description(script, text):
    """The description --help shows is not cut off: not the first line of a paragraph of more lines, in the docstring
    of the script or of a module it calls."""
    description = " ".join(text.split("\n\n")[1].split())
    module = _script_module(script)
    modules = [module] + [m for m in vars(module).values() if getattr(m, "__name__", "").startswith("rt_lookdev.")]
    for doc in (m.__doc__ or "" for m in modules):
        for lines in (p.strip().splitlines() for p in doc.split("\n\n")):
            assert not (len(lines) > 1 and " ".join(lines[0].split()) == description), (
                f"{script} --help cuts its description short: {description!r}")


@pytest.mark.parametrize("script", SCRIPTS)
def test_script_help_and_examples(script, tmp_path, lut_dir, world_exr, monkeypatch):
    """``--help`` works, with its whole description, and every command the script's docstring or --help shows
    works: run when it is in ``RUN_EXAMPLES``, else parsed by the script's own parser through its main."""
    _check_description(script, help_text(script))
    examples = examples_of(script)
    assert examples, f"{script}: no example command in its docstring or --help"
    fill = {"tmp": tmp_path, "luts": lut_dir, "world": world_exr}
    for command in examples:
        named = _COMMAND.match(command).group(2)
        for argv in example_argvs(command, fill):
            if command in RUN_EXAMPLES:
                proc = subprocess.run([sys.executable, named, *argv], cwd=REPO, capture_output=True, text=True,
                                      timeout=300)
                assert proc.returncode == 0, f"{command}\n{argv}\n{proc.stdout[-2000:]}{proc.stderr[-2000:]}"
            else:
                _parse_through_main(named, argv, monkeypatch)


def test_run_examples_are_shown():
    """``RUN_EXAMPLES`` names only commands the scripts show (a changed example must be looked at again)."""
    shown = {c for script in SCRIPTS for c in examples_of(script)}
    assert RUN_EXAMPLES <= shown, sorted(RUN_EXAMPLES - shown)
