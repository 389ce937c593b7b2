"""The standalone renderer on scene descriptions written without Blender (validation/benchmarks/realtime_benchmark's
frame-filling sphere): the scene description round-trips and refuses what it cannot read, the camera
puts world points on the pixels Blender's would, and the drawn image is the material function
evaluated by numpy at the rasterised points.  (Against Cycles: tests/blender/test_realtime_scene.py.)"""
from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from rt_lookdev.core.export import scene as scene_io
from rt_lookdev.core.materials.rt_lit_interface import Features
from rt_lookdev.validation.benchmarks import realtime_benchmark as bench

pytestmark = pytest.mark.glsl

SIZE = (64, 36)


@pytest.fixture(scope="module")
def sphere_scene(tmp_path_factory, lut_dir):
    folder = tmp_path_factory.mktemp("rt") / "sphere"
    return bench.write_scene(folder, Features("kulla_conty", "wrapped", sheen=True, cloth=True), True, 4, SIZE, lut_dir)


def test_scene_description_round_trips(sphere_scene):
    again = scene_io.read(sphere_scene.folder)
    assert again.to_json() == sphere_scene.to_json()
    assert again.light_kinds == ("quad", "disk", "point", "spot")
    (pos, nrm), = again.geometry().values()
    assert pos.dtype == np.float32 and pos.shape == nrm.shape and len(pos) % 3 == 0
    materials = again.build_materials()
    assert set(materials) == {"benchmark"}
    tables = again.table_set()
    for name in materials["benchmark"].table_names():
        assert tables[name].require_data().shape[2] == 4


@pytest.mark.parametrize("damage, message", [
    (lambda f: (f / "tables" / "ltc_ggx_inv.exr").unlink(), "ltc_ggx_inv.exr is missing"),
    (lambda f: (f / "scene.json").write_text("{not json"), "cannot be read"),
    (lambda f: _edit(f, version=99), "version 99 is not supported"),
    (lambda f: _edit(f, lights=[{"name": "Area", "kind": "tube", "parameters": {}}]), "kind 'tube'"),
    (lambda f: _edit(f, objects=[{"name": "x", "material": "nope", "key": "0"}]), "material 'nope'"),
    (lambda f: _edit(f, camera={"matrix_world": np.eye(4).tolist(), "type": "PANO"}), "PANO"),
    (lambda f: (f / "geometry.npz").write_bytes(b"garbage"), "cannot read the geometry"),
])
def test_a_damaged_export_is_refused_naming_what(sphere_scene, tmp_path, damage, message):
    folder = tmp_path / "copy"
    shutil.copytree(sphere_scene.folder, folder)
    damage(folder)
    with pytest.raises(scene_io.SceneDescriptionError, match=message.replace("(", r"\(")):
        desc = scene_io.read(folder)
        desc.geometry()
        desc.table_set()


def _edit(folder, **changes):
    data = json.loads((folder / "scene.json").read_text())
    data.update(changes)
    (folder / "scene.json").write_text(json.dumps(data))


def test_a_failed_export_leaves_the_previous_one(sphere_scene, tmp_path):
    folder = tmp_path / "export"
    shutil.copytree(sphere_scene.folder, folder)
    before = (folder / "scene.json").read_text()
    bad = scene_io.read(folder)
    with pytest.raises(scene_io.SceneDescriptionError, match="does not exist"):
        scene_io.write(folder, bad, {"0": bad.geometry()["sphere"]}, {"ltc_ggx_inv.exr": tmp_path / "missing.exr"})
    assert (folder / "scene.json").read_text() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["copy", "export"] or \
        sorted(p.name for p in tmp_path.iterdir()) == ["export"]


def test_camera_projects_like_blender():
    """Orthographic and perspective cameras, landscape and portrait, with shift: a world point projects to
    the NDC Blender's camera frame gives it."""
    rng = np.random.default_rng(3)
    for cam_type in ("ORTHO", "PERSP"):
        for resolution in ((200, 100), (100, 250)):
            m = np.eye(4)
            m[:3, 3] = [0.5, -1.0, 2.0]
            cam = scene_io.Camera(m.tolist(), cam_type, ortho_scale=3.0, angle=0.9, shift=(0.1, -0.05),
                                  resolution=resolution)
            hw, hh = cam.frame()
            assert max(hw, hh) == pytest.approx(1.5 if cam_type == "ORTHO" else np.tan(0.45))
            assert hw / hh == pytest.approx(resolution[0] / resolution[1])
            x, y, d = rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(1, 5)
            # a point at view-space (X, Y, -d): Blender's frame puts it at ((X / s - shift) / half extent)
            s = 1.0 if cam_type == "ORTHO" else d
            side = 2 * max(hw, hh)
            point = np.array([x * s, y * s, -d]) + m[:3, 3]
            clip = cam.view_projection() @ np.append(point, 1.0)
            ndc = clip[:2] / clip[3]
            assert ndc == pytest.approx([(x - 0.1 * side) / hw, (y + 0.05 * side) / hh])


