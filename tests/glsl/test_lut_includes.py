"""The source files of the LUT export: the GLSL / HLSL includes compile with glslang and their lookup
functions, run on the GPU over half textures, decode to the float32 table's bilinear lookups; the C header
compiles and holds the tables' values."""
from __future__ import annotations

import shutil
import subprocess

import numpy as np
import pytest

from rt_lookdev.core.export import lut_code, luts
from rt_lookdev.core.ir import semantics
from rt_lookdev.core.ir.tables import Table
from rt_lookdev.validation.harness import glslang

pytestmark = pytest.mark.glsl


@pytest.fixture(scope="module")
def export(tmp_path_factory, lut_dir):
    return luts.export(tmp_path_factory.mktemp("inc") / "luts", lut_dir, formats=["c", "glsl", "hlsl"])


@pytest.mark.parametrize("precision", luts.PRECISIONS)
def test_includes_compile(glslang_path, export, precision):
    glsl = (export.folder / f"rtl_luts_{precision}.glsl").read_text()
    hlsl = (export.folder / f"rtl_luts_{precision}.hlsl").read_text()
    for name in ("ggx_one_minus_e", "ggx_one_minus_e_avg", "ltc_ggx_inv", "ltc_sphere"):
        assert f"rtl_lookup_{name}(" in glsl and f"rtl_lookup_{name}(" in hlsl
    main = ("layout(location = 0) out vec4 o;\nvoid main()\n{\n    float r, g, b, a;\n"
            "    rtl_lookup_ltc_ggx_inv(0.5, 0.3, r, g, b, a);\n    o = vec4(r, g, b, a);\n}\n")
    glslang.compile_source("#version 450 core\n" + glsl + main, "frag", "glsl450")
    hmain = ("float4 main() : SV_Target\n{\n    float r, g, b, a;\n    rtl_lookup_ltc_sphere(0.2, 0.4, r, g, b, a);\n"
             "    return float4(r, g, b, a);\n}\n")
    glslang.compile_source(hlsl + hmain, "frag", "hlsl")


def test_half_lookups_decode_on_the_gpu(gl, lut_dir):
    """rtl_lookup_<table> over the half-precision texture (stored values, scaled) returns the float32
    table's bilinear lookup within half's rounding, for every table of the rtl layout."""
    from rt_lookdev.core.lut.lookup import LutSet
    from rt_lookdev.validation.harness.glsl_runner import compare_function

    rng = np.random.default_rng(4)
    for table in luts.layout_tables(LutSet.from_folder(lut_dir), "rtl"):
        stored, scales = luts.encode(table.data, "f16")
        fn = lut_code.lookup_function(table, scales)
        names = list(fn.input_sockets)
        values = {n: rng.uniform(-0.1 if n == "z" else 0.0, 1.0, (32, 32)).astype(np.float32) for n in names}
        textures = {table.name: Table.from_array(table.name, stored.astype(np.float32))}
        report = compare_function(fn, values, textures, runner=gl)
        assert all(c.ok for c in report.values()), {k: c.summary() for k, c in report.items()}
        # and what it computes is the float32 table's lookup, to half precision
        from rt_lookdev.core.ir.numpy_backend import evaluate

        f = fn.function
        got = evaluate(tuple(f.outputs[c] for c in "RGBA"), values, np.float64, textures)
        u, v = lut_code._parameters(table)[1](**{k: values[k].astype(np.float64) for k in names})
        exact = semantics.sample_bilinear(table.data, u, np.broadcast_to(v, np.shape(u)))
        bound = np.max(luts.rounding_bound(table.data, scales, "f16"), axis=(0, 1))
        for c in range(4):
            assert np.abs(got[c] - exact[..., c]).max() <= bound[c] * (1 + 1e-6) + 1e-12, (table.name, c)


def test_c_header_compiles_and_holds_the_values(export, tmp_path, lut_dir):
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        pytest.skip("no C compiler")
    program = tmp_path / "check.c"
    program.write_text('#include <stdio.h>\n#include "rtl_luts_f32.h"\n#include "rtl_luts_f16.h"\n'
                       'int main(void) {\n'
                       '    printf("%d %d %.9g %u %.9g\\n", RTL_LTC_GGX_INV_WIDTH, RTL_GGX_ONE_MINUS_E_AVG_HEIGHT,\n'
                       '           rtl_ltc_ggx_inv_f32[(10 * 64 + 20) * 4 + 2], (unsigned)rtl_ltc_cloth_inv_f16[7],\n'
                       '           rtl_ltc_cloth_inv_f16_decode_scale[1]);\n    return 0;\n}\n')
    exe = tmp_path / "check"
    subprocess.run([cc, "-std=c99", "-Wall", "-Werror", "-I", str(export.folder), str(program), "-o", str(exe)],
                   check=True, capture_output=True, timeout=300)
    out = subprocess.run([str(exe)], capture_output=True, text=True, check=True).stdout.split()
    from rt_lookdev.core.lut.lookup import LutSet

    t = LutSet.from_folder(lut_dir)
    stored, scales = luts.encode(t.array("ltc_cloth_inv"), "f16")
    assert out[:2] == ["64", "1"]
    assert np.float32(out[2]) == t.array("ltc_ggx_inv")[10, 20, 2]          # %.9g round-trips float32
    assert int(out[3]) == int(stored.reshape(-1).view("<u2")[7]) and np.float32(out[4]) == np.float32(scales[1])
