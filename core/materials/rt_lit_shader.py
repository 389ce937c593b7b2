"""The RT Lit material as a shader program: the real-time backend's output for engines.

``material_shader(material, dialect)`` takes a traced material (``rt_lit.build_rt_lit``: a feature set, the
scene's light kinds in order, its baked environment or None) and returns a ``MaterialShader``: a fragment
shader whose ``main`` feeds the emitted material function (core/ir/shader_text.py) from a documented
uniform interface, a vertex shader, and the interface itself (``uniforms``, ``tables``).  Units and
conventions are Blender's, so an engine passes the values Blender shows:

- material: ``uniform float u_metallic; uniform vec3 u_base_color; ...`` -- the RT Lit inputs
  (Principled names, colours linear RGB); the shading normal is the interpolated ``v_normal`` (a normal
  map goes there);
- lights: one uniform array per kind, in the material's light order (``RtlAreaLight u_quad_lights[n]``,
  ``u_disk_lights``, ``RtlPointLight u_point_lights``, ``RtlSpotLight u_spot_lights``, ``RtlSunLight
  u_sun_lights``): world-space location (m), rotation as the unit quaternion (x, y, z, w) of the light
  object's world rotation, world-space scale, power (W) or sun strength (W/m^2), colour, sizes (m),
  spot size (full cone angle, radians) and blend -- Blender's light settings, as core/lights.py reads them;
- world: ``u_world_sh[9]`` (L2 SH radiance, Ramamoorthi & Hanrahan 2001 order, image frame, strength 1),
  ``u_world_strength``, ``u_world_rotation`` (the Mapping node's Euler XYZ, radians) and the
  prefiltered levels' texture;
- occlusion (materials with ``Features.occlusion`` on and a world): ``u_ambient_occlusion``, the engine's ambient
  occlusion at the fragment (1: unoccluded); an engine with an AO buffer binds its read there (a uniform here, so
  the interface stays one set of values per draw);
- camera: ``u_camera_position``, ``u_camera_forward`` (unit view direction) and
  ``u_camera_orthographic`` (1: the view direction is -forward everywhere, as Blender's orthographic
  camera);
- tables: one RGBA32F texture per table (``MaterialShader.tables``; row 0 is v = 0), read with exact texel
  fetches, no sampler state;
- output: ``frag_radiance`` (RGB: outgoing radiance towards the camera, scene-linear; alpha 1).

The vertex shader takes world-space positions and normals (``a_position``, ``a_normal``)
and ``u_model`` / ``u_normal_matrix`` (identity for meshes already in world space) and
``u_view_projection``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import lights
from ..ir import shader_text
from ..ir.expr import FLOAT
from . import rt_lit
from .rt_lit_interface import LIGHT_KINDS, OCCLUSION_SOCKET, RT_LIT_INPUTS, Features

#: Light parameters that are one vector uniform field: prefix -> (field, type, components in field order).
_VECTOR_FIELDS = {
    "Location": ("location", "vec3", "XYZ"),
    "Rotation": ("rotation", "vec4", "XYZW"),       # (x, y, z, w): w is the real part (Blender's W)
    "Scale": ("scale", "vec3", "XYZ"),
    "Color": ("color", "vec3", "RGB"),
}
#: The struct of each base light kind; every kind's, options included, is ``light_struct(kind)``.
_BASE_STRUCTS = {"quad": "RtlAreaLight", "disk": "RtlAreaLight", "point": "RtlPointLight", "spot": "RtlSpotLight",
                 "sun": "RtlSunLight", "quad_spot": "RtlQuadSpotLight", "sphere": "RtlSphereLight",
                 "spot_sphere": "RtlSpotSphereLight", "sun_disk": "RtlSunDiskLight"}
_WORLD_SH = 9


def light_array(kind):
    """The uniform array of lights of ``kind``: "u_quad_lights", "u_quad_cone_range_lights"."""
    return f"u_{lights.kind_identifier(kind)}_lights"


def light_struct(kind):
    """The struct of ``kind``'s lights: its base kind's, with the options' names for a kind with options
    ("RtlAreaLightConeRange": its fields are the base's plus the options' parameters)."""
    base, options = lights.split_kind(kind)
    return _BASE_STRUCTS[base] + "".join(o.capitalize() for o in options)


def light_fields(kind):
    """[(field, type, [(parameter, component)])] of the struct of ``kind``, from its driver parameters
    (core/lights.py ``light_data``); component None for a scalar field."""
    fields, seen = [], {}
    for param in lights.light_data(kind).input_sockets:
        if param in lights.SHADING_POINT_INPUTS:
            continue
        word, _, axis = param.partition(" ")
        if word in _VECTOR_FIELDS and len(axis) == 1:
            name, typ, order = _VECTOR_FIELDS[word]
            if name not in seen:
                seen[name] = (name, typ, [None] * len(order))
                fields.append(seen[name])
            seen[name][2][order.index(axis)] = (param, "xyzw"[order.index(axis)])
        else:
            fields.append((shader_text.identifier(param), "float", [(param, None)]))
    return [(name, typ, list(parts)) for name, typ, parts in fields]


@dataclass(frozen=True)
class Uniform:
    """One uniform of the interface: its declaration's name and type, and what it is."""
    name: str
    type: str
    meaning: str


