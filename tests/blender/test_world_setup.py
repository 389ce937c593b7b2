"""addon/world_sync.py: which worlds RT Lit can use, their pixels, the cached bake, the "RTL World" group
and its drivers, and the Sync World operator (in-process bpy, small synthetic images)."""
from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("OpenEXR")

pytestmark = pytest.mark.blender

H, W = 32, 64


@pytest.fixture
def world_mod(bpy_module, empty_scene, tmp_path, monkeypatch):
    from rt_lookdev.addon import world_sync as world

    monkeypatch.setenv(world.CACHE_ENV, str(tmp_path / "env-cache"))
    yield world
    world.remove_world_group()


@pytest.fixture
def small():
    from rt_lookdev.core.environment.prefilter import PrefilterSettings

    return PrefilterSettings(16, 8, (0.0, 0.5, 1.0))


def _environment(seed=3):
    """(H, W, 3) top row first: smooth random radiance with a bright band in the top 4 rows."""
    rng = np.random.default_rng(seed)
    img = rng.uniform(0.1, 1.0, size=(H, W, 3)).astype(np.float32)
    img[:4] = (8.0, 6.0, 4.0)
    return img


def _image(bpy, name, top_first, float_buffer=True):
    """A generated image holding ``top_first`` (H, W, 3): bpy pixels are bottom row first, RGBA."""
    h, w = top_first.shape[:2]
    img = bpy.data.images.new(name, w, h, alpha=True, float_buffer=float_buffer)
    rgba = np.ones((h, w, 4), np.float32)
    rgba[..., :3] = top_first
    img.pixels.foreach_set(rgba[::-1].ravel())
    return img


def _world(bpy, scene, image=None, mapping=None, coords=True):
    """Background <- Environment Texture (``image``) [<- Mapping (type ``mapping``) <- Generated]."""
    from rt_lookdev.addon import compat

    world = compat.new_world("World")
    scene.world = world
    nt = world.node_tree
    bg = nt.nodes["Background"]
    env = nt.nodes.new("ShaderNodeTexEnvironment")
    env.image = image
    nt.links.new(env.outputs["Color"], bg.inputs["Color"])
    if mapping is not None:
        m = nt.nodes.new("ShaderNodeMapping")
        m.name = 'Mapping "rot"'           # a name that needs escaping in driver paths
        m.vector_type = mapping
        nt.links.new(m.outputs["Vector"], env.inputs["Vector"])
        if coords:
            tc = nt.nodes.new("ShaderNodeTexCoord")
            nt.links.new(tc.outputs["Generated"], m.inputs["Vector"])
    return world


def _rendered(setup, why):
    """A world that is neither one image nor a constant: Cycles renders it, and the note says why."""
    assert setup.usable and setup.source == "render" and setup.image is None, setup
    assert why in setup.note and setup.note.endswith("rendered by Cycles"), setup.note
    return setup


