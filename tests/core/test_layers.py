"""The architecture's rules, read from the source (docs/architecture.md, "Layers"):

- imports go downwards only: core/ir < shading_ops, conventions < core/lut < core techniques <
  core/materials < core/export < node_groups < addon < validation (scripts/ and tests/ sit on top); inside
  validation: harness < checks < benchmarks < main_job, and tools/ (packaging, the release matrix) is imported by
  none of them;
- no import cycle among the project's modules (imports inside functions count);
- no private name (a leading underscore) crosses a module: ``from x import _y`` or ``x._y`` on an imported module;
- every attribute taken from an imported project module exists there (what a moved function leaves behind);
- no file in validation/ is over 600 lines;
- no module of core/ imports bpy (or any other Blender module);
- no sys.path edits in scripts/ or tests/ (the package is installed in editable mode: pyproject.toml);
- every file name is used once in the tree;
- every file in scripts/ is a thin entry point.
"""
from __future__ import annotations

import ast
import functools
import re
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
PACKAGES = ("core", "node_groups", "addon", "validation")
BLENDER_MODULES = ("bpy", "bmesh", "mathutils", "gpu", "addon_utils", "_bpy", "bl_ui", "bpy_extras")

#: (layer name, rank, test): a module's layer is the first whose test matches its dotted name.
LAYERS = (
    ("core.ir", 0, lambda m: m == "core.ir" or m.startswith("core.ir.")),
    ("core ops", 1, lambda m: m in ("core.shading_ops", "core.conventions")),
    ("core.lut", 2, lambda m: m == "core.lut" or m.startswith("core.lut.")),
    ("core.materials", 4, lambda m: m == "core.materials" or m.startswith("core.materials.")),
    ("core.export", 5, lambda m: m == "core.export" or m.startswith("core.export.")),
    ("core techniques", 3, lambda m: m == "core" or m.startswith("core.")),
    ("node_groups", 6, lambda m: m.split(".")[0] == "node_groups"),
    ("addon", 7, lambda m: m.split(".")[0] == "addon"),
    ("validation.harness", 8, lambda m: m.startswith("validation.harness")),
    ("validation.tools", 8, lambda m: m.startswith("validation.tools")),
    ("validation.checks", 9, lambda m: m.startswith("validation.checks")),
    ("validation.benchmarks", 10, lambda m: m.startswith("validation.benchmarks")),
    ("validation.main_job", 11, lambda m: m == "validation.main_job"),
    ("validation", 8, lambda m: m.split(".")[0] == "validation"),
)


def layer_of(module):
    for name, rank, test in LAYERS:
        if test(module):
            return name, rank
    raise ValueError(f"{module} is in no layer")


