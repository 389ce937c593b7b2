"""A lookdev scene as files an engine (or the standalone renderer) reads: the scene description.

A folder holding

    scene.json       camera, lights, world, materials, objects (format ``FORMAT``, version ``VERSION``)
    geometry.npz     per object: world-space triangle corners ``<i>.positions`` (3T, 3) float32,
                     ``<i>.normals`` (3T, 3) float32 (the corner normals Cycles interpolates)
    tables/          the tables the materials read: the LUTs (the catalog's EXR files, as baked) and the
                     world's prefiltered levels (``<table name>.exr``)

Units and conventions are Blender's: metres, world space with +Z up, light parameters as the RT Lit
drivers read them (``core.lights.LIGHT_DATA``: "Location X", "Rotation W", ..., "Power", "Color R", ...),
material inputs by their RT Lit names, world SH in the image frame at strength 1 with the Background's
strength and the Mapping rotation alongside.  ``build_materials`` traces each material for the scene's
lights and world (``core.materials.rt_lit.build_rt_lit``), so a reader gets the same functions the
node groups were built from.

``write`` fills a temporary folder beside the target and renames it into place: an interrupted or
failed export leaves the previous folder (or none), never a partial one.  ``read`` checks what it reads
and names what is wrong and where.
"""
from __future__ import annotations

import json
import shutil
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from ..lights import split_kind
from ..lut import catalog
from ..lut.lookup import LutSet
from ..materials import rt_lit
from ..materials.rt_lit_interface import Features, LIGHT_KINDS
from ..materials.world_shading import WorldEnvironment
from .folders import replacing_folder

FORMAT = "rt-lookdev-scene"
VERSION = 1
SCENE_FILE = "scene.json"
GEOMETRY_FILE = "geometry.npz"
TABLES_DIR = "tables"
CAMERA_TYPES = ("ORTHO", "PERSP")
SENSOR_FITS = ("AUTO", "HORIZONTAL", "VERTICAL")


class SceneDescriptionError(ValueError):
    """A scene folder that cannot be read or written; the message says what and where."""


