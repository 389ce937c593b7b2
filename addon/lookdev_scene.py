"""The lookdev scene an artist gets in one click, and its path-traced twin.

``new_lookdev_scene(...)`` builds a new scene in the current file (nothing else in the file is touched):
two rows of spheres across roughness, a dielectric row and a gold row (Principled materials converted to
RT Lit), a key rectangle light, a fill disk light, a rim spot light, a studio HDRI world (one of
Blender's own, baked for the World term), an orthographic camera, and render settings for lookdev:
Cycles with 0 bounces (RT Lit surfaces are emitters: with bounces they would light each other a second
time), the view transform the artist picks (AgX or Standard).

``new_concave_scene(...)`` builds issue 29's asset-like concave scene the same way: a torus resting on the floor of an
open box and a Suzanne beside it (objects that touch and shadow each other), RT Lit from Principled, the same lights
and world, a perspective camera (``validation.checks.lookdev_twin.concave_study`` measures it).

``add_path_traced_twin(scene)`` adds the scene's twin: a scene "<name> Path Traced" with the same world and
camera that holds every object the scene renders.  An object with an RT Lit material in some slot is copied
(same data and modifiers, transform copied from the original by a constraint, so moving a sphere moves its
twin), and each such slot of the copy holds, linked to the object, the Principled BSDF the RT Lit material was
converted from, with the values edited in RT Lit (``convert.rt_lit_to_principled`` on a copy, one per
material); an instancer of a collection with RT Lit objects is copied to instance a twin of that collection;
every other object (lights, camera, other materials, no material) is the object itself.  The copies join the
light-linking collections of the lights and emitters with their originals' states, so light and shadow linking
act on the twin as on the scene.  It renders with Cycles path tracing, by default direct light only (0 bounces:
what RT Lit computes, plus the shadows it does not), so switching scenes compares real-time and path-traced
shading.  ``validation.checks.lookdev_twin`` measures the two against each other.  Not twinned: materials a modifier
assigns (Geometry Nodes' Set Material), particle instances, and the view layers' collection settings (exclude
aside: an object the scene does not render is left out); a light-linking collection that a scene renders cannot
hold the copies, and the twin is refused.

The lights RT Lit shades are one set per file ("RTL Scene Lights", ``materials.py``): the twin shares the
lookdev scene's lights, so switching to it keeps the RT Lit groups in sync.
"""
from __future__ import annotations

import math

import bpy

from . import compat
from .common import SHADOW_COPY_KEY
from .light_model import link_states

#: Sphere roughness along each row.
ROUGHNESS = (0.05, 0.25, 0.5, 0.75, 1.0)
SPACING = 1.1
RADIUS = 0.42
#: (row name, Principled inputs); row 0 on top.  Gold's Base Color is its measured F0, as in the preset
#: "RTL Gold" (core/materials/presets.py gives the source).
ROWS = (
    ("Dielectric", {"Base Color": (0.8, 0.25, 0.1, 1.0), "Metallic": 0.0}),
    ("Gold", {"Base Color": (1.000, 0.766, 0.336, 1.0), "Metallic": 1.0}),
)
DEFAULT_HDRI = "studio"
VIEW_TRANSFORMS = ("AgX", "Standard")
TWIN_SUFFIX = " Path Traced"
#: Custom property on a twin scene: the name of the lookdev scene it copies.
TWIN_OF_KEY = "rtl_twin_of"
#: Custom property on a twin sphere: the name of the lookdev object it copies.
TWIN_SOURCE_KEY = "rtl_twin_source"


# --- building blocks (shared with the demo scene) ------------------------------------------------------

def principled_material(name, values):
    """A new node material whose Principled BSDF has ``values`` (input name -> value)."""
    mat = compat.new_material(name)
    bsdf = next(n for n in mat.node_tree.nodes if n.bl_idname == "ShaderNodeBsdfPrincipled")
    for key, value in values.items():
        bsdf.inputs[key].default_value = value
    return mat