def test_world_setup_sources(bpy_module, world_mod):
    """Issue 33: every world that shows something is usable: an equirect image read as it is, a plain colour as a
    constant, anything else rendered by Cycles (the note says why); only a world showing nothing is refused."""
    bpy = bpy_module
    scene = bpy.context.scene
    setup = world_mod.world_setup(scene.world)
    assert not setup.usable and "no World" in setup.reason

    image = _image(bpy, "env.exr", _environment())
    world = _world(bpy, scene, image)
    nt = world.node_tree
    bg, env = nt.nodes["Background"], nt.nodes["Environment Texture"]
    setup = world_mod.world_setup(world)
    assert setup.usable and setup.reason == "" and setup.image == image and setup.source == "image"
    assert setup.background == bg and setup.mapping is None and setup.label == "env.exr"

    # Blender 5.0 deprecates World.use_nodes and ignores False (the world renders its nodes)
    from rt_lookdev.addon import compat

    if compat.version() >= compat.PERMANENT_NODE_TREES:
        with pytest.warns(DeprecationWarning):
            world.use_nodes = False
        assert world_mod.world_setup(world).usable
    else:
        world.use_nodes = False
        world.color = (0.2, 0.3, 0.4)
        setup = world_mod.world_setup(world)          # Cycles renders the world's Color
        assert setup.source == "constant" and setup.colour == pytest.approx((0.2, 0.3, 0.4))
        assert "does not use nodes" in setup.note and setup.live_strength is None
        world.use_nodes = True

    # Texture Coordinate > Generated straight into the texture, and through a reroute: the same
    tc = nt.nodes.new("ShaderNodeTexCoord")
    reroute = nt.nodes.new("NodeReroute")
    nt.links.new(tc.outputs["Generated"], reroute.inputs[0])
    nt.links.new(reroute.outputs[0], env.inputs["Vector"])
    assert world_mod.world_setup(world).usable
    nt.links.new(tc.outputs["Object"], env.inputs["Vector"])
    _rendered(world_mod.world_setup(world), "Texture Coordinate > Generated")
    nt.links.remove(env.inputs["Vector"].links[0])

    env.projection = "MIRROR_BALL"
    _rendered(world_mod.world_setup(world), "projection")
    env.projection = "EQUIRECTANGULAR"
    link = bg.inputs["Color"].links[0]
    link.is_muted = True                     # a muted link is no link: a plain colour
    bg.inputs["Color"].default_value = (0.05, 0.1, 0.2, 1.0)
    setup = world_mod.world_setup(world)
    assert setup.usable and setup.source == "constant" and setup.colour == pytest.approx((0.05, 0.1, 0.2))
    assert setup.live_strength == bg.inputs["Strength"] and setup.label.startswith("plain colour")
    nt.links.remove(link)
    assert world_mod.world_setup(world).source == "constant"
    nt.links.new(env.outputs["Color"], bg.inputs["Color"])

    env.image = None
    _rendered(world_mod.world_setup(world), "no image")
    missing = bpy.data.images.new("missing", 4, 4)
    missing.source = "FILE"
    missing.filepath = "/nonexistent/rtl_missing.exr"
    env.image = missing
    _rendered(world_mod.world_setup(world), "no pixels")
    byte = _image(bpy, "byte", _environment()[:, :, :] / 8.0, float_buffer=False)
    env.image = byte
    assert world_mod.world_setup(world).usable             # 8-bit sRGB: decoded
    byte.colorspace_settings.name = "Linear Rec.2020"
    _rendered(world_mod.world_setup(world), "colour space")
    env.image = image

    emission = nt.nodes.new("ShaderNodeEmission")
    nt.links.new(emission.outputs[0], nt.nodes["World Output"].inputs["Surface"])
    setup = _rendered(world_mod.world_setup(world), "Emission")
    assert setup.live_strength is None                 # baked with whatever strength the tree gives
    nt.links.new(bg.outputs[0], nt.nodes["World Output"].inputs["Surface"])
    value = nt.nodes.new("ShaderNodeValue")
    nt.links.new(value.outputs[0], bg.inputs["Strength"])
    assert _rendered(world_mod.world_setup(world), "Strength is linked").live_strength is None
    nt.links.remove(bg.inputs["Strength"].links[0])
    assert world_mod.world_setup(world).source == "image"
    # what shows nothing is refused: a muted Background, nothing into the output, no output
    bg.mute = True
    setup = world_mod.world_setup(world)
    assert not setup.usable and "muted" in setup.reason
    bg.mute = False
    nt.links.remove(nt.nodes["World Output"].inputs["Surface"].links[0])
    assert "nothing linked" in world_mod.world_setup(world).reason


@pytest.mark.parametrize("vector_type", ["POINT", "VECTOR"])
def test_world_setup_mapping(bpy_module, world_mod, vector_type):
    bpy = bpy_module
    scene = bpy.context.scene
    world = _world(bpy, scene, _image(bpy, "env", _environment()), mapping=vector_type)
    m = world.node_tree.nodes['Mapping "rot"']
    m.inputs["Rotation"].default_value = (0.1, -0.2, 0.3)
    setup = world_mod.world_setup(world)
    assert setup.usable and setup.mapping == m

    def reason():
        r = _rendered(world_mod.world_setup(world), "unsupported Mapping").note
        assert r.startswith("unsupported Mapping"), r
        return r

    m.inputs["Scale"].default_value = (2.0, 1.0, 1.0)
    assert "Scale" in reason()
    m.inputs["Scale"].default_value = (1.0, 1.0, 1.0)
    location = m.inputs[1]                    # by name only while available (Point): 5.0 hides it for Vector
    location.default_value = (0.0, 0.5, 0.0)
    if vector_type == "POINT":
        assert "Location" in reason()
    else:                                     # a Vector mapping ignores Location
        assert world_mod.world_setup(world).usable
    location.default_value = (0.0, 0.0, 0.0)
    value = world.node_tree.nodes.new("ShaderNodeCombineXYZ")
    link = world.node_tree.links.new(value.outputs[0], m.inputs["Rotation"])
    assert "Rotation input is linked" in reason()
    world.node_tree.links.remove(link)
    m.vector_type = "TEXTURE"
    assert "TEXTURE" in reason()
    m.vector_type = vector_type
    world.node_tree.links.remove(m.inputs["Vector"].links[0])
    # Measured: an unlinked Mapping Vector is the constant (0, 0, 0), not the view direction
    assert "Vector input is unlinked" in reason()


