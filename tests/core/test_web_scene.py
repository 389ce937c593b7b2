"""The web bundle of a scene description (core/export/web_scene.py): what the viewer (engines/viewer) reads is the
standalone renderer's own program, tables, triangles and uniform values, written as files a static page fetches."""
import json

import numpy as np
import pytest

from rt_lookdev.core.export import web_scene
from rt_lookdev.core.materials import rt_lit_shader
from rt_lookdev.core.materials.rt_lit_interface import Features
from rt_lookdev.validation.benchmarks import realtime_benchmark as bench


@pytest.fixture(scope="module")
def sphere(tmp_path_factory, lut_dir):
    folder = tmp_path_factory.mktemp("web")
    desc = bench.write_scene(folder / "sphere", Features("turquin", "cod"), True, 4, (32, 18), lut_dir)
    return desc, web_scene.write_web(folder / "web", desc), folder / "web"


def test_the_bundle_holds_the_renderers_program_tables_and_values(sphere):
    desc, draw, folder = sphere
    assert json.loads((folder / "draw.json").read_text()) == json.loads(json.dumps(draw))
    assert draw["format"] == "rt-lookdev-web" and draw["resolution"] == [32, 18]
    (program,) = draw["programs"]
    material = desc.build_materials()["benchmark"]
    shader = rt_lit_shader.material_shader(material, "glsl300es", precise=False)
    assert (folder / program["fragment"]).read_text() == shader.fragment
    assert (folder / program["vertex"]).read_text().startswith("#version 300 es")
    tables = desc.table_set()
    for table, info in draw["tables"].items():
        data = np.fromfile(folder / info["file"], "<f4").reshape(info["height"], info["width"], 4)
        source = np.asarray(tables[table].require_data(), np.float32)
        assert np.array_equal(data[..., :source.shape[2]], source), table
    (obj,) = draw["objects"]
    expected = shader.uniform_values(desc.materials["benchmark"].inputs, desc.objects[0].light_values(desc.lights),
                                     desc.world.parameters)
    assert json.loads(json.dumps(expected)) == json.loads(json.dumps(obj["uniforms"]))
    positions, normals = next(iter(desc.geometry().values()))
    geometry = np.fromfile(folder / "geometry.bin", "<f4").reshape(-1, 6)
    assert obj["first"] == 0 and obj["count"] == len(positions) == len(geometry)
    assert np.array_equal(geometry[:, :3], positions) and np.array_equal(geometry[:, 3:], normals)


def test_the_camera_is_the_renderers(sphere):
    desc, draw, _ = sphere
    view = np.array(draw["camera"]["view"]).reshape(4, 4).T           # column-major as uploaded
    projection = np.array(draw["camera"]["projection"]).reshape(4, 4).T
    assert np.allclose(projection @ view, desc.camera.view_projection(), rtol=0, atol=1e-12)
    assert [light["uniform"] for light in draw["lights"]] == [
        "u_quad_lights[0].power", "u_disk_lights[0].power", "u_point_lights[0].power", "u_spot_lights[0].power"]