@dataclass
class Camera:
    """Blender's camera: ``matrix_world`` (4 x 4, row-major; looks along its -Z, +Y up), ``type`` ORTHO
    or PERSP, ``ortho_scale`` (m) or ``angle`` (radians, across the ``sensor_fit`` dimension), ``shift``
    (x, y) in units of the larger frame side, clipping (m), the render resolution (width, height)."""
    matrix_world: list
    type: str = "ORTHO"
    ortho_scale: float = 1.0
    angle: float = 0.8575
    sensor_fit: str = "AUTO"
    shift: tuple = (0.0, 0.0)
    clip_start: float = 0.1
    clip_end: float = 100.0
    resolution: tuple = (256, 256)

    def validate(self, where):
        m = np.asarray(self.matrix_world, np.float64)
        if m.shape != (4, 4) or not np.isfinite(m).all():
            raise SceneDescriptionError(f"{where}: camera matrix_world must be a finite 4 x 4 matrix")
        if self.type not in CAMERA_TYPES:
            raise SceneDescriptionError(f"{where}: camera type {self.type!r} is not supported (only {CAMERA_TYPES})")
        if self.sensor_fit not in SENSOR_FITS:
            raise SceneDescriptionError(f"{where}: sensor_fit {self.sensor_fit!r} is not one of {SENSOR_FITS}")
        w, h = self.resolution
        if int(w) < 1 or int(h) < 1:
            raise SceneDescriptionError(f"{where}: resolution {self.resolution} must be positive")
        if not 0.0 < self.clip_start < self.clip_end:
            raise SceneDescriptionError(f"{where}: clipping {self.clip_start}..{self.clip_end} is empty")
        size = self.ortho_scale if self.type == "ORTHO" else self.angle
        if not (np.isfinite(size) and size > 0.0) or (self.type == "PERSP" and size >= np.pi):
            raise SceneDescriptionError(f"{where}: camera {'ortho_scale' if self.type == 'ORTHO' else 'angle'} "
                                        f"{size} is not usable")

    @property
    def position(self):
        return np.asarray(self.matrix_world, np.float64)[:3, 3]

    @property
    def forward(self):
        """Unit view direction (-Z of the camera's world matrix)."""
        z = np.asarray(self.matrix_world, np.float64)[:3, 2]
        return -z / np.linalg.norm(z)

    def frame(self):
        """(half width, half height) of the view: at distance 1 for PERSP, in metres for ORTHO."""
        w, h = (float(x) for x in self.resolution)
        extent = 0.5 * (self.ortho_scale if self.type == "ORTHO" else 2.0 * np.tan(0.5 * self.angle))
        horizontal = self.sensor_fit == "HORIZONTAL" or (self.sensor_fit == "AUTO" and w >= h)
        return (extent, extent * h / w) if horizontal else (extent * w / h, extent)

    def view(self):
        """The view matrix (4 x 4, float64): world to Blender's camera frame (looking along -Z, +Y up)."""
        m = np.asarray(self.matrix_world, np.float64)
        rot = m[:3, :3] / np.linalg.norm(m[:3, :3], axis=0)          # no scale in the view
        view = np.eye(4)
        view[:3, :3] = rot.T
        view[:3, 3] = -rot.T @ m[:3, 3]
        return view

    def projection(self):
        """The OpenGL projection (4 x 4, float64): Blender's view frame mapped to NDC [-1, 1]^2, depth
        [clip_start, clip_end] to [-1, 1]."""
        hw, hh = self.frame()
        side = max(hw, hh)
        sx, sy = (2.0 * side * float(s) for s in self.shift)           # shift: units of the larger side
        n, f = float(self.clip_start), float(self.clip_end)
        proj = np.zeros((4, 4))
        if self.type == "ORTHO":
            proj[0, 0], proj[1, 1] = 1.0 / hw, 1.0 / hh
            proj[0, 3], proj[1, 3] = -sx / hw, -sy / hh
            proj[2, 2], proj[2, 3] = -2.0 / (f - n), -(f + n) / (f - n)
            proj[3, 3] = 1.0
        else:
            proj[0, 0], proj[1, 1] = 1.0 / hw, 1.0 / hh
            proj[0, 2], proj[1, 2] = sx / hw, sy / hh
            proj[2, 2], proj[2, 3] = -(f + n) / (f - n), -2.0 * f * n / (f - n)
            proj[3, 2] = -1.0
        return proj

    def view_projection(self):
        """The OpenGL clip-from-world matrix (4 x 4, float64) of this camera: ``projection() @ view()``."""
        return self.projection() @ self.view()


@dataclass
class SceneLight:
    """One light RT Lit shades: ``kind`` (core.materials.rt_lit_interface.LIGHT_KINDS) and its driver
    parameters (name -> float, Blender units)."""
    name: str
    kind: str
    parameters: dict


@dataclass
class SceneWorld:
    """The baked world: the prefiltered table's name and file (under tables/) and the World parameters
    ("SH 0".."SH 8": RGB, "Strength", "Rotation": Euler XYZ)."""
    table: str
    file: str
    parameters: dict


@dataclass
class SceneMaterial:
    """An RT Lit material: its ``Features`` (as a dict) and input values (RT_LIT_INPUTS name -> float or
    RGB); ``linked``: inputs linked to other nodes in Blender, exported at their unlinked value."""
    name: str
    features: dict
    inputs: dict
    linked: list = field(default_factory=list)


@dataclass
class SceneObject:
    """A mesh object drawn with ``material``; its triangles are in geometry.npz under key ``key``;
    ``excluded_lights``: the lights Blender's light linking keeps from it (their "Excluded" is 1 when it is drawn)."""
    name: str
    material: str
    key: str
    triangles: int = 0
    excluded_lights: list = field(default_factory=list)

    def light_values(self, lights):
        """The parameters of ``lights`` (SceneLights) as this object is drawn with them."""
        return [dict(light.parameters, Excluded=1.0) if light.name in self.excluded_lights else light.parameters
                for light in lights]


