"""The real-time benchmark's lights (validation/benchmarks/realtime_benchmark.py): at every light count each light
carries exactly its kind's driver parameters, so the emitted shader's uniforms can be filled (16 lights once died
with KeyError 'Power' when the sphere, spot-with-radius and sun-disk kinds joined)."""
from rt_lookdev.core.lights import SHADING_POINT_INPUTS, light_data
from rt_lookdev.core.materials.rt_lit_interface import LIGHT_KINDS
from rt_lookdev.validation.benchmarks.realtime_benchmark import light_kinds, light_parameters


def test_each_light_has_its_kinds_driver_parameters():
    seen = set()
    for count in (1, 4, 16):
        for k, kind in enumerate(light_kinds(count)):
            expected = {p for p in light_data(kind).input_sockets if p not in SHADING_POINT_INPUTS}
            assert set(light_parameters(kind, k, count)) == expected, (count, kind)
            seen.add(kind)
    assert seen == set(LIGHT_KINDS) - {"quad_spot"}