def _rasterise_orthographic(cam, positions, normals, size):
    """For each pixel centre of an orthographic camera looking along +Y (the benchmark's): the nearest
    triangle's interpolated position and normal (barycentric, as a rasteriser interpolates), and a mask of
    pixels whose centre lies well inside a triangle (not within 1e-4 of an edge)."""
    w, h = size
    hw, hh = cam.frame()
    ox, oz = cam.position[0], cam.position[2]
    X, Z = np.meshgrid(ox + ((np.arange(w) + 0.5) / w * 2 - 1) * hw, oz + (1 - (np.arange(h) + 0.5) / h * 2) * hh)
    q = np.stack([X.ravel(), Z.ravel()], -1)[:, None, :]               # (P, 1, 2)
    tri = positions.reshape(-1, 3, 3).astype(np.float64)
    nrm = normals.reshape(-1, 3, 3).astype(np.float64)
    a, b, c = (tri[None, :, k][..., [0, 2]] for k in range(3))
    det = (b - a)[..., 0] * (c - a)[..., 1] - (b - a)[..., 1] * (c - a)[..., 0]
    d = q - a
    l1 = (d[..., 0] * (c - a)[..., 1] - d[..., 1] * (c - a)[..., 0]) / np.where(det == 0, np.inf, det)
    l2 = ((b - a)[..., 0] * d[..., 1] - (b - a)[..., 1] * d[..., 0]) / np.where(det == 0, np.inf, det)
    l0 = 1 - l1 - l2
    lam = np.stack([l0, l1, l2], -1)                                    # (P, T, 3)
    inside = (lam >= 0).all(-1)
    depth = np.where(inside, np.einsum("ptk,tk->pt", lam, tri[..., 1]), np.inf)
    best = depth.argmin(1)
    pick = lam[np.arange(len(best)), best]
    pos = np.einsum("pk,pkc->pc", pick, tri[best])
    n = np.einsum("pk,pkc->pc", pick, nrm[best])
    clear = pick.min(-1) > 1e-4
    return pos.reshape(h, w, 3), n.reshape(h, w, 3), clear.reshape(h, w)


def test_render_is_the_material_function_at_the_rasterised_points(gl, sphere_scene):
    """Each pixel equals the numpy evaluation (float32) of the same material function at the point and
    normal the pixel centre sees on the exported triangles (interpolated as a rasteriser does)."""
    from rt_lookdev.validation.harness.glsl_runner import conformance
    from rt_lookdev.validation.harness.realtime_render import RealtimeRenderer

    with RealtimeRenderer(sphere_scene) as renderer:
        image = renderer.render()
    assert np.isfinite(image).all() and (image.max(-1) > 0).all()
    material = sphere_scene.build_materials()["benchmark"]
    cam = sphere_scene.camera
    (positions, normals), = sphere_scene.geometry().values()
    p, n, clear = _rasterise_orthographic(cam, positions, normals, SIZE)
    values = {**{k: np.asarray(v, np.float64) for k, v in sphere_scene.materials["benchmark"].inputs.items()},
              "Position": p, "Geometry Normal": n, "Incoming": np.broadcast_to(-cam.forward, p.shape)}
    for names, light in zip(material.light_inputs, sphere_scene.lights):
        values.update({name: light.parameters[param] for param, name in names.items()})
    values.update({name: np.asarray(sphere_scene.world.parameters[param]) for param, name in material.world_inputs.items()})
    tables = sphere_scene.table_set()
    ref32 = material.evaluate(values, tables, dtype=np.float32)["Radiance"]
    ref64 = material.evaluate(values, tables, dtype=np.float64)["Radiance"]
    c = conformance(image[clear], ref32[clear], ref64[clear])
    rel = np.abs(image[clear] - ref32[clear]) / np.maximum(np.abs(ref32[clear]), 1e-2)
    print(f"{clear.sum()} of {clear.size} pixels: {c.summary()}; median {np.median(rel):.2e}")
    # the rasteriser's interpolation differs from this one by float32 rounding only
    assert c.ok, c.summary()
    assert np.median(rel) <= 1e-6 and clear.mean() > 0.9


def test_power_scales_the_image_and_lights_add_up(gl, tmp_path, lut_dir):
    """Doubling a light's power doubles its pixels; uniforms reach each light of an array by its index."""
    from rt_lookdev.validation.harness.realtime_render import RealtimeRenderer

    desc = bench.write_scene(tmp_path / "quad", Features("single", "lambert"), False, 4, SIZE, lut_dir)
    with RealtimeRenderer(desc) as r:
        base = r.render().astype(np.float64)
    for light in desc.lights:
        if "Power" in light.parameters:
            light.parameters["Power"] *= 2.0
        else:
            light.parameters["Strength"] *= 2.0
    with RealtimeRenderer(desc) as r:
        doubled = r.render().astype(np.float64)
    lit = base > 1e-3
    np.testing.assert_allclose(doubled[lit], 2.0 * base[lit], rtol=2e-6)


def test_unsupported_features_and_refused_shaders_are_named(gl, sphere_scene, tmp_path, monkeypatch):
    from rt_lookdev.core.materials import rt_lit_shader
    from rt_lookdev.validation.harness import glsl_runner
    from rt_lookdev.validation.harness.realtime_render import RealtimeRenderer

    folder = tmp_path / "copy"
    shutil.copytree(sphere_scene.folder, folder)
    data = json.loads((folder / "scene.json").read_text())
    data["materials"]["benchmark"]["features"]["specular"] = "phong"
    (folder / "scene.json").write_text(json.dumps(data))
    with pytest.raises(scene_io.SceneDescriptionError, match="material 'benchmark'.*specular model"):
        scene_io.read(folder).build_materials()

    real = rt_lit_shader.material_shader

    def broken(material, dialect="glsl450", precise=True):
        shader = real(material, dialect, precise)
        shader.fragment = shader.fragment.replace("void main()\n{", "void main()\n{\n    float broken = missing_name;", 1)
        return shader

    monkeypatch.setattr(rt_lit_shader, "material_shader", broken)
    with pytest.raises(glsl_runner.ShaderCompileError) as err:
        RealtimeRenderer(sphere_scene)
    message = str(err.value)
    assert "RT Lit (kulla-conty, wrapped, sheen, cloth; 4 lights; env_benchmark)" in message
    assert "missing_name" in message and "float broken = missing_name;" in message