def test_world_image_array_orientation_and_cleaning(bpy_module, world_mod):
    bpy = bpy_module
    import mathutils

    src = _environment()
    src[10, 5] = (np.nan, np.inf, -np.inf)
    src[11, 6] = (-0.5, 0.25, 0.0)
    arr = world_mod.world_image_array(_image(bpy, "env", src))
    assert arr.shape == (H, W, 3) and arr.dtype == np.float32
    # row 0 is the top scanline (+Z): the bright band
    np.testing.assert_array_equal(arr[:4], np.broadcast_to(np.float32([8.0, 6.0, 4.0]), (4, W, 3)))
    np.testing.assert_array_equal(arr[10, 5], 0.0)
    np.testing.assert_array_equal(arr[11, 6], [0.0, 0.25, 0.0])
    clean = src.copy()
    clean[10, 5] = 0.0
    clean[11, 6, 0] = 0.0
    np.testing.assert_array_equal(arr, clean)

    # 8-bit sRGB: bytes / 255 decoded as Blender decodes sRGB
    ramp = np.tile(np.linspace(0.0, 1.0, W, dtype=np.float32)[None, :, None], (H, 1, 3))
    byte = _image(bpy, "byte", ramp, float_buffer=False)
    raw = np.empty(W * H * 4, np.float32)
    byte.pixels.foreach_get(raw)
    raw = raw.reshape(H, W, 4)[::-1, :, :3]
    got = world_mod.world_image_array(byte)
    assert np.all(got[0] == got[-1]) and got[0, -1, 0] == pytest.approx(1.0)
    from rt_lookdev.addon import compat

    lut = [mathutils.Color((v, v, v)).from_srgb_to_scene_linear()[0] for v in raw[0, :, 0]]
    np.testing.assert_allclose(got[0, :, 0], lut, atol=max(1e-6, 1.05 * compat.srgb_decoding_error()))
    byte.colorspace_settings.name = "Non-Color"          # regenerates a generated image: set the bytes again
    rgba = np.ones((H, W, 4), np.float32)
    rgba[..., :3] = raw
    byte.pixels.foreach_set(rgba[::-1].ravel())
    np.testing.assert_array_equal(world_mod.world_image_array(byte), raw)