@dataclass
class MaterialShader:
    """Shader sources of one traced RT Lit material and their interface (module docstring).

    ``bindings``: material-function input -> the shader expression that feeds it; ``uniforms``: the
    interface, in declaration order; ``tables``: table name -> (texture uniform, height, width);
    ``light_slots``: for each light of the material, (kind, index in its kind's array)."""
    material: object
    dialect: str
    fragment: str
    vertex: str
    uniforms: tuple
    bindings: dict
    tables: dict
    light_slots: tuple
    module: object

    def uniform_values(self, material_values, lights_values=(), world_values=None, ambient_occlusion=1.0):
        """{uniform path -> value} for the material's inputs (RT_LIT_INPUTS name -> value), its lights'
        parameters (one dict of driver values per light, in the material's light order), the world's
        (``WORLD_PARAMETERS`` name -> value) and the ambient occlusion (materials with occlusion on): e.g.
        "u_quad_lights[0].location" -> (x, y, z), "u_world_sh" -> nine RGB triples.  Camera uniforms and tables are
        the renderer's."""
        out = {}
        for name, sock in RT_LIT_INPUTS.items():
            if name in _VARYING_INPUTS:
                continue
            # an input the material does not name (a scene description written before the input existed, e.g.
            # "Diffuse Roughness") takes its socket's default, as an unlinked node socket would
            value = material_values.get(name, sock.default)
            out[_material_uniform(name)] = float(value) if sock.kind == "float" else tuple(float(v) for v in value[:3])
        if len(lights_values) != len(self.light_slots):
            raise ValueError(f"{self.material.name}: {len(lights_values)} lights given, the shader was built for "
                             f"{len(self.light_slots)} ({', '.join(k for k, _ in self.light_slots)})")
        for (kind, index), params in zip(self.light_slots, lights_values):
            for field, typ, parts in light_fields(kind):
                values = tuple(float(params[param]) for param, _ in parts)
                out[f"{light_array(kind)}[{index}].{field}"] = values[0] if typ == "float" else values
        if self.material.environment is not None:
            if world_values is None:
                raise ValueError(f"{self.material.name} shades a world: pass world_values")
            out["u_world_sh"] = [tuple(float(v) for v in np.asarray(world_values[f"SH {i}"])[:3])
                                 for i in range(_WORLD_SH)]
            out["u_world_strength"] = float(world_values["Strength"])
            out["u_world_rotation"] = tuple(float(v) for v in np.asarray(world_values["Rotation"])[:3])
        if self.material.occlusion_inputs:
            out[_OCCLUSION_UNIFORM] = float(ambient_occlusion)
        return out


_OCCLUSION_UNIFORM = "u_ambient_occlusion"

#: RT Lit inputs fed per fragment, not by a uniform: the shading normal is the interpolated normal.
_VARYING_INPUTS = ("Normal",)


def _material_uniform(name):
    return shader_text.identifier(name, "u_")


def _types(dialect):
    d = shader_text.DIALECTS[dialect]
    return {"float": "float", "vec3": d.vec3, "vec4": d.vec4}


def light_slots(light_kinds):
    """(kind, index in its kind's array) of each light, in order."""
    counts, slots = {}, []
    for kind in light_kinds:
        slots.append((kind, counts.get(kind, 0)))
        counts[kind] = counts.get(kind, 0) + 1
    return tuple(slots)


