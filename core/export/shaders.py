"""Write an RT Lit material's shaders for an engine: the fragment and vertex shader in each dialect, the
uniform interface as JSON, and the tables the shader samples.

    write_material_shaders(folder, material, dialects=("glsl450", "glsl300es", "hlsl"), luts=None)

``folder`` gets ``rt_lit.<dialect>.frag`` / ``.vert`` (``.ps.hlsl`` / ``.vs.hlsl`` for HLSL),
``interface.json`` (the uniforms in declaration order with their types and meanings, the light slots,
and per table its texture uniform, size and file) and, when ``luts`` (a LUT folder) is given, the LUT
files the material reads (the world's prefiltered table too, when the material has one).  Written to a
temporary sibling folder and renamed into place, like the scene export.
"""
from __future__ import annotations

import argparse
import json
import shutil
from pathlib import Path

from ..lights import OPTION_KINDS, split_kind
from ..lut import catalog
from ..lut.exr_io import LutError
from ..materials import rt_lit, rt_lit_shader
from ..materials.rt_lit_interface import (DIFFUSE_MODELS, Features, LIGHT_KINDS, PRINCIPLED_SHEEN, SHEEN_MODELS,
                                          SPECULAR_MODELS)
from ..materials.world_shading import WorldEnvironment
from .folders import replacing_folder

EXTENSIONS = {"glsl450": ("glsl450.frag", "glsl450.vert"), "glsl300es": ("glsl300es.frag", "glsl300es.vert"),
              "hlsl": ("ps.hlsl", "vs.hlsl")}


def interface(shader):
    """The uniform interface of a ``MaterialShader`` as plain data."""
    return {"material": shader.material.name, "features": shader.material.features.as_dict(),
            "light_slots": [{"kind": kind, "uniform": f"{rt_lit_shader.light_array(kind)}[{index}]",
                             "struct": rt_lit_shader.light_struct(kind),
                             "fields": [{"field": f, "type": t, "parameters": [p for p, _ in parts]}
                                        for f, t, parts in rt_lit_shader.light_fields(kind)]}
                            for kind, index in shader.light_slots],
            "uniforms": [{"name": u.name, "type": u.type, "meaning": u.meaning} for u in shader.uniforms],
            "tables": {name: {"uniform": texture, "height": h, "width": w, "format": "RGBA32F",
                              "rows": "texel row j covers v in [j/H, (j + 1)/H): upload the EXR's last scanline as row 0", "read": "exact texel fetches (no sampler state)"}
                       for name, (texture, h, w) in shader.tables.items()},
            "output": "frag_radiance: RGB outgoing radiance towards the camera (scene-linear), alpha 1"}


def write_material_shaders(folder, material, dialects=tuple(EXTENSIONS), luts=None, precise=True):
    """Write ``material`` (``rt_lit.RtLitMaterial``) into ``folder``; returns the files written (names)."""
    unknown = [d for d in dialects if d not in EXTENSIONS]
    if unknown:
        raise ValueError(f"unknown dialects {unknown}; choose from {sorted(EXTENSIONS)}")
    written = []
    with replacing_folder(folder) as tmp:
        shaders = {}
        for dialect in dialects:
            shader = rt_lit_shader.material_shader(material, dialect, precise)
            shaders[dialect] = shader
            frag, vert = EXTENSIONS[dialect]
            (tmp / f"rt_lit.{frag}").write_text(shader.fragment)
            (tmp / f"rt_lit.{vert}").write_text(shader.vertex)
            written += [f"rt_lit.{frag}", f"rt_lit.{vert}"]
        first = next(iter(shaders.values()))
        data = interface(first)
        if luts is not None:
            for name, entry in data["tables"].items():
                if name in catalog.TABLES:
                    source = Path(luts) / catalog.TABLES[name].filename
                elif material.environment is not None and name == material.environment.name \
                        and material.environment.source is not None:
                    source = Path(material.environment.source)
                else:
                    raise ValueError(f"table {name!r} has no file to copy (an environment without its EXR)")
                if not source.is_file():
                    raise FileNotFoundError(f"table {name!r}: {source} does not exist (bake the LUTs first)")
                shutil.copyfile(source, tmp / source.name)
                entry["file"] = source.name
                written.append(source.name)
        (tmp / "interface.json").write_text(json.dumps(data, indent=1))
        written.append("interface.json")
    return written