def sphere(name, location, material, collection, radius=RADIUS):
    """A smooth UV sphere object with ``material``, linked into ``collection``."""
    import bmesh

    mesh = bpy.data.meshes.new(name)
    bm = bmesh.new()
    bmesh.ops.create_uvsphere(bm, u_segments=64, v_segments=32, radius=radius)
    bm.to_mesh(mesh)
    bm.free()
    for poly in mesh.polygons:
        poly.use_smooth = True
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    obj.location = location
    collection.objects.link(obj)
    return obj


def light(name, kind, power, location, rotation, collection, color=(1.0, 1.0, 1.0), **settings):
    """A light object of Blender type ``kind`` ("AREA", "SPOT", ...) with ``settings`` on its data."""
    data = bpy.data.lights.new(name, kind)
    data.energy = power
    data.color = color
    for key, value in settings.items():
        setattr(data, key, value)
    obj = bpy.data.objects.new(name, data)
    obj.location = location
    obj.rotation_euler = rotation
    collection.objects.link(obj)
    return obj


def studio_hdris():
    """{name: path} of the studio HDRIs of the running Blender (``datafiles/studiolights/world``: city,
    courtyard, forest, interior, night, studio, sunrise, sunset)."""
    from pathlib import Path

    folder = bpy.utils.system_resource("DATAFILES", path="studiolights/world")
    return {p.stem: p for p in sorted(Path(folder).glob("*.exr"))} if folder else {}


def hdri_path(hdri):
    """A studio HDRI name of the running Blender, or the path of an equirectangular EXR."""
    from ..core.environment import equirect

    found = studio_hdris().get(str(hdri))
    return found if found is not None else equirect.resolve_hdri(hdri)


def add_hdri_world(scene, hdri, strength, rotation_z=0.0, name=None):
    """World = Background(strength) <- Environment Texture(hdri) <- Mapping(rotation) <- Generated, the
    setup "Sync RT Lit World" bakes (``world_sync.world_setup``)."""
    world = compat.new_world(name or f"HDRI {hdri}")
    scene.world = world
    nt = world.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputWorld")
    background = nt.nodes.new("ShaderNodeBackground")
    background.inputs["Strength"].default_value = strength
    env = nt.nodes.new("ShaderNodeTexEnvironment")
    env.image = bpy.data.images.load(str(hdri_path(hdri)), check_existing=True)
    mapping = nt.nodes.new("ShaderNodeMapping")
    mapping.inputs["Rotation"].default_value = (0.0, 0.0, rotation_z)
    coords = nt.nodes.new("ShaderNodeTexCoord")
    nt.links.new(coords.outputs["Generated"], mapping.inputs["Vector"])
    nt.links.new(mapping.outputs["Vector"], env.inputs["Vector"])
    nt.links.new(env.outputs["Color"], background.inputs["Color"])
    nt.links.new(background.outputs["Background"], out.inputs["Surface"])
    return world


def ortho_camera(name, location, rotation, ortho_scale, collection):
    data = bpy.data.cameras.new(name)
    data.type = "ORTHO"
    data.ortho_scale = ortho_scale
    cam = bpy.data.objects.new(name, data)
    cam.location = location
    cam.rotation_euler = rotation
    collection.objects.link(cam)
    return cam


# --- the lookdev scene ---------------------------------------------------------------------------------

def _studio_lights(collection):
    """Key rectangle (front left, above), fill disk (front right, low), rim spot (behind, above).  The
    point-like settings RT Lit does not shade are 0 (spot radius), so nothing is ignored."""
    key = light("Key Quad", "AREA", 400.0, (-2.5, -3.5, 3.0), (0.85, 0.0, -0.62), collection,
                (1.0, 0.96, 0.9), shape="RECTANGLE", size=2.0, size_y=1.2)
    fill = light("Fill Disk", "AREA", 150.0, (3.5, -3.0, 0.8), (1.4, 0.0, 0.86), collection,
                 (0.85, 0.92, 1.0), shape="DISK", size=1.5)
    rim = light("Rim Spot", "SPOT", 1500.0, (0.0, 4.0, 3.5), (-0.85, 0.0, 0.0), collection,
                spot_size=math.radians(60.0), spot_blend=0.2, shadow_soft_size=0.0)
    return key, fill, rim