@dataclass
class SceneDescription:
    camera: Camera
    lights: list
    world: SceneWorld | None
    materials: dict
    objects: list
    tables: dict                      # table name -> file under tables/
    folder: Path | None = None
    source: str = ""                  # where it was exported from (the .blend)

    # -- reading the parts ----------------------------------------------------------------------------
    @property
    def light_kinds(self):
        return tuple(light.kind for light in self.lights)

    def geometry(self):
        """{object name: (positions (3T, 3) float32, normals (3T, 3) float32)} from geometry.npz."""
        path = self._path(GEOMETRY_FILE)
        try:
            with np.load(path) as data:
                out = {}
                for obj in self.objects:
                    pos, nrm = data[f"{obj.key}.positions"], data[f"{obj.key}.normals"]
                    if pos.shape != nrm.shape or pos.ndim != 2 or pos.shape[1] != 3 or len(pos) % 3:
                        raise SceneDescriptionError(f"{path}: object {obj.name!r} has positions {pos.shape} and "
                                                    f"normals {nrm.shape}; expected (3T, 3) each")
                    if not (np.isfinite(pos).all() and np.isfinite(nrm).all()):
                        raise SceneDescriptionError(f"{path}: object {obj.name!r} has non-finite vertices")
                    out[obj.name] = (np.asarray(pos, np.float32), np.asarray(nrm, np.float32))
                return out
        except KeyError as exc:
            raise SceneDescriptionError(f"{path}: no array {exc} (the file does not match {SCENE_FILE})") from None
        except (OSError, ValueError) as exc:
            if isinstance(exc, SceneDescriptionError):
                raise
            raise SceneDescriptionError(f"{path}: cannot read the geometry ({exc})") from None

    def environment(self):
        """The world's ``WorldEnvironment`` (None without a world)."""
        if self.world is None:
            return None

        path = self._path(TABLES_DIR, self.world.file)
        try:
            return WorldEnvironment.load(path, self.world.table)
        except Exception as exc:
            raise SceneDescriptionError(f"{path}: the world's prefiltered table cannot be read ({exc})") from None

    def table_set(self):
        """The table set the materials read: the LUTs of tables/ (verified on first use) and the world's."""
        folder = self._path(TABLES_DIR)
        luts = [name for name in self.tables if name in catalog.TABLES]
        for name in luts:
            if self.tables[name] != catalog.TABLES[name].filename:
                raise SceneDescriptionError(f"{self.folder / SCENE_FILE}: table {name!r} must be the file "
                                            f"{catalog.TABLES[name].filename}, not {self.tables[name]!r}")
            self._path(TABLES_DIR, self.tables[name])
        tables = LutSet.from_folder(folder, names=luts)
        env = self.environment()
        return tables if env is None else tables.with_tables(env.as_table())

    def build_materials(self):
        """{material name: core.materials.rt_lit.RtLitMaterial} traced for the scene's lights and world;
        each material's tables must be in the description."""
        env = self.environment()
        out = {}
        for name, mat in self.materials.items():
            try:
                features = Features.from_dict(mat.features)
                built = rt_lit.build_rt_lit(features, self.light_kinds, env)
            except ValueError as exc:
                raise SceneDescriptionError(f"{self.folder / SCENE_FILE}: material {name!r}: {exc}") from None
            missing = [t for t in built.table_names() if t not in self.tables and (env is None or t != env.name)]
            if missing:
                raise SceneDescriptionError(f"{self.folder / SCENE_FILE}: material {name!r} reads tables {missing}, "
                                            f"which the export does not hold (tables/ has {sorted(self.tables)})")
            out[name] = built
        return out

    def _path(self, *parts):
        if self.folder is None:
            raise SceneDescriptionError("this scene description has no folder (it was not read from one)")
        path = Path(self.folder, *parts)
        if not path.exists():
            raise SceneDescriptionError(f"{path} is missing: the export is incomplete (export it again)")
        return path

    # -- serialising -----------------------------------------------------------------------------------
    def to_json(self):
        return {"format": FORMAT, "version": VERSION, "source": self.source,
                "camera": asdict(self.camera),
                "lights": [asdict(light) for light in self.lights],
                "world": asdict(self.world) if self.world is not None else None,
                "materials": {name: asdict(m) for name, m in self.materials.items()},
                "objects": [asdict(o) for o in self.objects],
                "tables": dict(self.tables)}


