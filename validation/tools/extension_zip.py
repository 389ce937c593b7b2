"""Validate and build the RT Lookdev extension zip with Blender's own extension tool.

Uses ``blender_ext.py`` shipped inside the ``bpy`` wheel (the code behind
``blender --command extension``), so no Blender binary is needed::

    python scripts/build_extension.py                 # -> dist/rt_lookdev-<version>.zip
    python scripts/build_extension.py --output-dir /tmp/out

Steps: check the baked LUTs are present and current, ``validate`` the source tree,
``build`` the zip, ``validate`` the zip, then list the zip and check that it holds
what the add-on needs at run time and none of the development files.
"""
from __future__ import annotations

import argparse
import importlib.util
import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path, PurePosixPath


REPO_ROOT = Path(__file__).resolve().parents[2]
MANIFEST = REPO_ROOT / "blender_manifest.toml"
DEFAULT_OUTPUT_DIR = REPO_ROOT / "dist"

#: Entries the zip must contain (a trailing "/" means "at least one file under it").
REQUIRED_ENTRIES = (
    "__init__.py",
    "blender_manifest.toml",
    "addon/",
    "addon/__init__.py",
    "core/",
    "core/__init__.py",
    "core/lut/",
    "node_groups/",
    "luts/",
    "assets/rt_lookdev_presets.blend",
    "assets/blender_assets.cats.txt",
)
#: Top-level names that must never be shipped.
FORBIDDEN_TOP_LEVEL = ("tests", "scripts", "validation", "docs", "out", "dist", ".ci", ".git", ".venv",
                       "pyproject.toml")


class BuildError(RuntimeError):
    """A build step failed; the message says which and why."""


def log(message: str) -> None:
    print(f"build_extension: {message}", flush=True)


def read_manifest(path: Path = MANIFEST) -> dict:
    if not path.is_file():
        raise BuildError(f"manifest not found: {path}")
    with path.open("rb") as fh:
        return tomllib.load(fh)


def default_zip_name(manifest: dict) -> str:
    return f"{manifest['id']}-{manifest['version']}.zip"


def find_extension_cli() -> Path:
    """Path of ``bl_pkg/cli/blender_ext.py`` inside the installed ``bpy`` wheel.

    Found without importing bpy (importing it takes ~0.5 s and loads a whole Blender).
    """
    spec = importlib.util.find_spec("bpy")
    if spec is None or not spec.submodule_search_locations:
        raise BuildError(
            f"the bpy module is not installed for {sys.executable}; "
            "run `source scripts/env.sh` (creates .venv with bpy==5.0.1) and use its python"
        )
    bpy_dir = Path(next(iter(spec.submodule_search_locations)))
    candidates = sorted(bpy_dir.glob("*/scripts/addons_core/bl_pkg/cli/blender_ext.py"))
    if not candidates:
        raise BuildError(f"blender_ext.py not found under {bpy_dir}/<version>/scripts/addons_core/bl_pkg/cli/")
    return candidates[-1]


def run_cli(cli: Path, *args: str) -> str:
    """Run ``blender_ext.py <args>`` with this interpreter; raise BuildError on failure."""
    cmd = [sys.executable, str(cli), *args]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    output = (proc.stdout + proc.stderr).strip()
    if proc.returncode != 0:
        raise BuildError(f"`blender_ext.py {' '.join(args)}` failed (exit {proc.returncode}):\n{output}")
    return output


def check_luts() -> list:
    """Require every LUT the add-on reads to be baked and current; return the statuses."""
    try:
        from ...core.lut import catalog
    except ImportError as ex:
        raise BuildError(
            f"cannot import the LUT catalog ({ex}); run with the project venv: "
            "`source scripts/env.sh && python scripts/build_extension.py`"
        ) from ex

    lut_dir = catalog.default_lut_dir()
    statuses = list(catalog.lut_status(lut_dir))
    if not statuses:
        raise BuildError(f"the LUT catalog lists no tables (looked in {lut_dir})")
    bad = [s for s in statuses if s.state != "ok"]
    if bad:
        lines = "\n".join(f"  {s.name}: {s.state}" + (f" ({s.message})" if s.message else "") for s in bad)
        raise BuildError(
            f"{len(bad)} of {len(statuses)} LUT tables in {lut_dir} are not ready:\n{lines}\n"
            "Bake them first with `python scripts/bake_luts.py`, then build again."
        )
    return statuses


