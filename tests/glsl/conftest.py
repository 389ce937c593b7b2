"""GLSL backend tests: they run emitted shaders on a headless OpenGL 4.5 context (EGL; Mesa's llvmpipe on
a CPU machine) and compile them with glslang.  Where neither can run here, they skip saying why; under CI
(CI=true, where .ci/run installs both) they fail instead."""
import os

import pytest


def _unavailable(why):
    if os.environ.get("CI", "").lower() == "true":
        pytest.fail(f"{why} (CI installs it: .ci/run)")
    pytest.skip(why)


@pytest.fixture(scope="session")
def gl():
    from rt_lookdev.validation.harness import glsl_runner

    ok, why = glsl_runner.available()
    if not ok:
        _unavailable(why)
    return glsl_runner.GlslRunner()


@pytest.fixture(scope="session")
def glslang_path():
    from rt_lookdev.validation.harness import glslang

    path = glslang.executable()
    if path is None:
        _unavailable("glslangValidator not found (Debian package glslang-tools)")
    return path