def test_bake_world_is_cached_by_content(bpy_module, world_mod, small, tmp_path, monkeypatch):
    bpy = bpy_module
    from rt_lookdev.core.environment import equirect, prefilter, sh

    scene = bpy.context.scene
    assert world_mod.bake_world(scene, tmp_path, settings=small) is None       # no world
    image = _image(bpy, "My Env.exr", _environment())
    _world(bpy, scene, image)
    calls = []
    first = world_mod.bake_world(scene, tmp_path, progress=lambda *a: calls.append(a), settings=small)
    assert first.states == {"sh": "baked", "prefiltered": "baked"}
    assert calls[-1] == ("prefiltered", 3, 3)
    array = world_mod.world_image_array(image)
    assert first.source_hash == equirect.image_hash(array)
    assert first.name == f"My_Env_{first.source_hash[:12]}" and first.source == "generated:My Env.exr"
    assert first.prefiltered_path.parent == tmp_path and first.prefiltered_path.name.startswith(first.name)
    np.testing.assert_allclose(first.sh_image, sh.sh_project(array), rtol=1e-6, atol=1e-7)
    levels, rl, _ = prefilter.read_prefiltered(first.prefiltered_path)
    assert levels.shape == (3, 8, 16, 3) and rl == [0.0, 0.5, 1.0]

    def boom(*a, **k):
        raise AssertionError("a cached re-run must not compute")
    with monkeypatch.context() as mp:
        mp.setattr(prefilter, "prefilter", boom)
        mp.setattr(sh, "sh_project", boom)
        again = world_mod.bake_world(scene, tmp_path, settings=small)
    assert again.states == {"sh": "cached", "prefiltered": "cached"}
    np.testing.assert_array_equal(again.sh_image, first.sh_image)

    # same name, other content: other files, the first bake's files stay
    other = _environment(seed=4)
    image.pixels.foreach_set(np.concatenate([other, np.ones((H, W, 1), np.float32)], -1)[::-1].ravel())
    second = world_mod.bake_world(scene, tmp_path, settings=small)
    assert second.states == {"sh": "baked", "prefiltered": "baked"}
    assert second.source_hash != first.source_hash and second.prefiltered_path != first.prefiltered_path
    assert first.prefiltered_path.is_file() and first.sh_path.is_file()
    assert prefilter.read_sh(first.sh_path)[1]["source_hash"] == first.source_hash

    # default folder: $RTL_ENVIRONMENT_CACHE
    assert world_mod.default_cache_dir() == tmp_path / "env-cache"
    assert world_mod.default_cache_dir().is_dir()
    monkeypatch.delenv(world_mod.CACHE_ENV)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert world_mod.default_cache_dir() == tmp_path / "xdg" / "rt_lookdev" / "environments"


def _use_group(bpy, scene, group):
    """An object whose material instances ``group`` (drivers inside a group evaluate only while the
    view layer uses it) and links two of its outputs."""
    from rt_lookdev.addon import compat

    mat = compat.new_material("uses RTL World")
    nt = mat.node_tree
    node = nt.nodes.new("ShaderNodeGroup")
    node.node_tree = group
    emission = nt.nodes.new("ShaderNodeEmission")
    nt.links.new(node.outputs["World Strength"], emission.inputs["Strength"])
    nt.links.new(node.outputs["World SH 0"], emission.inputs["Color"])
    obj = bpy.data.objects.new("user", bpy.data.meshes.new("user"))
    obj.data.materials.append(mat)
    scene.collection.objects.link(obj)
    return mat, node