def _light_kinds(text):
    """--lights: the kinds in order ("quad,disk+cone+range"); a bad one is argparse's error, naming the valid ones."""
    kinds = tuple(k for k in text.split(",") if k)
    for kind in kinds:
        try:
            split_kind(kind)
        except ValueError as exc:
            options = "; ".join(f"+{o} on {', '.join(bases)}" for o, bases in OPTION_KINDS.items())
            raise argparse.ArgumentTypeError(f"{exc}; the options, in this order: {options} "
                                             "(quad+cone+range)") from None
    return kinds


def _dialects(text):
    """--dialects: one or more of ``EXTENSIONS``, comma-separated."""
    dialects = tuple(d for d in text.split(",") if d)
    unknown = [d for d in dialects if d not in EXTENSIONS]
    if unknown or not dialects:
        what = f"unknown dialects {', '.join(unknown)}" if unknown else "no dialect"
        raise argparse.ArgumentTypeError(f"{what}; choose from {', '.join(EXTENSIONS)}")
    return dialects


#: What --world takes, for its errors.
_WORLD_FILE = "a world bake's prefiltered EXR (<name>_ggx_prefiltered.exr of python scripts/bake_environment.py)"


def _world(parser, path, table):
    """The --world environment, or the parser's one-line error saying what is wrong with the file."""
    if not path.is_file():
        parser.error(f"argument --world: {path} does not exist; it takes {_WORLD_FILE}")
    try:
        return WorldEnvironment.load(path, table or path.stem)
    except (LutError, ValueError) as exc:
        parser.error(f"argument --world: {path} is not {_WORLD_FILE}: {exc.__cause__ or exc}")


def parse_args(argv):
    """The options of scripts/export_shader.py, checked: a bad one ends in argparse's one-line error (exit code 2).
    ``environment``: the --world file loaded (a ``WorldEnvironment``), or None."""
    p = argparse.ArgumentParser(description="Write the RT Lit material's shaders, interface and tables for an engine")
    p.add_argument("--out", type=Path, required=True)
    p.add_argument("--specular", default="turquin", choices=SPECULAR_MODELS)
    p.add_argument("--diffuse", default="cod", choices=DIFFUSE_MODELS)
    p.add_argument("--sheen", nargs="?", default="none", const=PRINCIPLED_SHEEN, choices=SHEEN_MODELS,
                   help=f"the sheen model (default none); --sheen alone: {PRINCIPLED_SHEEN}, Principled's sheen, as "
                        "Convert gives a Principled material with sheen (the talk's Disney sheen is disney_talk)")
    p.add_argument("--cloth", action="store_true")
    p.add_argument("--lights", type=_light_kinds, default="quad,disk",
                   help=f"light kinds in order, from {', '.join(LIGHT_KINDS)}; options as quad+cone+range")
    p.add_argument("--dialects", type=_dialects, default=",".join(EXTENSIONS),
                   help=f"comma-separated, from {', '.join(EXTENSIONS)} (default: all)")
    p.add_argument("--world", type=Path, default=None, help="a prefiltered environment EXR (a world bake)")
    p.add_argument("--world-table", default=None, help="its table name (default: the file's stem)")
    p.add_argument("--no-precise", action="store_true", help="let the compiler fuse and reorder arithmetic")
    p.add_argument("--lut-dir", type=Path, default=None)
    args = p.parse_args(argv)
    args.environment = _world(p, args.world, args.world_table) if args.world else None
    return args


def run_args(args, log=print):
    """scripts/export_shader.py: build the material the options name and write it; the exit code."""
    material = rt_lit.build_rt_lit(Features(args.specular, args.diffuse, args.sheen, args.cloth), args.lights,
                                   args.environment)
    written = write_material_shaders(args.out, material, args.dialects,
                                     args.lut_dir or catalog.default_lut_dir(), not args.no_precise)
    log(f"{material.name}: wrote {len(written)} files to {args.out}: {', '.join(written)}")
    return 0