def configure_lookdev_render(scene, view_transform="AgX", samples=16):
    """Cycles with no bounces (the RT Lit surfaces are emitters, so a bounce would light the scene a
    second time), ``samples`` for anti-aliasing, the artist's view transform."""
    if view_transform not in VIEW_TRANSFORMS:
        raise ValueError(f"view transform must be one of {VIEW_TRANSFORMS}, got {view_transform!r}")
    scene.render.engine = "CYCLES"
    c = scene.cycles
    c.samples = int(samples)
    c.preview_samples = max(1, int(samples) // 2)
    c.max_bounces = 0
    c.use_denoising = False
    c.use_preview_denoising = False
    scene.view_settings.view_transform = view_transform
    scene.view_settings.look = "None"


#: The floor's material and switches: grey, rough, the cheapest lobes (and the scene's world occlusion).
FLOOR_VALUES = {"Base Color": (0.5, 0.5, 0.5, 1.0), "Roughness": 0.8, "Metallic": 0.0}
FLOOR_FEATURES = {"specular": "single", "diffuse": "lambert"}
#: With a floor the camera looks down by this much (radians), so the floor is seen.
FLOOR_CAMERA_TILT = math.radians(15.0)


def _floor(name, collection, z, lut_dir, scene, occlusion="none"):
    """A 9 x 5 m plane under the spheres with an RT Lit material (where RT Lit's missing shadows show), its world
    occluded as ``occlusion`` says (``Features.occlusion``)."""
    import bmesh

    from ..core.materials.rt_lit_interface import Features
    from . import convert, materials

    mat = principled_material(f"{name} Floor", FLOOR_VALUES)
    convert.principled_to_rt_lit(mat, lambda f: materials.ensure_rt_lit_group(f, scene, lut_dir),
                                 Features(**FLOOR_FEATURES, occlusion=occlusion))
    mesh = bpy.data.meshes.new(f"{name} Floor")
    bm = bmesh.new()
    bmesh.ops.create_grid(bm, x_segments=1, y_segments=1, size=1.0)
    bmesh.ops.scale(bm, vec=(4.5, 2.5, 1.0), verts=bm.verts)
    bm.to_mesh(mesh)
    bm.free()
    mesh.materials.append(mat)
    obj = bpy.data.objects.new(f"{name} Floor", mesh)
    obj.location = (0.0, 0.0, z)
    collection.objects.link(obj)
    return obj


def studio_scene(name, hdri, world_strength, view_transform, resolution, advance=None):
    """A new scene of the current file set up as the lookdev scenes are: the lookdev render settings, the studio HDRI
    ``hdri`` (None: no world) synced as RT Lit's World term, the studio lights synced; ``advance()`` is called after
    the world and after the lights (progress)."""
    from . import materials
    from . import world_sync as rtl_world

    scene = bpy.data.scenes.new(name)
    configure_lookdev_render(scene, view_transform)
    scene.render.resolution_x, scene.render.resolution_y = resolution
    scene.render.resolution_percentage = 100
    scene.world = None
    if hdri is not None:
        world = add_hdri_world(scene, hdri, world_strength, name=f"{name} {hdri}")
        world.cycles.sampling_method = "AUTOMATIC"   # the twin path-traces this world
    rtl_world.sync_world(scene)          # bakes (cached) the HDRI; no world: no World term
    if advance is not None:
        advance()
    _studio_lights(scene.collection)
    materials.sync_scene_lights(scene)   # lights first: the RT Lit groups are built for them
    if advance is not None:
        advance()
    return scene


def new_lookdev_scene(name="RT Lookdev", features=None, hdri=DEFAULT_HDRI, world_strength=1.0,
                      view_transform="AgX", lut_dir=None, resolution=(960, 480), progress=None, floor=False):
    """Build the lookdev scene (see the module doc) as a new scene of the current file; returns it.

    ``features``: the RT Lit switches (``Features``; default ``Features()``); ``hdri``: a studio HDRI name
    (``core.environment.equirect.studio_hdris``) or an EXR path, None for no world; ``progress(done,
    total)`` is called after each step (the world bake, each material); ``floor``: a grey RT Lit floor under
    the spheres, and the camera tilted to see it (shadowed only with RT Lit Shadows on: addon/shadows.py)."""
    from ..core.materials.rt_lit_interface import Features
    from . import convert, materials

    features = features or Features()
    total = 2 + len(ROWS) * len(ROUGHNESS)
    step = [0]

    def advance():
        step[0] += 1
        if progress is not None:
            progress(step[0], total)

    scene = studio_scene(name, hdri, world_strength, view_transform, resolution, advance)
    collection = scene.collection

    def factory(feats):
        return materials.ensure_rt_lit_group(feats, scene, lut_dir)

    x0 = -0.5 * (len(ROUGHNESS) - 1) * SPACING
    for row, (label, values) in enumerate(ROWS):
        for col, r in enumerate(ROUGHNESS):
            object_name = f"{label} r{r:.2f}"
            mat = principled_material(f"{name} {object_name}", dict(values, Roughness=r))
            convert.principled_to_rt_lit(mat, factory, features)
            z = 0.5 * SPACING * (len(ROWS) - 1) - row * SPACING
            sphere(f"{name} {object_name}", (x0 + col * SPACING, 0.0, z), mat, collection)
            advance()

    tilt = FLOOR_CAMERA_TILT if floor else 0.0
    cam = ortho_camera(f"{name} Camera", (0.0, -10.0 * math.cos(tilt), 10.0 * math.sin(tilt)),
                       (0.5 * math.pi - tilt, 0.0, 0.0), SPACING * len(ROUGHNESS) + 0.1, collection)
    scene.camera = cam
    if floor:
        bottom = 0.5 * SPACING * (len(ROWS) - 1) - (len(ROWS) - 1) * SPACING - RADIUS
        _floor(name, collection, bottom, lut_dir, scene, features.occlusion)
    return scene


# --- the concave scene ---------------------------------------------------------------------------------

#: The concave scene's open box (floor and three walls, open at the front and the top), its torus and Suzanne (m).
BOX_HALF = 1.2
BOX_HEIGHT = 1.0
TORUS_RADII = (0.42, 0.14)           # major, minor
TORUS_LOCATION = (-0.45, -0.25, TORUS_RADII[1])
SUZANNE_SCALE = 0.42
#: Suzanne's mesh (``bmesh.ops.create_monkey``) reaches 0.98 below its origin: she sits on the floor.
SUZANNE_LOCATION = (0.35, 0.2, 0.98 * SUZANNE_SCALE)
SUZANNE_TURN = math.radians(-20.0)
#: (object, Principled inputs): a grey rough box, a coloured rough torus, a copper Suzanne (the preset "RTL Copper"'s
#: measured F0, core/materials/presets.py).
CONCAVE_MATERIALS = (
    ("Box", {"Base Color": (0.55, 0.55, 0.55, 1.0), "Roughness": 0.8, "Metallic": 0.0}),
    ("Torus", {"Base Color": (0.1, 0.35, 0.8, 1.0), "Roughness": 0.45, "Metallic": 0.0}),
    ("Suzanne", {"Base Color": (0.955, 0.637, 0.538, 1.0), "Roughness": 0.35, "Metallic": 1.0}),
)
#: The perspective camera: where it stands, the point it looks at, its lens (mm, 36 mm sensor).
CONCAVE_CAMERA = ((0.0, -4.3, 2.6), (0.0, 0.1, 0.3), 42.0)


def open_box_mesh(name, half=BOX_HALF, height=BOX_HEIGHT):
    """A floor (2 ``half`` square at z = 0) and three walls of ``height`` (left, right, back: open towards -y and
    the top), every face's normal pointing into the box."""
    a, h = half, height
    verts = [(-a, -a, 0), (a, -a, 0), (a, a, 0), (-a, a, 0), (-a, -a, h), (a, -a, h), (a, a, h), (-a, a, h)]
    faces = [(0, 1, 2, 3),          # floor, +z
             (3, 2, 6, 7),          # back wall (y = a), -y
             (0, 3, 7, 4),          # left wall (x = -a), +x
             (1, 5, 6, 2)]          # right wall (x = a), -x
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    mesh.update()
    return mesh


def torus_mesh(name, radii=TORUS_RADII, segments=(64, 24)):
    """A smooth torus around the z axis (major, minor radius), its normals outwards."""
    (big, small), (nu, nv) = radii, segments
    verts = []
    for i in range(nu):
        u = 2.0 * math.pi * i / nu
        for j in range(nv):
            v = 2.0 * math.pi * j / nv
            ring = big + small * math.cos(v)
            verts.append((ring * math.cos(u), ring * math.sin(u), small * math.sin(v)))
    faces = [(i * nv + j, ((i + 1) % nu) * nv + j, ((i + 1) % nu) * nv + (j + 1) % nv, i * nv + (j + 1) % nv)
             for i in range(nu) for j in range(nv)]
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    mesh.update()
    for poly in mesh.polygons:
        poly.use_smooth = True
    return mesh


def suzanne_mesh(name, scale=SUZANNE_SCALE, subdivisions=1):
    """Blender's monkey (``bmesh.ops.create_monkey``, facing -y), scaled, subdivided once (smooth), smooth shaded."""
    import bmesh
    from mathutils import Matrix

    bm = bmesh.new()
    bmesh.ops.create_monkey(bm, matrix=Matrix.Scale(scale, 4))
    if subdivisions:
        bmesh.ops.subdivide_edges(bm, edges=bm.edges, cuts=subdivisions, use_grid_fill=True, smooth=1.0)
    mesh = bpy.data.meshes.new(name)
    bm.to_mesh(mesh)
    bm.free()
    for poly in mesh.polygons:
        poly.use_smooth = True
    return mesh


def perspective_camera(name, location, target, lens, collection):
    """A perspective camera at ``location`` looking at ``target`` (its up towards +z), ``lens`` mm on a 36 mm
    sensor."""
    from mathutils import Vector

    data = bpy.data.cameras.new(name)
    data.type = "PERSP"
    data.lens = lens
    data.sensor_width = 36.0
    cam = bpy.data.objects.new(name, data)
    cam.location = location
    cam.rotation_euler = (Vector(target) - Vector(location)).to_track_quat("-Z", "Y").to_euler()
    collection.objects.link(cam)
    return cam


def _concave_objects(name, collection):
    """{label: object} of the open box, the torus resting on its floor and Suzanne sitting beside it."""
    box = bpy.data.objects.new(f"{name} Box", open_box_mesh(f"{name} Box"))
    torus = bpy.data.objects.new(f"{name} Torus", torus_mesh(f"{name} Torus"))
    torus.location = TORUS_LOCATION
    suzanne = bpy.data.objects.new(f"{name} Suzanne", suzanne_mesh(f"{name} Suzanne"))
    suzanne.location = SUZANNE_LOCATION
    suzanne.rotation_euler = (0.0, 0.0, SUZANNE_TURN)
    objects = {"Box": box, "Torus": torus, "Suzanne": suzanne}
    for obj in objects.values():
        collection.objects.link(obj)
    return objects


def new_concave_scene(name="RT Concave", features=None, hdri=DEFAULT_HDRI, world_strength=1.0,
                      view_transform="AgX", lut_dir=None, resolution=(640, 480)):
    """An asset-like concave scene (issue 29) as a new scene of the current file; returns it.  A torus resting on
    the floor of an open box (floor, left, right and back walls; open towards the camera and the top) and a smooth
    Suzanne sitting beside it, so objects touch and shadow each other; RT Lit materials converted from Principled
    (``CONCAVE_MATERIALS``: grey rough box, blue rough torus, copper Suzanne), every one with ``features``
    (default ``Features()``); the studio lights and HDRI world of ``new_lookdev_scene``; a perspective camera
    looking into the box from the front, above."""
    from ..core.materials.rt_lit_interface import Features
    from . import convert, materials

    features = features or Features()
    scene = studio_scene(name, hdri, world_strength, view_transform, resolution)
    collection = scene.collection

    def factory(feats):
        return materials.ensure_rt_lit_group(feats, scene, lut_dir)

    objects = _concave_objects(name, collection)
    for label, values in CONCAVE_MATERIALS:
        mat = principled_material(f"{name} {label}", values)
        convert.principled_to_rt_lit(mat, factory, features)
        objects[label].data.materials.append(mat)
    location, target, lens = CONCAVE_CAMERA
    scene.camera = perspective_camera(f"{name} Camera", location, target, lens, collection)
    return scene


def rt_lit_slots(obj):
    """Indices of the material slots of ``obj`` whose material (as the slot links it) is RT Lit."""
    from .convert import is_rt_lit_material

    return [i for i, slot in enumerate(obj.material_slots) if is_rt_lit_material(slot.material)]


def _instanced(obj):
    """The collection ``obj`` instances, or None."""
    return obj.instance_collection if obj.instance_type == "COLLECTION" else None


def uses_rt_lit(obj, _seen=None):
    """Whether ``obj`` renders an RT Lit material: in one of its slots, or in the collection it instances."""
    if rt_lit_slots(obj):
        return True
    instanced = _instanced(obj)
    seen = set() if _seen is None else _seen
    if instanced is None or instanced.as_pointer() in seen:
        return False
    seen.add(instanced.as_pointer())
    return any(uses_rt_lit(o, seen) for o in instanced.all_objects)


def lookdev_spheres(scene):
    """The objects of ``scene`` with an RT Lit material in one of their slots, in name order."""
    return sorted((o for o in scene.objects if rt_lit_slots(o)), key=lambda o: o.name)


# --- the path-traced twin ------------------------------------------------------------------------------

#: The light-linking collections of an object (``Object.light_linking``): light linking and shadow linking.
LINKING_COLLECTIONS = ("receiver_collection", "blocker_collection")


def twin_material(material):
    """A Principled copy of the RT Lit ``material``: the values edited in RT Lit carried back
    (``convert.rt_lit_to_principled`` on a copy; the original stays RT Lit), tagged with its name."""
    from . import convert

    twin = material.copy()
    twin.name = material.name + TWIN_SUFFIX
    try:
        convert.rt_lit_to_principled(twin)
    except Exception:
        bpy.data.materials.remove(twin)
        raise
    for key in list(twin.keys()):        # the copy is not an RT Lit material
        if key.startswith("rtl_"):
            del twin[key]
    twin[TWIN_SOURCE_KEY] = material.name
    return twin


def _reachable(objects):
    """{pointer: object} of ``objects`` and of the objects of the collections they instance, at any depth."""
    out, todo = {}, list(objects)
    while todo:
        obj = todo.pop(0)
        if obj.as_pointer() in out:
            continue
        out[obj.as_pointer()] = obj
        instanced = _instanced(obj)
        if instanced is not None:
            todo.extend(instanced.all_objects)
    return out


def _collection_holders():
    """{collection pointer: what renders it, in words}: the collections of every scene and those objects
    instance, with their children."""
    holders = {}
    roots = [(s.collection, f"the scene '{s.name}'") for s in bpy.data.scenes]
    roots += [(_instanced(o), f"the instances of '{o.name}'") for o in bpy.data.objects if _instanced(o) is not None]
    for root, holder in roots:
        for collection in (root, *root.children_recursive):
            holders.setdefault(collection.as_pointer(), holder)
    return holders


def _linking_plan(objects):
    """[(light-linking collection, [(original, state)])]: where the copies of ``objects`` (and of the objects they
    instance) go so that every emitter links them as their originals.  Raises ValueError when such a collection
    cannot hold them: linked from a library, or rendered itself (the copies would show there)."""
    reachable = _reachable(objects)
    copied = {p for p, o in reachable.items() if uses_rt_lit(o)}
    plan, seen, holders = [], set(), None
    for emitter in reachable.values():
        for attr in LINKING_COLLECTIONS:
            collection = getattr(emitter.light_linking, attr)
            if collection is None or collection.as_pointer() in seen:
                continue
            seen.add(collection.as_pointer())
            entries = [(o, state) for p, (o, state) in link_states(collection).items() if p in copied]
            if not entries:
                continue
            what = f"the light linking of '{emitter.name}' uses the collection '{collection.name}'"
            if collection.library is not None:
                raise ValueError(f"{what}, linked from '{collection.library.filepath}': the twin cannot add its "
                                 "copies to it; make it local")
            holders = _collection_holders() if holders is None else holders
            holder = holders.get(collection.as_pointer())
            if holder is not None:
                raise ValueError(f"{what}, which {holder} renders: the twin's copies would appear there. Give "
                                 f"'{emitter.name}' a light-linking collection of its own (Object Properties > "
                                 "Shading > Light Linking)")
            plan.append((collection, entries))
    return plan


class _TwinParts:
    """The copies, collections and materials one twin is made of, each made once (``made``: every ID made,
    with the name it is meant to have)."""

    def __init__(self):
        self.objects = {}        # original's pointer -> the object the twin renders for it (itself or its copy)
        self.collections = {}    # pointer of a collection -> itself or its twin
        self.materials = {}      # RT Lit material's pointer -> its Principled twin
        self.made = []

    def material(self, material):
        key = material.as_pointer()
        if key not in self.materials:
            self.materials[key] = twin_material(material)
            self.made.append((self.materials[key], material.name + TWIN_SUFFIX))
        return self.materials[key]

    def object(self, obj):
        """``obj`` itself when it renders no RT Lit material, else its copy: sharing its data, the Principled twin
        in each RT Lit slot (linked to the object), the twin of the collection it instances, its transform copied
        from ``obj`` by a constraint."""
        key = obj.as_pointer()
        if key in self.objects:
            return self.objects[key]
        self.objects[key] = obj
        slots = rt_lit_slots(obj)
        instanced = _instanced(obj)
        instanced_twin = self.collection(instanced) if instanced is not None else None
        if not slots and instanced_twin == instanced:
            return obj
        copy = obj.copy()
        copy.name = obj.name + TWIN_SUFFIX
        self.made.append((copy, obj.name + TWIN_SUFFIX))
        copy[TWIN_SOURCE_KEY] = obj.name
        for i in slots:
            material = obj.material_slots[i].material
            copy.material_slots[i].link = "OBJECT"
            copy.material_slots[i].material = self.material(material)
        if instanced_twin != instanced:
            copy.instance_collection = instanced_twin
        constraint = copy.constraints.new("COPY_TRANSFORMS")
        constraint.target = obj
        self.objects[key] = copy
        return copy

    def collection(self, collection):
        """``collection`` itself when none of its objects is copied, else a new collection of their twins."""
        key = collection.as_pointer()
        if key in self.collections:
            return self.collections[key]
        self.collections[key] = collection
        objects = [self.object(o) for o in collection.objects]
        children = [self.collection(c) for c in collection.children]
        if objects == list(collection.objects) and children == list(collection.children):
            return collection
        twin = bpy.data.collections.new(collection.name + TWIN_SUFFIX)
        self.made.append((twin, collection.name + TWIN_SUFFIX))
        twin[TWIN_SOURCE_KEY] = collection.name
        twin.instance_offset = collection.instance_offset
        twin.hide_render = collection.hide_render
        for obj in objects:
            twin.objects.link(obj)
        for child in children:
            twin.children.link(child)
        self.collections[key] = twin
        return twin

    def remove(self):
        """Remove everything made (a twin that could not be finished)."""
        bpy.data.batch_remove([id_block for id_block, _ in self.made])
        self.made.clear()


def _configure_twin(twin, scene, bounces, samples):
    """The twin's world, camera and Cycles path tracing, with ``scene``'s resolution and view."""
    twin[TWIN_OF_KEY] = scene.name
    twin.world = scene.world
    if scene.world is not None:
        scene.world.cycles.sampling_method = "AUTOMATIC"
    twin.camera = scene.camera
    for attr in ("resolution_x", "resolution_y", "resolution_percentage"):
        setattr(twin.render, attr, getattr(scene.render, attr))
    twin.render.engine = "CYCLES"
    twin.cycles.samples = int(samples)
    twin.cycles.preview_samples = max(1, int(samples) // 4)
    twin.cycles.max_bounces = int(bounces)
    twin.view_settings.view_transform = scene.view_settings.view_transform
    twin.view_settings.look = scene.view_settings.look


def add_path_traced_twin(scene, bounces=0, samples=128):
    """Add (or rebuild) the path-traced twin of ``scene`` (the module doc); returns the twin scene.

    Raises ValueError, changing nothing, when ``scene`` renders no RT Lit material or a light-linking collection
    cannot take the copies (``_linking_plan``); a twin made before stays until the new one is whole."""
    from .materials import is_rendered

    # the light copies of RT Lit's shadow probes (addon/shadows.py) render in the probe layers only
    rendered = [o for o in scene.objects if SHADOW_COPY_KEY not in o and is_rendered(scene, o)]
    if not any(uses_rt_lit(o) for o in rendered):
        raise ValueError(f"scene '{scene.name}' renders no RT Lit material to twin")
    plan = _linking_plan(rendered)
    twin_name = scene.name + TWIN_SUFFIX
    old = bpy.data.scenes.get(twin_name)
    old = old if old is not None and TWIN_OF_KEY in old.keys() else None
    parts = _TwinParts()
    twin = bpy.data.scenes.new(twin_name)
    parts.made.append((twin, twin_name))
    try:
        _configure_twin(twin, scene, bounces, samples)
        for obj in rendered:
            twin.collection.objects.link(parts.object(obj))
        if scene.camera is not None and scene.camera.name not in twin.collection.objects:
            twin.collection.objects.link(scene.camera)
        for collection, entries in plan:
            for original, state in entries:
                copy = parts.objects[original.as_pointer()]
                if copy != original:
                    collection.objects.link(copy)
                    collection.collection_objects[len(collection.objects) - 1].light_linking.link_state = state
    except Exception:
        parts.remove()
        raise
    if old is not None:
        remove_twin(old)
    for id_block, name in parts.made:        # the names the old twin held
        if id_block.name != name:
            id_block.name = name
    return twin


def _twin_parts(collection, objects, collections):
    """Gather the copies in ``collection`` and the twin collections they instance, at any depth."""
    for obj in collection.objects:
        if TWIN_SOURCE_KEY in obj.keys() and obj not in objects:
            objects.append(obj)
            instanced = _instanced(obj)
            if instanced is not None and TWIN_SOURCE_KEY in instanced.keys() and instanced not in collections:
                collections.append(instanced)
                _twin_parts(instanced, objects, collections)
    for child in collection.children:
        if TWIN_SOURCE_KEY in child.keys() and child not in collections:
            collections.append(child)
            _twin_parts(child, objects, collections)


def remove_twin(twin):
    """Remove a twin scene with what it made: its copies, their instanced collections and the materials only they
    used (what it shares stays; the copies leave the light-linking collections with them)."""
    objects, collections = [], []
    _twin_parts(twin.collection, objects, collections)
    materials = {slot.material.as_pointer(): slot.material for obj in objects for slot in obj.material_slots
                 if slot.link == "OBJECT" and slot.material is not None}
    if objects or collections:
        bpy.data.batch_remove([*objects, *collections])
    unused = [m for m in materials.values() if m.users == 0]
    if unused:
        bpy.data.batch_remove(unused)
    bpy.data.scenes.remove(twin)


def twin_of(scene):
    """The lookdev scene ``scene`` is the twin of, or None."""
    name = scene.get(TWIN_OF_KEY)
    return bpy.data.scenes.get(name) if name else None