def test_sync_world_group_and_drivers(bpy_module, world_mod, small, tmp_path):
    bpy = bpy_module
    scene = bpy.context.scene
    world = _world(bpy, scene, _image(bpy, "env", _environment()), mapping="POINT")
    bg = world.node_tree.nodes["Background"]
    m = world.node_tree.nodes['Mapping "rot"']
    bg.inputs["Strength"].default_value = 1.5
    m.inputs["Rotation"].default_value = (0.1, -0.2, 0.3)

    record = world_mod.sync_world(scene, tmp_path, settings=small)
    bake = world_mod.bake_world(scene, tmp_path, settings=small)
    assert bake.states == {"sh": "cached", "prefiltered": "cached"}
    assert record == {"table": bake.table_name, "prefiltered": str(bake.prefiltered_path),
                      "sh": str(bake.sh_path), "source_hash": bake.source_hash, "image": "env", "source": "image",
                      "roughness_levels": [0.0, 0.5, 1.0]}
    ng = bpy.data.node_groups[world_mod.WORLD_GROUP]
    assert ng["rtl_world"].to_dict() == record
    assert record["table"] == f"env_{bake.prefiltered_hash[:12]}"
    env, _ = world_mod.world_environment()
    assert env.name == record["table"] and env.as_table().source == bake.prefiltered_path

    outputs = [(it.name, it.socket_type) for it in ng.interface.items_tree if it.item_type == "SOCKET"]
    assert outputs == ([(f"World SH {i}", "NodeSocketVector") for i in range(9)]
                       + [("World Strength", "NodeSocketFloat"), ("World Rotation", "NodeSocketVector")])
    assert all(it.in_out == "OUTPUT" for it in ng.interface.items_tree if it.item_type == "SOCKET")
    out = next(n for n in ng.nodes if n.bl_idname == "NodeGroupOutput")
    for i in range(9):
        node = out.inputs[f"World SH {i}"].links[0].from_node
        assert node.bl_idname == "ShaderNodeCombineXYZ"
        np.testing.assert_array_equal([s.default_value for s in node.inputs[:3]], bake.sh_image[i].astype(np.float32))
    strength = out.inputs["World Strength"].links[0].from_node
    rotation = out.inputs["World Rotation"].links[0].from_node
    assert strength.bl_idname == "ShaderNodeValue" and strength.outputs[0].default_value == 1.5
    np.testing.assert_allclose([s.default_value for s in rotation.inputs[:3]], (0.1, -0.2, 0.3), rtol=1e-6)
    drivers = {fc.data_path: fc.driver for fc in ng.animation_data.drivers}
    assert len(drivers) == 4
    assert all(d.is_valid and d.is_simple_expression and d.variables[0].targets[0].id == world
               for d in drivers.values())
    assert drivers['nodes["Strength"].outputs[0].default_value'].variables[0].targets[0].data_path == \
        'node_tree.nodes["Background"].inputs[1].default_value'
    assert drivers['nodes["Rotation"].inputs[2].default_value'].variables[0].targets[0].data_path == \
        'node_tree.nodes["Mapping \\"rot\\""].inputs[2].default_value[2]'

    params = world_mod.world_parameters(scene)
    assert params["Strength"] == pytest.approx(bg.inputs["Strength"].default_value)
    np.testing.assert_allclose(params["Rotation"], (0.1, -0.2, 0.3), rtol=1e-6)
    for i in range(9):
        np.testing.assert_allclose(params[f"SH {i}"], bake.sh_image[i], rtol=1e-6)

    # drivers follow the world (once the view layer uses the group)
    mat, user = _use_group(bpy, scene, ng)
    bg.inputs["Strength"].default_value = 2.25
    m.inputs["Rotation"].default_value[2] = -0.7
    bpy.context.view_layer.update()
    assert strength.outputs[0].default_value == 2.25
    assert rotation.inputs[2].default_value == pytest.approx(-0.7)
    assert world_mod.world_parameters(scene)["Strength"] == 2.25

    # a re-sync rebuilds in place: same group, interface and the users' links kept
    pointer = ng.as_pointer()
    assert world_mod.sync_world(scene, tmp_path, settings=small) == record
    ng = bpy.data.node_groups[world_mod.WORLD_GROUP]
    assert ng.as_pointer() == pointer and user.node_tree == ng
    assert user.outputs["World Strength"].is_linked and user.outputs["World SH 0"].is_linked
    assert len(ng.animation_data.drivers) == 4
    assert len([n for n in ng.nodes if n.bl_idname == "ShaderNodeValue"]) == 1

    # no Mapping: rotation is a static 0, no rotation drivers
    world.node_tree.links.remove(world.node_tree.nodes["Environment Texture"].inputs["Vector"].links[0])
    world_mod.sync_world(scene, tmp_path, settings=small)
    assert [fc.data_path for fc in ng.animation_data.drivers] == ['nodes["Strength"].outputs[0].default_value']
    assert [s.default_value for s in ng.nodes["Rotation"].inputs[:3]] == [0.0, 0.0, 0.0]
    np.testing.assert_array_equal(world_mod.world_parameters(scene)["Rotation"], 0.0)

    # a plain colour: a constant world (one texel baked), the strength still driven, no rotation
    world.node_tree.links.remove(bg.inputs["Color"].links[0])
    bg.inputs["Color"].default_value = (0.2, 0.4, 0.8, 1.0)
    record = world_mod.sync_world(scene, tmp_path, settings=small)
    assert record["source"] == "constant" and record["image"] == "plain colour (0.2, 0.4, 0.8)"
    assert [fc.data_path for fc in ng.animation_data.drivers] == ['nodes["Strength"].outputs[0].default_value']
    params = world_mod.world_parameters(scene)
    np.testing.assert_allclose(params["SH 0"], np.array([0.2, 0.4, 0.8]) * 2 * np.sqrt(np.pi), rtol=1e-5)
    np.testing.assert_allclose([params[f"SH {i}"] for i in range(1, 9)], 0.0, atol=1e-6)
    assert params["Strength"] == pytest.approx(bg.inputs["Strength"].default_value)

    # a world that shows nothing: the group goes, the World term is off
    bg.mute = True
    assert world_mod.sync_world(scene, tmp_path, settings=small) is None
    assert world_mod.WORLD_GROUP not in bpy.data.node_groups
    assert world_mod.world_parameters(scene) is None
    assert world_mod.sync_world(scene, tmp_path, settings=small) is None


