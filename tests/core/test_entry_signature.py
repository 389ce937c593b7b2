"""The one entry signature (validation/harness/entry.py): every module of validation/checks/ and
validation/benchmarks/ that defines ``parse_args`` imports; those of ``CONVERTED`` have ``run(args, progress=...)``
and ``to_markdown(result)``, and their scripts are ``entry.main(...)``.  The list is explicit: the other modules move
to the signature one by one (issue 28), and each joins the list when it does."""
from __future__ import annotations

import ast
import importlib
import inspect
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]

#: The modules that follow the entry signature (validation/<folder>/<name>) -> their script in scripts/.
CONVERTED = {
    "checks/energy_render": "validate_energy.py",
    "checks/rough_diffuse_furnace": "validate_rough_diffuse.py",
    "benchmarks/environment_benchmark": "benchmark_environment.py",
    "benchmarks/horizon_benchmark": "benchmark_horizon.py",
    "benchmarks/light_culling_benchmark": "benchmark_light_culling.py",
    "benchmarks/light_fallback_benchmark": "benchmark_light_fallback.py",
    "benchmarks/light_sync_benchmark": "benchmark_light_sync.py",
    "benchmarks/ltc_suite_like": "benchmark_ltc_suite_like.py",
    "benchmarks/lut_benchmark": "benchmark_luts.py",
    "benchmarks/lut_export_benchmark": "benchmark_lut_export.py",
    "benchmarks/ltc_code_export_benchmark": "benchmark_ltc_code_export.py",
    "benchmarks/metal_split_benchmark": "benchmark_metal_split.py",
    "benchmarks/realtime_benchmark": "benchmark_realtime.py",
    "benchmarks/rt_lit_benchmark": "benchmark_rt_lit.py",
    "benchmarks/specular_occlusion_benchmark": "benchmark_specular_occlusion.py",
    "benchmarks/spread_benchmark": "benchmark_spread.py",
    "benchmarks/wrapped_diffuse_benchmark": "benchmark_wrapped_diffuse.py",
    "benchmarks/floor_shadows_benchmark": "benchmark_floor_shadows.py",
    "benchmarks/concave_shadows_benchmark": "benchmark_concave_shadows.py",
    "benchmarks/eevee_shadows_benchmark": "benchmark_eevee_shadows.py",
    "benchmarks/three_ltc_benchmark": "benchmark_three_ltc.py",
}


def entry_modules():
    """validation/checks/ and validation/benchmarks/ modules with a top-level ``parse_args``, as "<folder>/<name>"."""
    found = []
    for folder in ("checks", "benchmarks"):
        for path in sorted((REPO / "validation" / folder).glob("*.py")):
            tree = ast.parse(path.read_text(), str(path))
            if any(isinstance(node, ast.FunctionDef) and node.name == "parse_args" for node in tree.body):
                found.append(f"{folder}/{path.stem}")
    return found


def module(name):
    return importlib.import_module("rt_lookdev.validation." + name.replace("/", "."))


def test_the_converted_modules_define_parse_args():
    assert set(CONVERTED) <= set(entry_modules()), sorted(set(CONVERTED) - set(entry_modules()))


@pytest.mark.parametrize("name", entry_modules())
def test_module_with_parse_args_imports(name):
    assert callable(module(name).parse_args)


@pytest.mark.parametrize("name", sorted(CONVERTED))
def test_run_and_to_markdown_have_the_entry_signature(name):
    mod = module(name)
    params = list(inspect.signature(mod.run).parameters.values())
    assert [p.name for p in params] == ["args", "progress"], f"{name}.run{inspect.signature(mod.run)}"
    args, progress = params
    assert args.default is inspect.Parameter.empty and args.kind is inspect.Parameter.POSITIONAL_OR_KEYWORD
    assert progress.default is not inspect.Parameter.empty and callable(progress.default), name
    assert len(inspect.signature(mod.to_markdown).parameters) == 1, f"{name}.to_markdown"


@pytest.mark.parametrize("name", sorted(CONVERTED))
def test_script_is_entry_main(name):
    text = (REPO / "scripts" / CONVERTED[name]).read_text()
    stem = name.split("/")[1]
    assert "entry.main(" in text, CONVERTED[name]
    assert f"import {stem}" in text, f"{CONVERTED[name]} does not import {stem}"