class _Interface:
    """The uniform declarations of one material in one dialect, the docs of each, and the binding of every
    material-function input to the shader expression that feeds it."""

    def __init__(self, material, dialect):
        self.material, self.types, self.hlsl = material, _types(dialect), dialect == "hlsl"
        self.lines, self.docs, self.bindings = [], [], {}
        self.slots = light_slots(material.light_kinds)

    def declare(self, name, typ, meaning, count=None):
        suffix = f"[{count}]" if count else ""
        self.lines.append(f"{'' if self.hlsl else 'uniform '}{self.types.get(typ, typ)} {name}{suffix};   // {meaning}")
        self.docs.append(Uniform(name + suffix, typ, meaning))

    def material_inputs(self):
        self.lines.append("// Material: the RT Lit inputs (Principled names; colours linear RGB)")
        for name, sock in RT_LIT_INPUTS.items():
            if name in _VARYING_INPUTS:
                self.bindings[name] = "shading_normal"
                continue
            uniform = _material_uniform(name)
            self.declare(uniform, "float" if sock.kind == "float" else "vec3", f"{name}: {sock.description}")
            self.bindings[name] = uniform

    def lights(self):
        counts = {}
        for kind, index in self.slots:
            counts[kind] = index + 1
        if counts:
            self.lines.append("// Lights, Blender's units: location m, rotation the unit quaternion (x, y, z, w) of the "
                              "object's world rotation, world scale, power W (sun: strength W/m^2), sizes m, spot size rad")
        for struct in dict.fromkeys(light_struct(k) for k in counts):
            kind = next(k for k in counts if light_struct(k) == struct)
            members = " ".join(f"{self.types[typ]} {field};" for field, typ, _ in light_fields(kind))
            self.lines.append(f"struct {struct} {{ {members} }};")
        for kind, count in counts.items():
            self.declare(light_array(kind), light_struct(kind),
                         f"the scene's {kind} lights, in the material's light order", count)
        for (kind, index), names in zip(self.slots, self.material.light_inputs):
            for field, _, parts in light_fields(kind):
                for param, component in parts:
                    path = f"{light_array(kind)}[{index}].{field}" + (f".{component}" if component else "")
                    self.bindings[names[param]] = path

    def world(self):
        if self.material.environment is None:
            return
        self.lines.append("// World: SH and the prefiltered levels (table below)")
        self.declare("u_world_sh", "vec3", "L2 SH radiance coefficients (R&H 2001 order), image frame, strength 1",
                     _WORLD_SH)
        self.declare("u_world_strength", "float", "the Background node's Strength")
        self.declare("u_world_rotation", "vec3", "the world Mapping node's Euler XYZ rotation, radians")
        for param, name in self.material.world_inputs.items():
            if param.startswith("SH "):
                self.bindings[name] = f"u_world_sh[{int(param.split()[1])}]"
            else:
                self.bindings[name] = {"Strength": "u_world_strength", "Rotation": "u_world_rotation"}[param]

    def occlusion(self):
        for name in self.material.occlusion_inputs:
            self.lines.append("// Occlusion of the World term: the engine's ambient occlusion (core/occlusion.py)")
            self.declare(_OCCLUSION_UNIFORM, "float", f"{name}: {OCCLUSION_SOCKET.description}")
            self.bindings[name] = _OCCLUSION_UNIFORM

    def camera_and_geometry(self):
        self.lines.append("// Camera")
        self.declare("u_camera_position", "vec3", "world-space camera position, m")
        self.declare("u_camera_forward", "vec3", "unit view direction (the camera's -Z axis)")
        self.declare("u_camera_orthographic", "float", "1: orthographic (Incoming = -forward), 0: perspective")
        self.bindings.update({"Position": "v_position", "Geometry Normal": "v_normal", "Incoming": "incoming"})


def _declarations(material, dialect):
    """(uniform declarations (lines), Uniform docs, bindings, light slots)."""
    iface = _Interface(material, dialect)
    iface.material_inputs()
    iface.lights()
    iface.world()
    iface.occlusion()
    iface.camera_and_geometry()
    missing = [n for n, _ in material.function.inputs if n not in iface.bindings]
    if missing:
        raise ValueError(f"{material.name}: no uniform feeds {missing}")
    return iface.lines, iface.docs, iface.bindings, iface.slots


_GLSL_MAIN = """
in vec3 v_position;   // world-space shading point (m)
in vec3 v_normal;     // interpolated world-space normal (any length)
layout(location = 0) out vec4 frag_radiance;

void main()
{{
    vec3 shading_normal = v_normal;
    vec3 incoming = (u_camera_orthographic != 0.0) ? -u_camera_forward
                                                         : rtl_normalize(u_camera_position - v_position);
{body}
    frag_radiance = vec4({result}, 1.0);
}}
"""

_HLSL_MAIN = """
float4 main(float4 frag_coord : SV_Position, float3 v_position : TEXCOORD0,
            float3 v_normal : TEXCOORD1) : SV_Target
{{
    float3 shading_normal = v_normal;
    float3 incoming = (u_camera_orthographic != 0.0) ? -u_camera_forward
                                                           : rtl_normalize(u_camera_position - v_position);
{body}
    return float4({result}, 1.0);
}}
"""