@pytest.fixture
def sync_operator(bpy_module):
    from rt_lookdev.addon.operators import RTL_OT_sync_world

    bpy_module.utils.register_class(RTL_OT_sync_world)
    yield bpy_module.ops.rtl.sync_world
    bpy_module.utils.unregister_class(RTL_OT_sync_world)


def test_sync_world_operator(bpy_module, world_mod, small, sync_operator, capfd, monkeypatch):
    bpy = bpy_module
    from rt_lookdev.core.environment import prefilter

    # the operator bakes with the default settings; keep them small here
    monkeypatch.setattr(prefilter, "PrefilterSettings", lambda: small)
    scene = bpy.context.scene
    assert sync_operator.poll()
    assert sync_operator() == {'FINISHED'}
    assert "RT Lit World term off: the scene has no World" in capfd.readouterr().out
    _world(bpy, scene, _image(bpy, "env", _environment()))
    assert sync_operator() == {'FINISHED'}
    out = capfd.readouterr().out
    assert "RT Lit World: 'env' baked in" in out and "0 RT Lit groups rebuilt" in out
    record = dict(bpy.data.node_groups[world_mod.WORLD_GROUP]["rtl_world"])
    assert record["prefiltered"].startswith(str(world_mod.default_cache_dir()))
    assert sync_operator() == {'FINISHED'}
    assert "RT Lit World: 'env' cached" in capfd.readouterr().out


def test_sync_world_switches_the_rt_lit_term_and_drops_stale_images(bpy_module, world_mod, small, sync_operator,
                                                                   monkeypatch, lut_dir):
    """An RT Lit material gets the World term after a sync, a re-bake with other settings gives another
    table (and the old packed image is removed), and a world without image removes the term and its image."""
    bpy = bpy_module
    from rt_lookdev.addon import materials, node_emit
    from rt_lookdev.core.environment import prefilter

    scene = bpy.context.scene
    mesh = bpy.data.meshes.new("quad")
    mesh.from_pydata([(0, 0, 0), (1, 0, 0), (1, 1, 0)], [], [(0, 1, 2)])
    obj = bpy.data.objects.new("tri", mesh)
    scene.collection.objects.link(obj)
    mat = bpy.data.materials.new("rt")
    obj.data.materials.append(mat)
    settings_class = prefilter.PrefilterSettings
    monkeypatch.setattr(prefilter, "PrefilterSettings", lambda: small)

    def world_groups():
        ng = mat.node_tree.nodes["RT Lit"].node_tree
        # one per engine tree: the Cycles tree's carries the suffix " (Linear)"
        return {name.removesuffix(" (Linear)") for name in node_emit.tree_node_counts(ng)
                if name.startswith("RTL Shade World")}

    def env_images():
        return sorted(i.name for i in bpy.data.images if i.name.startswith("RTL_env_"))

    materials.assign_rt_lit(mat, scene=scene, lut_dir=lut_dir)
    assert not world_groups() and not env_images()          # no world: nothing built or loaded
    _world(bpy, scene, _image(bpy, "env", _environment()))
    assert sync_operator() == {'FINISHED'}
    first = dict(bpy.data.node_groups[world_mod.WORLD_GROUP]["rtl_world"])["table"]
    assert len(world_groups()) == 1 and env_images() == [f"RTL_{first}"]

    other = settings_class(32, 16, (0.0, 0.5, 1.0))
    monkeypatch.setattr(prefilter, "PrefilterSettings", lambda: other)
    assert sync_operator() == {'FINISHED'}
    second = dict(bpy.data.node_groups[world_mod.WORLD_GROUP]["rtl_world"])["table"]
    assert second != first and env_images() == [f"RTL_{second}"]
    assert tuple(bpy.data.images[f"RTL_{second}"].size) == (32, 16 * 3)

    scene.world.node_tree.nodes["Background"].mute = True         # a world that shows nothing: no World term
    assert sync_operator() == {'FINISHED'}
    assert world_mod.WORLD_GROUP not in bpy.data.node_groups
    assert not world_groups() and not env_images()


