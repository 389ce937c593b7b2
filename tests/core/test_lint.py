"""Static checks with pyflakes (pinned in requirements.lock): no unused imports or variables, no
undefined names, in every module of the project.

Lines marked ``# noqa`` are skipped (a deliberate import for its side effect).  Blender property
annotations (``name: StringProperty(name="LUT Directory")``) are not type hints, and
pyflakes reads their strings as forward annotations; messages on such lines are skipped.
"""
from __future__ import annotations

import ast
from pathlib import Path

import pytest

pyflakes_api = pytest.importorskip("pyflakes.api")
from pyflakes import messages, reporter  # noqa: E402

REPO = Path(__file__).resolve().parents[2]
FOLDERS = ("core", "addon", "node_groups", "validation", "scripts", "tests")


class _Collect(reporter.Reporter):
    def __init__(self):
        super().__init__(None, None)
        self.found = []

    def flake(self, message):
        self.found.append(message)

    def syntaxError(self, filename, msg, lineno, offset, text):
        self.found.append(f"{filename}:{lineno}: syntax error {msg}")

    def unexpectedError(self, filename, msg):
        self.found.append(f"{filename}: {msg}")


def _property_lines(tree):
    """Line numbers of class-level annotations that are calls (``x: FloatProperty(...)``)."""
    lines = set()
    for cls in (n for n in ast.walk(tree) if isinstance(n, ast.ClassDef)):
        for item in cls.body:
            if isinstance(item, ast.AnnAssign) and isinstance(item.annotation, ast.Call):
                lines.update(range(item.lineno, item.end_lineno + 1))
    return lines


def test_pyflakes_finds_nothing():
    problems = []
    for folder in FOLDERS:
        for path in sorted((REPO / folder).rglob("*.py")):
            source = path.read_text()
            collect = _Collect()
            pyflakes_api.check(source, str(path.relative_to(REPO)), collect)
            skip = _property_lines(ast.parse(source))
            lines = source.splitlines()
            annotations = (messages.ForwardAnnotationSyntaxError, messages.UndefinedName)
            problems += [str(m) for m in collect.found
                         if isinstance(m, str) or not ((isinstance(m, annotations) and m.lineno in skip)
                                                       or "# noqa" in lines[m.lineno - 1])]
    assert not problems, "\n".join(problems)