def _json_value(value):
    """numpy values as JSON (json.dumps' ``default``)."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, (np.floating, np.integer)):
        return value.item()
    raise TypeError(f"{type(value).__name__} is not JSON serialisable")


def write(folder, description, geometry, table_files, log=None):
    """Write ``description`` (its ``tables``: name -> file name under tables/) with ``geometry`` ({object
    key: (positions, normals)}) and ``table_files`` ({file name: source path}) into ``folder``, atomically:
    everything goes to a temporary sibling folder that replaces ``folder`` only when complete."""
    folder = Path(folder)
    with replacing_folder(folder, SceneDescriptionError) as tmp:
        (tmp / TABLES_DIR).mkdir()
        for name, source in table_files.items():
            source = Path(source)
            if not source.is_file():
                raise SceneDescriptionError(f"table file {source} (for {name}) does not exist")
            shutil.copyfile(source, tmp / TABLES_DIR / name)
        arrays = {}
        for key, (positions, normals) in geometry.items():
            arrays[f"{key}.positions"] = np.asarray(positions, np.float32)
            arrays[f"{key}.normals"] = np.asarray(normals, np.float32)
        np.savez(tmp / GEOMETRY_FILE, **arrays)
        (tmp / SCENE_FILE).write_text(json.dumps(description.to_json(), indent=1, default=_json_value))
        read(tmp)                                   # what a reader will see: refuse to publish otherwise
    if log:
        log(f"scene export: {folder} ({len(description.objects)} objects, {len(description.lights)} lights, "
            f"{len(table_files)} tables)")
    return folder


def read(folder):
    """The ``SceneDescription`` in ``folder``; ``SceneDescriptionError`` naming the file and the problem."""
    folder = Path(folder)
    path = folder / SCENE_FILE
    try:
        data = json.loads(path.read_text())
    except FileNotFoundError:
        raise SceneDescriptionError(f"{path} is missing: {folder} is not an RT Lookdev scene export") from None
    except (OSError, ValueError) as exc:
        raise SceneDescriptionError(f"{path} cannot be read ({exc})") from None
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        raise SceneDescriptionError(f"{path}: not an RT Lookdev scene (format {data.get('format') if isinstance(data, dict) else None!r})")
    if data.get("version") != VERSION:
        raise SceneDescriptionError(f"{path}: version {data.get('version')} is not supported (this reader reads "
                                    f"version {VERSION}); export the scene again")

    try:
        camera = Camera(**data["camera"])
        lights = [SceneLight(**light) for light in data["lights"]]
        world = SceneWorld(**data["world"]) if data.get("world") else None
        materials = {name: SceneMaterial(**m) for name, m in data["materials"].items()}
        objects = [SceneObject(**o) for o in data["objects"]]
        tables = dict(data["tables"])
    except (KeyError, TypeError) as exc:
        raise SceneDescriptionError(f"{path}: malformed ({type(exc).__name__}: {exc})") from None
    camera.validate(path)
    for light in lights:
        try:
            split_kind(light.kind)
        except ValueError as exc:
            raise SceneDescriptionError(f"{path}: light {light.name!r} is of kind {light.kind!r}; RT Lit shades "
                                        f"{LIGHT_KINDS} ({exc})") from None
    for obj in objects:
        if obj.material not in materials:
            raise SceneDescriptionError(f"{path}: object {obj.name!r} uses material {obj.material!r}, which is not "
                                        "in the description")
    if world is not None and world.table not in tables:
        raise SceneDescriptionError(f"{path}: the world's table {world.table!r} is not listed in tables")
    for name, file in tables.items():
        if not (folder / TABLES_DIR / file).is_file():
            raise SceneDescriptionError(f"{folder / TABLES_DIR / file} is missing (table {name!r}); the export is "
                                        "incomplete: export the scene again")
    return SceneDescription(camera, lights, world, materials, objects, tables, folder, data.get("source", ""))