def test_rt_lit_rebuilds_from_the_packed_image_when_the_cache_is_gone(bpy_module, world_mod, small, lut_dir,
                                                                     tmp_path):
    """The .blend carries the prefiltered image: with the cache file deleted (another machine), the RT
    Lit group is traced from the packed pixels, gets the same stamp (no rebuild) and the same values."""
    bpy = bpy_module
    from rt_lookdev.addon import materials
    from rt_lookdev.core.materials.world_shading import WorldEnvironment

    scene = bpy.context.scene
    _world(bpy, scene, _image(bpy, "env", _environment()))
    record = world_mod.sync_world(scene, tmp_path / "cache", settings=small)
    mat = bpy.data.materials.new("rt")
    materials.assign_rt_lit(mat, scene=scene, lut_dir=lut_dir)
    ng = mat.node_tree.nodes["RT Lit"].node_tree
    stamp = ng["rtl_stamp"]
    from_file = WorldEnvironment.load(record["prefiltered"], record["table"])
    for path in (tmp_path / "cache").iterdir():
        path.unlink()
    env, _ = world_mod.world_environment()
    np.testing.assert_array_equal(env.table, from_file.table)
    assert env.roughness_levels == from_file.roughness_levels == tuple(small.roughness)
    again = materials.ensure_rt_lit_group(scene=scene, lut_dir=lut_dir)
    assert again == ng and ng["rtl_stamp"] == stamp
    bpy.data.images.remove(bpy.data.images[f"RTL_{record['table']}"])
    with pytest.raises(RuntimeError, match="Sync RT Lit World again"):
        world_mod.world_environment()


def test_world_occlusion_reads_cycles_ambient_occlusion(bpy_module, world_mod, small, lut_dir, tmp_path):
    """World occlusion (``Features.occlusion``, issue 29): each engine tree of an occluded RT Lit material takes
    the "Ambient Occlusion" input from an Ambient Occlusion node.  Rendered by Cycles, a floor open to the sky
    (the AO rays all miss: AO = 1) looks exactly as without occlusion, and the same floor inside a closed box
    (every ray hits: AO = 0) receives nothing from the world, where the unoccluded material still shows it."""
    bpy = bpy_module
    from rt_lookdev.addon import materials
    from rt_lookdev.core.materials.rt_lit_interface import OCCLUSION_INPUT, Features
    from rt_lookdev.validation.harness.engines import render_engines

    scene = bpy.context.scene
    _world(bpy, scene, _image(bpy, "env", _environment()))
    world_mod.sync_world(scene, tmp_path, settings=small)
    mesh = bpy.data.meshes.new("floor")
    mesh.from_pydata([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], [], [(0, 1, 2, 3)])
    floor = bpy.data.objects.new("floor", mesh)
    scene.collection.objects.link(floor)
    mat = bpy.data.materials.new("rt occluded")
    floor.data.materials.append(mat)
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    camera.location = (0.0, -0.6, 1.2)
    camera.rotation_euler = (0.45, 0.0, 0.0)
    scene.collection.objects.link(camera)
    scene.camera = camera

    def render(features):
        materials.assign_rt_lit(mat, features, scene=scene, lut_dir=lut_dir)
        return render_engines(scene, ("CYCLES",), resolution=12, samples=1)["CYCLES"][0]

    occluded = Features("turquin", "cod", occlusion="cones_clipped")
    open_plain, open_occluded = render(Features("turquin", "cod")), render(occluded)
    ng = mat.node_tree.nodes[materials.RT_LIT_NODE_NAME].node_tree
    for engine, *_ in materials.ENGINE_TREES:
        tree = ng.nodes[engine].node_tree
        ao = [n for n in tree.nodes if n.bl_idname == "ShaderNodeAmbientOcclusion"]
        assert len(ao) == 1 and ao[0].outputs["AO"].is_linked, engine
        assert ao[0].inputs["Distance"].default_value == materials.AO_DISTANCE
        assert any(link.to_socket.name == OCCLUSION_INPUT for link in tree.links if link.from_node == ao[0]), engine
    assert open_plain.min() > 0.05
    np.testing.assert_allclose(open_occluded, open_plain, rtol=1e-5, atol=1e-7)

    box = bpy.data.meshes.new("box")             # a closed box around the floor and the camera
    box.from_pydata([(x, y, z) for x in (-3, 3) for y in (-3, 3) for z in (-1, 3)], [],
                    [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)])
    scene.collection.objects.link(bpy.data.objects.new("box", box))
    boxed_occluded, boxed_plain = render(occluded), render(Features("turquin", "cod"))
    np.testing.assert_allclose(boxed_plain, open_plain, rtol=1e-6)      # the unoccluded material ignores the box
    assert boxed_occluded.max() <= 1e-6


