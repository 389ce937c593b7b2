"""The standalone real-time renderer: draws an exported scene description (core/export/scene.py) with the
emitted RT Lit shaders (core/materials/rt_lit_shader.py) on OpenGL 4.5 -- no Blender.

    renderer = RealtimeRenderer(scene_description)        # compiles one program per feature set
    image = renderer.render()                             # (H, W, 3) float32, row 0 at the top

Each object is drawn as world-space triangles (identity model matrix) with the camera's view projection,
a float32 RGBA colour target and a 32-bit depth buffer, one sample per pixel at the pixel centre (as
the measurement renders of Cycles: validation/harness/render_setup.py); the background is 0.  Table textures
are RGBA32F, read by the shaders with exact texel fetches.  ``timings`` holds the compile and the
per-frame times (``frame_seconds``: draw + finish, read-back excluded).
"""
from __future__ import annotations

import time

import numpy as np

from ...core.materials import rt_lit_shader
from ...core.materials.rt_lit_interface import Features
from . import glsl_runner


class RealtimeRenderer:
    """Programs, textures and vertex buffers of one scene on the headless OpenGL context."""

    def __init__(self, scene, precise=True, resolution=None, ctx=None):
        self.ctx = ctx or glsl_runner.context()
        self.scene = scene
        self.resolution = tuple(resolution or scene.camera.resolution)
        self.timings = {"trace_seconds": 0.0, "emit_seconds": 0.0, "compile_seconds": 0.0}
        self._resources = []
        t0 = time.perf_counter()
        built = scene.build_materials()
        self.timings["trace_seconds"] = time.perf_counter() - t0
        tables = scene.table_set()
        self.shaders, self.programs = {}, {}
        for name, material in built.items():
            key = Features.from_dict(scene.materials[name].features)
            if key not in self.programs:
                t0 = time.perf_counter()
                shader = rt_lit_shader.material_shader(material, "glsl450", precise)
                self.timings["emit_seconds"] += time.perf_counter() - t0
                t0 = time.perf_counter()
                self.programs[key] = self._program(shader)
                self.timings["compile_seconds"] += time.perf_counter() - t0
                self.shaders[key] = shader
        self.textures = {}
        for shader in self.shaders.values():
            for table, (texture, h, w) in shader.tables.items():
                if table not in self.textures:
                    data = tables[table].require_data()
                    if data.shape[:2] != (h, w):
                        raise ValueError(f"table {table!r} is {data.shape[:2]}, the shader was emitted for {(h, w)}")
                    self.textures[table] = self._keep(glsl_runner.texture(self.ctx, data))
        self.meshes = []
        for obj, (positions, normals) in zip(scene.objects, scene.geometry().values()):
            buf = self._keep(self.ctx.buffer(np.concatenate([positions, normals], axis=1).astype("f4").tobytes()))
            key = Features.from_dict(scene.materials[obj.material].features)
            program = self.programs[key]
            vao = self._keep(self.ctx.vertex_array(
                program, [(buf, "3f 3f", "a_position", "a_normal")]))
            self.meshes.append((obj, key, vao))
        w, h = self.resolution
        self.color = self._keep(self.ctx.texture((w, h), 4, dtype="f4"))
        self.depth = self._keep(self.ctx.depth_texture((w, h)))
        self.fbo = self._keep(self.ctx.framebuffer(color_attachments=[self.color], depth_attachment=self.depth))

    def _keep(self, obj):
        self._resources.append(obj)
        return obj

    def _program(self, shader):
        try:
            return self._keep(self.ctx.program(vertex_shader=shader.vertex, fragment_shader=shader.fragment))
        except Exception as exc:
            raise glsl_runner.ShaderCompileError(
                f"{shader.material.name}: the driver ({glsl_runner.available()[1]}) refused the shader: {exc}\n"
                + glsl_runner.numbered(shader.fragment)) from exc

    def _set_uniforms(self, program, shader, material_values, obj):
        scene = self.scene
        world = scene.world.parameters if scene.world is not None else None
        values = shader.uniform_values(material_values, obj.light_values(scene.lights), world)
        cam = scene.camera
        values.update({"u_camera_position": tuple(cam.position), "u_camera_forward": tuple(cam.forward),
                       "u_camera_orthographic": 1.0 if cam.type == "ORTHO" else 0.0})
        for name, value in values.items():
            if name in program:             # the compiler drops uniforms the material never reads
                program[name].value = value
        vp = cam.view_projection().astype("f4")
        program["u_view_projection"].write(vp.T.tobytes())          # column-major
        if "u_model" in program:
            program["u_model"].write(np.eye(4, dtype="f4").tobytes())
        if "u_normal_matrix" in program:
            program["u_normal_matrix"].write(np.eye(3, dtype="f4").tobytes())
        for unit, (table, (texture, _, _)) in enumerate(shader.tables.items()):
            if texture in program:
                self.textures[table].use(unit)
                program[texture].value = unit

    def draw(self):
        """Draw every object once (no read-back)."""
        ctx = self.ctx
        self.fbo.use()
        ctx.viewport = (0, 0) + self.resolution
        ctx.enable(ctx.DEPTH_TEST)
        ctx.disable(ctx.CULL_FACE)
        self.fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        for obj, key, vao in self.meshes:
            self._set_uniforms(self.programs[key], self.shaders[key], self.scene.materials[obj.material].inputs, obj)
            vao.render(ctx.TRIANGLES)

    def frame_seconds(self):
        """Wall time of one frame: draw every object and wait for the GPU."""
        t0 = time.perf_counter()
        self.draw()
        self.ctx.finish()
        return time.perf_counter() - t0

    def render(self):
        """The frame as (H, W, 3) float32, row 0 at the top (as Blender's renders are read)."""
        self.timings["frame_seconds"] = self.frame_seconds()
        w, h = self.resolution
        raw = np.frombuffer(self.fbo.read(components=4, dtype="f4"), np.float32).reshape(h, w, 4)
        return np.flipud(raw[..., :3]).copy()

    def release(self):
        for obj in reversed(self._resources):
            obj.release()
        self._resources.clear()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.release()
        return False
