"""Compile shader text with glslang's reference compiler (Debian ``glslang-tools``: glslangValidator).

``compile_source(source, stage, dialect)`` writes the source to a temporary file and runs
``glslangValidator`` on it -- GLSL 4.50 and GLSL ES 3.00 checked against their specifications, HLSL
(shader model 5+) compiled to SPIR-V through glslang's HLSL front end (``-D -V -e main``) -- and raises
``GlslangError`` with the compiler's messages and, for each line they name, that line of the source.
"""
from __future__ import annotations

import re
import shutil
import subprocess
import tempfile
from pathlib import Path

_SUFFIX = {"frag": "frag", "vert": "vert"}


class GlslangError(RuntimeError):
    """glslang refused a shader: the message holds its log and the source lines it names."""


def executable():
    """The path of glslangValidator, or None."""
    return shutil.which("glslangValidator")


def _named_lines(log, source):
    lines = source.splitlines()
    out = []
    for match in re.finditer(r"ERROR: [^:\n]*:(\d+):", log):
        n = int(match.group(1))
        if 1 <= n <= len(lines):
            out.append(f"{n:5d}  {lines[n - 1]}")
    return out


def compile_source(source, stage="frag", dialect="glsl450", timeout=120):
    """Compile ``source`` for ``stage`` ("frag", "vert") in ``dialect`` ("glsl450", "glsl300es", "hlsl");
    returns glslang's output.  Raises GlslangError (with the failing source lines) or RuntimeError when
    glslangValidator is not installed."""
    exe = executable()
    if exe is None:
        raise RuntimeError("glslangValidator not found: install Debian's glslang-tools")
    with tempfile.TemporaryDirectory(prefix="rtl-glslang-") as tmp:
        if dialect == "hlsl":
            path = Path(tmp) / "shader.hlsl"
            cmd = [exe, "-D", "-V", "-S", stage, "-e", "main", str(path), "-o", str(Path(tmp) / "shader.spv")]
        else:
            path = Path(tmp) / f"shader.{_SUFFIX[stage]}"
            cmd = [exe, str(path)]
        path.write_text(source)
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    log = (proc.stdout + proc.stderr).strip()
    if proc.returncode != 0:
        named = _named_lines(log, source)
        raise GlslangError(f"glslang ({dialect}, {stage}) refused the shader:\n{log}"
                           + ("\n--- the lines it names ---\n" + "\n".join(named) if named else ""))
    return log