def _module_name(path):
    parts = list(path.relative_to(REPO).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def project_modules():
    return [p for pkg in PACKAGES for p in sorted((REPO / pkg).rglob("*.py"))]


def imports_of(path, source=None):
    """(project modules imported, other top-level modules imported) by one file (its ``source``, or
    the file's text)."""
    tree = ast.parse(path.read_text() if source is None else source, str(path))
    name = _module_name(path)
    package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
    project, external = set(), set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.level:
            base = package[:len(package) - node.level + 1]
            target = ".".join(base + ([node.module] if node.module else []))
            if node.module is None:
                project.update(f"{target}.{a.name}" if target else a.name for a in node.names)
            else:
                project.add(target)
        elif isinstance(node, ast.ImportFrom):
            (project if node.module.split(".")[0] == "rt_lookdev" else external).add(node.module)
        elif isinstance(node, ast.Import):
            for alias in node.names:
                (project if alias.name.split(".")[0] == "rt_lookdev" else external).add(alias.name)
    project = {m.removeprefix("rt_lookdev.") for m in project if m not in ("rt_lookdev", "")}
    return project, {m.split(".")[0] for m in external}


def _is_module(name):
    base = REPO.joinpath(*name.split("."))
    return base.with_suffix(".py").is_file() or (base / "__init__.py").is_file()


def upward_imports(path, source=None):
    """The imports of one file that climb a layer."""
    me = _module_name(path)
    my_layer, my_rank = layer_of(me)
    found = []
    for target in imports_of(path, source)[0]:
        target = target if _is_module(target) else target.rsplit(".", 1)[0]   # "from .x import name"
        layer, rank = layer_of(target)
        if rank > my_rank or (layer == "validation.tools" and my_layer != layer):
            found.append(f"{me} ({my_layer}) imports {target} ({layer})")
    return found


def test_imports_go_downwards_only():
    upward = [line for path in project_modules() for line in upward_imports(path)]
    assert not upward, "imports that climb a layer:\n  " + "\n  ".join(sorted(upward))


@pytest.mark.parametrize("where,line", [
    ("core/ir/semantics.py", "from ..materials import rt_lit"),
    ("core/ir/expr.py", "from ..lut import lookup"),
    ("core/lut/lookup.py", "from .. import multiscatter"),
    ("core/materials/surface.py", "from ...addon import materials"),
    ("addon/materials.py", "from ..validation.checks import suite"),
    ("validation/harness/outputs.py", "from ..checks import suite_cases"),
    ("validation/checks/suite.py", "from ..benchmarks import speed_error"),
    ("validation/benchmarks/speed_error.py", "from .. import main_job"),
    ("validation/checks/suite.py", "from ..tools import extension_zip"),
])
def test_the_layer_rule_catches_an_upward_import(where, line):
    """The rule fails on a lower layer importing a higher one (the same files with one import added)."""
    path = REPO / where
    assert not upward_imports(path)
    assert upward_imports(path, path.read_text() + "\n" + line + "\n")


def test_core_imports_no_blender_module():
    offenders = []
    for path in sorted((REPO / "core").rglob("*.py")):
        _, external = imports_of(path)
        bad = external & set(BLENDER_MODULES)
        if bad:
            offenders.append(f"{path.relative_to(REPO)}: {sorted(bad)}")
    assert not offenders, offenders


_SYS_PATH = re.compile(r"\bsys\.path(\.(insert|append|extend)\b|\s*(\[|\+?=))")


@pytest.mark.parametrize("folder", ["scripts", "tests"])
def test_no_sys_path_edits(folder):
    offenders = [str(p.relative_to(REPO)) for p in sorted((REPO / folder).rglob("*.py"))
                 if _SYS_PATH.search(p.read_text())]
    assert not offenders, f"sys.path used in {offenders}; import rt_lookdev (editable install) instead"


def test_file_names_are_unique():
    seen = {}
    for pkg in PACKAGES + ("scripts", "tests"):
        for path in (REPO / pkg).rglob("*.py"):
            if path.name in ("__init__.py", "conftest.py"):
                continue
            seen.setdefault(path.name, []).append(str(path.relative_to(REPO)))
    twice = {name: paths for name, paths in seen.items() if len(paths) > 1}
    assert not twice, twice


def test_scripts_are_thin_entry_points():
    """Entry points only: argument parsing, a call into the package, an exit code (<= 150 lines, no
    function definitions beyond main and its small helpers)."""
    for path in sorted((REPO / "scripts").glob("*.py")):
        text = path.read_text()
        lines = len(text.splitlines())
        assert lines <= 150, f"{path.name}: {lines} lines"
        assert 'if __name__ == "__main__":' in text, path.name
        functions = [n.name for n in ast.walk(ast.parse(text)) if isinstance(n, ast.FunctionDef)]
        assert len(functions) <= 4, (path.name, functions)


def test_the_sys_path_rule_catches_edits():
    edits = (".insert(0, here)", "[:0] = [a]", ".append(x)", " += [x]")       # (joined here, so that this
    for tail in edits:                                                          # file passes its own rule)
        assert _SYS_PATH.search("sys.path" + tail), tail
    assert not _SYS_PATH.search("no sys.path edits in scripts/")


def _resolved_imports(path):
    """(imported module, name taken from it or None, line) for every project import of one file, at any depth
    (inside functions too): ``from pkg import mod`` is the module ``pkg.mod``, ``from mod import name`` the
    module ``mod`` and ``name``."""
    tree = ast.parse(path.read_text(), str(path))
    name = _module_name(path)
    package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package[:len(package) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            elif node.module.split(".")[0] == "rt_lookdev":
                target = node.module.removeprefix("rt_lookdev").lstrip(".")
            else:
                continue
            for alias in node.names:
                sub = f"{target}.{alias.name}" if target else alias.name
                found.append((sub, None, node.lineno) if _is_module(sub) else (target, alias.name, node.lineno))
        elif isinstance(node, ast.Import):
            found.extend((a.name.removeprefix("rt_lookdev").lstrip("."), None, node.lineno)
                         for a in node.names if a.name.split(".")[0] == "rt_lookdev")
    return found


def import_graph():
    """{module: the project modules it imports}, over every module of the packages."""
    modules = {_module_name(p): p for p in project_modules()}
    return {m: {t for t, _, _ in _resolved_imports(p) if t in modules} for m, p in modules.items()}


def import_cycles(graph):
    """The strongly connected components of more than one module (or a module importing itself): Tarjan's
    algorithm, iterative."""
    index, low, on_stack, stack, cycles = {}, {}, set(), [], []
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            v, children = work[-1]
            for w in children:
                if w not in index:
                    index[w] = low[w] = len(index)
                    stack.append(w)
                    on_stack.add(w)
                    work.append((w, iter(sorted(graph[w]))))
                    break
                if w in on_stack:
                    low[v] = min(low[v], index[w])
            else:
                work.pop()
                if work:
                    low[work[-1][0]] = min(low[work[-1][0]], low[v])
                if low[v] == index[v]:
                    component = []
                    while True:
                        w = stack.pop()
                        on_stack.discard(w)
                        component.append(w)
                        if w == v:
                            break
                    if len(component) > 1 or v in graph[v]:
                        cycles.append(sorted(component))
    return cycles


def test_no_import_cycles():
    cycles = import_cycles(import_graph())
    assert not cycles, "import cycles:\n  " + "\n  ".join(" <-> ".join(c) for c in cycles)


def test_the_cycle_finder_finds_cycles():
    assert import_cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert import_cycles({"a": {"a"}}) == [["a"]]
    assert import_cycles({"a": {"b"}, "b": set()}) == []


def _private(name):
    return name.startswith("_") and not name.startswith("__")


def private_names_across_modules(path, source=None):
    """The private names one file takes from another module: ``from x import _y`` and ``m._y`` where ``m`` is a
    name the file imported (a module or anything else taken from a project module)."""
    tree = ast.parse(path.read_text() if source is None else source, str(path))
    me = _module_name(path)
    found = [f"{me}:{line} from {target} import {name}"
             for target, name, line in (_resolved_imports(path) if source is None else ())
             if name and _private(name)]
    if source is not None:
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and node.level:
                found.extend(f"{me}:{node.lineno} from .{node.module} import {a.name}"
                             for a in node.names if _private(a.name))
    imported = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and (node.level or node.module.split(".")[0] == "rt_lookdev"):
            imported.update(a.asname or a.name for a in node.names)
        elif isinstance(node, ast.Import):
            imported.update(a.asname or a.name.split(".")[0] for a in node.names
                            if a.name.split(".")[0] == "rt_lookdev")
    found += [f"{me}:{node.lineno} {node.value.id}.{node.attr}" for node in ast.walk(tree)
              if isinstance(node, ast.Attribute) and _private(node.attr) and isinstance(node.value, ast.Name)
              and node.value.id in imported]
    return found


#: Private names still taken across modules: the LUT bake sources' (core/lut_bake.py is one: renaming a name
#: there changes its code hash and makes the shipped tables stale).  The list may only shrink.
PRIVATE_ACROSS_MODULES_ALLOWED = ("lut_bake._metadata",)


def test_no_private_name_crosses_a_module():
    """How it counts: every ``from x import _y`` of a project module, and every attribute ``m._y`` where ``m`` is
    a name bound by an import from the project, in core/, node_groups/, addon/ and validation/ (dunder names are
    not private)."""
    found = [line for path in project_modules() for line in private_names_across_modules(path)
             if not line.endswith(PRIVATE_ACROSS_MODULES_ALLOWED)]
    assert not found, "private names used across modules:\n  " + "\n  ".join(found)


def test_the_private_name_rule_catches_one():
    path = REPO / "validation" / "checks" / "suite.py"
    assert not private_names_across_modules(path)
    assert private_names_across_modules(path, path.read_text() + "\nfrom .suite_cases import _x\n")
    assert private_names_across_modules(path, path.read_text() + "\ny = outputs._fmt_csv\n")


VALIDATION_MAX_LINES = 600


def test_validation_files_are_at_most_600_lines():
    """A validation module that grows past this is split by concern (scenes, renders, metrics, report, driver)."""
    long = {str(p.relative_to(REPO)): n for p in sorted((REPO / "validation").rglob("*.py"))
            if (n := len(p.read_text().splitlines())) > VALIDATION_MAX_LINES}
    assert not long, long


@functools.lru_cache(maxsize=None)
def _top_level_names(module):
    """The names a project module defines or imports at its top level (and, for a package, its submodules)."""
    base = REPO.joinpath(*module.split("."))
    path = base.with_suffix(".py") if base.with_suffix(".py").is_file() else base / "__init__.py"
    tree = ast.parse(path.read_text(), str(path))
    names = set()
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            names.update(a.asname or a.name.split(".")[0] for a in node.names)
        else:
            for sub in ast.walk(node):
                if isinstance(sub, ast.Name) and isinstance(sub.ctx, ast.Store):
                    names.add(sub.id)
                elif isinstance(sub, (ast.FunctionDef, ast.ClassDef)):
                    names.add(sub.name)
    if path.name == "__init__.py":
        names.update(p.stem for p in path.parent.glob("*.py"))
        names.update(p.name for p in path.parent.iterdir() if p.is_dir())
    return names


def missing_module_attributes(path):
    """``m.name`` where ``m`` is an imported project module that has no ``name`` (a function moved away, a
    misspelling): what a refactoring leaves behind and only a run would find.  Names also bound locally (a
    parameter or variable shadowing the module) are not judged."""
    tree = ast.parse(path.read_text(), str(path))
    in_package = path.relative_to(REPO).parts[0] in PACKAGES
    me = _module_name(path) if in_package else ""
    package = (me.split(".") if path.name == "__init__.py" else me.split(".")[:-1]) if in_package else []
    modules = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            if node.level and in_package:
                base = package[:len(package) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            elif not node.level and node.module and node.module.split(".")[0] == "rt_lookdev":
                target = node.module.removeprefix("rt_lookdev").lstrip(".")
            else:
                continue
            for alias in node.names:
                sub = f"{target}.{alias.name}" if target else alias.name
                if _is_module(sub):
                    modules[alias.asname or alias.name] = sub
        elif isinstance(node, ast.Import):
            modules.update({a.asname: a.name.removeprefix("rt_lookdev.") for a in node.names
                            if a.name.startswith("rt_lookdev.") and a.asname})
    bound = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Store)}
    bound |= {n.arg for n in ast.walk(tree) if isinstance(n, ast.arg)}
    return [f"{path.relative_to(REPO)}:{n.lineno} {n.value.id}.{n.attr}" for n in ast.walk(tree)
            if isinstance(n, ast.Attribute) and isinstance(n.value, ast.Name) and n.value.id in modules
            and n.value.id not in bound and n.attr not in _top_level_names(modules[n.value.id])]


def test_attributes_taken_from_project_modules_exist():
    paths = project_modules() + sorted((REPO / "scripts").glob("*.py")) + sorted((REPO / "tests").rglob("*.py"))
    missing = [line for path in paths for line in missing_module_attributes(path)]
    assert not missing, "attributes that the imported module lacks:\n  " + "\n  ".join(missing)