def zip_names(zip_path: Path) -> list[str]:
    with zipfile.ZipFile(zip_path) as zf:
        return zf.namelist()


def check_zip_contents(names: list[str], lut_files: list[str] = ()) -> None:
    """Raise BuildError unless ``names`` holds the run-time files and no development files."""
    files = [n for n in names if not n.endswith("/")]
    problems = []
    for entry in REQUIRED_ENTRIES:
        if entry.endswith("/"):
            if not any(f.startswith(entry) for f in files):
                problems.append(f"missing: no files under {entry}")
        elif entry not in files:
            problems.append(f"missing: {entry}")
    if not any(PurePosixPath(f).match("luts/*.exr") for f in files):
        problems.append("missing: no luts/*.exr")
    for lut in lut_files:
        if lut not in files:
            problems.append(f"missing LUT: {lut}")
    for name in files:
        parts = PurePosixPath(name).parts
        if parts[0] in FORBIDDEN_TOP_LEVEL:
            problems.append(f"should not be shipped: {name}")
        elif "__pycache__" in parts or name.endswith(".pyc"):
            problems.append(f"should not be shipped: {name}")
    if problems:
        raise BuildError("bad zip contents:\n  " + "\n  ".join(problems))


def build(output_dir: Path = DEFAULT_OUTPUT_DIR) -> Path:
    """Check LUTs, validate, build and check the zip; return its path."""
    manifest = read_manifest()
    log(f"manifest: {manifest['id']} {manifest['version']} ({MANIFEST})")

    cli = find_extension_cli()
    log(f"extension tool: {cli}")

    statuses = check_luts()
    lut_files: list[str] = []
    for s in statuses:
        try:
            lut_files.append(Path(s.path).resolve().relative_to(REPO_ROOT).as_posix())
        except ValueError:
            raise BuildError(f"LUT {s.name} is outside the repository: {s.path}") from None
    log(f"LUTs: all {len(statuses)} tables ok ({', '.join(s.name for s in statuses)})")

    run_cli(cli, "validate", str(REPO_ROOT))
    log(f"validated source tree {REPO_ROOT}")

    output_dir = Path(output_dir).resolve()
    output_dir.mkdir(parents=True, exist_ok=True)  # blender_ext.py fails if it is missing
    zip_path = output_dir / default_zip_name(manifest)
    run_cli(cli, "build", "--source-dir", str(REPO_ROOT), "--output-dir", str(output_dir))
    if not zip_path.is_file():
        raise BuildError(f"build reported success but {zip_path} does not exist")
    log(f"built {zip_path} ({zip_path.stat().st_size} bytes)")

    run_cli(cli, "validate", str(zip_path))
    log(f"validated {zip_path.name}")

    names = zip_names(zip_path)
    print(f"contents of {zip_path.name} ({len(names)} entries):")
    for name in names:
        print(f"  {name}")
    check_zip_contents(names, lut_files)
    log("zip contents ok: run-time files present; tests/, scripts/, docs/, dot files absent")
    return zip_path


def parse_args(argv: list[str]) -> argparse.Namespace:
    """The options of scripts/build_extension.py parsed from ``argv``."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--output-dir",
        type=Path,
        default=DEFAULT_OUTPUT_DIR,
        help=f"where to write the zip (default: {DEFAULT_OUTPUT_DIR.relative_to(REPO_ROOT)}/)",
    )
    return parser.parse_args(argv)


def run(args: argparse.Namespace) -> dict:
    """``build(args.output_dir)``; a BuildError is printed to stderr.  Returns {"passed", "zip"}."""
    try:
        zip_path = build(args.output_dir)
    except BuildError as ex:
        print(f"build_extension: ERROR: {ex}", file=sys.stderr)
        return {"passed": False, "zip": None}
    return {"passed": True, "zip": zip_path}