def test_render_world_array_has_the_environment_texture_layout(bpy_module, world_mod):
    """Issue 33: a world of nodes is baked from Cycles' equirectangular panoramic render (``render_world_array``),
    which must lay the world out as an Environment Texture is read (core/environment/equirect.py: row 0 at the
    zenith, u = 0.5 - atan2(y, x) / 2 pi).  A world showing its Generated direction (x 0.5 + 0.5) at Strength 3,
    rendered with that Background at Strength 1: each pixel within 3e-3 of the mean of the directions over its area
    in the mean (measured 8e-4 at 256 x 128, 4 samples), whatever the strength; the scene, camera and world copy it
    made are removed, and the user's render in "Render Result" is kept (its own slot)."""
    bpy = bpy_module
    from rt_lookdev.addon import compat
    from rt_lookdev.core.environment import equirect

    world = compat.new_world("directions")
    nt = world.node_tree
    bg = nt.nodes["Background"]
    bg.inputs["Strength"].default_value = 3.0
    coords = nt.nodes.new("ShaderNodeTexCoord")
    scale = nt.nodes.new("ShaderNodeVectorMath")
    scale.operation = "MULTIPLY_ADD"
    scale.inputs[1].default_value = scale.inputs[2].default_value = (0.5, 0.5, 0.5)
    nt.links.new(coords.outputs["Generated"], scale.inputs[0])
    nt.links.new(scale.outputs[0], bg.inputs["Color"])
    def blocks():           # Blender's own "Render Result" image appears with a session's first render
        return {kind: set(getattr(bpy.data, kind).keys()) - {"Render Result"}
                for kind in ("scenes", "worlds", "cameras", "objects", "images")}

    before = blocks()
    image = world_mod.render_world_array(world, "Background", width=128, samples=4)
    assert blocks() == before
    assert image.shape == (64, 128, 3) and image.dtype == np.float32
    fine = equirect.texel_directions(64 * 4, 128 * 4).reshape(64, 4, 128, 4, 3).mean(axis=(1, 3))
    error = np.abs(image - (fine * 0.5 + 0.5)).max(axis=-1)
    assert error.mean() <= 3e-3, error.mean()
    assert bg.inputs["Strength"].default_value == 3.0            # the original world untouched
    # the user's last render stays in its "Render Result" slot: world renders go to a slot of their own, reused
    slots = bpy.data.images["Render Result"].render_slots
    slots.active_index = 0
    world_mod.render_world_array(world, "Background", width=16, samples=1)
    count = len(slots)
    world_mod.render_world_array(world, "Background", width=16, samples=1)
    assert slots.active_index == 0 and len(slots) == count
    assert [slot.name for slot in slots].count(world_mod.RENDER_SLOT) == 1


def test_constant_world_values_are_cleaned(bpy_module, world_mod):
    """A plain colour with a NaN, an infinite or a negative channel (a driver, a typo) bakes as Cycles shows it: 0
    there (Cycles shows negative radiance as 0), the rest as it is; one texel, finite."""
    from rt_lookdev.addon import compat

    world = compat.new_world("odd")
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (float("nan"), -0.5, 0.25, 1.0)
    setup = world_mod.world_setup(world)
    assert setup.source == "constant"
    array = world_mod.world_array(setup)
    assert array.shape == (1, 1, 3) and array.dtype == np.float32
    np.testing.assert_array_equal(array[0, 0], [0.0, 0.0, 0.25])
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (float("inf"), 1.0, 1.0, 1.0)
    assert np.isfinite(world_mod.world_array(world_mod.world_setup(world))).all()
