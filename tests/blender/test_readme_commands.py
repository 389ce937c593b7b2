"""Every command the README shows is run by a test or by the main job.

``RUN_BY`` names, for each script the README mentions, the test (file::function) or the main job that runs
it; the first test checks the README names nothing else and that each place really mentions the script.
The commands no other test runs are run here, small (``test_readme_command_runs``)."""
import re
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
    "scripts/benchmark_environment.py": "here",
    "scripts/benchmark_rt_lit.py": "here",
    "scripts/build_presets.py": "here",
    "scripts/benchmark_wrapped_diffuse.py": "here",
    "scripts/benchmark_light_fallback.py": "here",
    "scripts/benchmark_light_culling.py": "here",
    "scripts/validate_rough_diffuse.py": "here",
    "scripts/measure_sheen_table.py": "here",
    "scripts/benchmark_metal_split.py": "here",
}

#: The commands run here: (script, arguments, files it must write under the output folder).
SMOKE = {
    "scripts/benchmark_luts.py": (["--quick", "--repeats", "1", "--out", "{out}"], ["luts.md", "luts.json"]),
    "scripts/benchmark_ltc.py": (["--quick", "--skip-bake", "--repeats", "1", "--out", "{out}"], ["ltc.md", "ltc.json"]),
    "scripts/benchmark_lut_export.py": (["--quads", "10", "--disks", "5", "--out", "{out}/lut_export.md"],
                                        ["lut_export.md", "lut_export.json"]),
    "scripts/benchmark_environment.py": (["--quick", "--hdris", "studio", "--normals", "100", "--dirs", "20",
                                          "--out", "{out}/environment.md"], ["environment.md", "environment.json"]),
    "scripts/benchmark_rt_lit.py": (["--quick", "--out", "{out}"], ["rt_lit.md", "rt_lit.json"]),
    "scripts/build_presets.py": (["--out", "{out}"], ["rt_lookdev_presets.blend", "blender_assets.cats.txt"]),
    "scripts/benchmark_wrapped_diffuse.py": (["--quick", "--lights", "4", "--out", "{out}"],
                                             ["wrapped_diffuse.md", "wrapped_diffuse.json"]),
    "scripts/benchmark_light_fallback.py": (["--quick", "--out", "{out}"], ["light_fallback.md", "light_fallback.json"]),
    "scripts/benchmark_light_culling.py": (["--quick", "--scenes", "grid", "--out", "{out}"],
                                           ["light_culling.md", "light_culling.json"]),
    "scripts/validate_rough_diffuse.py": (["--resolution", "24", "--samples", "8", "--out", "{out}"],
                                          ["rough_diffuse_furnace.json"]),
    "scripts/measure_sheen_table.py": (["--lut-dir", "{out}"], ["zeltner_sheen.exr", "zeltner_sheen_sh1.exr"]),
    "scripts/benchmark_metal_split.py": (["--quick", "--out", "{out}"], ["metal_split.md", "metal_split.json"]),
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


@pytest.mark.parametrize("script", sorted(SMOKE))
def test_readme_command_runs(script, tmp_path):
    args, outputs = SMOKE[script]
    out = tmp_path / "out"
    proc = subprocess.run([sys.executable, script, *(a.format(out=out) for a in args)], cwd=REPO,
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stdout[-2000:] + proc.stderr[-2000:]
    for name in outputs:
        assert (out / name).stat().st_size > 0, name


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