_GLSL_VERTEX = """
uniform mat4 u_view_projection;
uniform mat4 u_model;
uniform mat3 u_normal_matrix;
in vec3 a_position;
in vec3 a_normal;
out vec3 v_position;
out vec3 v_normal;

void main()
{
    vec4 world = u_model * vec4(a_position, 1.0);
    v_position = world.xyz;
    v_normal = u_normal_matrix * a_normal;
    gl_Position = u_view_projection * world;
}
"""

_HLSL_VERTEX = """
float4x4 u_view_projection;
float4x4 u_model;
float3x3 u_normal_matrix;

struct RtlVertexOut { float4 position : SV_Position; float3 world : TEXCOORD0; float3 normal : TEXCOORD1; };

RtlVertexOut main(float3 a_position : POSITION, float3 a_normal : NORMAL)
{
    RtlVertexOut o;
    float4 world = mul(u_model, float4(a_position, 1.0));
    o.world = world.xyz;
    o.normal = mul(u_normal_matrix, a_normal);
    o.position = mul(u_view_projection, world);
    return o;
}
"""


def vertex_shader(dialect="glsl450"):
    """The vertex shader of every RT Lit material (world-space position and normal to the fragment)."""
    d = shader_text.DIALECTS[dialect]
    return d.header + (_HLSL_VERTEX if dialect == "hlsl" else _GLSL_VERTEX)


def material_shader(material, dialect="glsl450", precise=True):
    """``MaterialShader`` of ``material`` (``rt_lit.RtLitMaterial``) in ``dialect`` ("glsl450",
    "glsl300es", "hlsl"); ``precise`` as ``shader_text.emit``."""
    if dialect not in shader_text.DIALECTS:
        raise ValueError(f"unknown shader dialect {dialect!r}; choose one of {sorted(shader_text.DIALECTS)}")
    unknown = [k for k in material.light_kinds if lights.base_kind(k) not in LIGHT_KINDS]
    if unknown:
        raise ValueError(f"{material.name}: light kinds {unknown} have no shader form (RT Lit shades {LIGHT_KINDS})")
    module = shader_text.emit(material.function, dialect, precise)
    lines, docs, bindings, slots = _declarations(material, dialect)
    entry = module.entry
    t = _types(dialect)
    body = []
    args = []
    for name, _, kind in entry.inputs:
        args.append(bindings[name])
    results = []
    for name, ident, kind in entry.outputs:
        var = f"r_{ident}"
        body.append(f"    {t['float'] if kind == FLOAT else t['vec3']} {var};")
        results.append((name, var))
    body.append(f"    {entry.ident}({', '.join(args + [v for _, v in results])});")
    result = dict(results)["Radiance"]
    main = (_HLSL_MAIN if dialect == "hlsl" else _GLSL_MAIN).format(body="\n".join(body), result=result)
    # the interface goes after the version / precision header, before the module's functions
    header = module.dialect.header
    assert module.source.startswith(header)
    source = (header + f"// RT Lit material: {material.name}\n// Uniform interface (core/materials/rt_lit_shader.py)\n"
              + "\n".join(lines) + "\n" + module.source[len(header):] + main)
    return MaterialShader(material, dialect, source, vertex_shader(dialect), tuple(docs), bindings,
                          dict(module.tables), slots, module)


def interface_markdown(shader):
    """The uniform interface of ``shader`` as a Markdown table (docs/realtime.md holds the one of
    ``reference_material``, checked against this by tests/glsl/test_shader_compile.py)."""
    lines = ["| uniform | type | meaning |", "|---|---|---|"]
    lines += [f"| `{u.name}` | `{u.type}` | {u.meaning.replace('|', '/')} |" for u in shader.uniforms]
    structs = {}
    for kind, _ in shader.light_slots:
        structs.setdefault(light_struct(kind), kind)
    lines += ["", "| struct | field | type | Blender parameter (core/lights.py) |", "|---|---|---|---|"]
    for struct, kind in structs.items():
        for field, typ, parts in light_fields(kind):
            params = ", ".join(f"{p} (.{c})" if c else p for p, c in parts)
            lines.append(f"| `{struct}` | `{field}` | `{typ}` | {params} |")
    lines += ["", "| table texture | size (W x H) |", "|---|---|"]
    lines += [f"| `{texture}` | {w} x {h} |" for texture, h, w in shader.tables.values()]
    return "\n".join(lines)


def reference_material(environment):
    """The material docs/realtime.md documents: every technique on, one light of each kind, a world."""
    return rt_lit.build_rt_lit(Features("kulla_conty", "wrapped", sheen=True, cloth=True), LIGHT_KINDS, environment)
