"""three.js in a real browser: render cases with ``engines/three`` in headless Chromium and read back the numbers.

The browser side is ``engines/three/harness/harness.js`` (a metallic plane under a ``RectAreaLight``, rendered to a
float target with a chosen LTC table pair, plus a pass of world positions), driven by
``engines/three/tools/render_cases.mjs`` (playwright-core and Debian's ``chromium``; WebGL2 on SwiftShader).  This
module writes the spec, runs node, and decodes the result into numpy arrays; the truth at each pixel
(``pixel_frames``) is the caller's.

Needs ``node``, the package's ``node_modules`` (``npm ci`` in engines/three, which ``scripts/env.sh`` runs) and a
Chromium (``CHROMIUM``, default ``/usr/bin/chromium``): ``missing()`` says which is absent.
"""
from __future__ import annotations

import base64
import json
import os
import shutil
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[2]
PACKAGE = REPO / "engines" / "three"
CHROMIUM = os.environ.get("CHROMIUM", "/usr/bin/chromium")


def missing():
    """What the browser runs lack here (a sentence), or None when node, the package's modules and Chromium are all
    present."""
    if shutil.which("node") is None:
        return "node is not on PATH (Debian: apt-get install nodejs npm)"
    if not (PACKAGE / "node_modules" / "three").is_dir() or not (PACKAGE / "node_modules" / "playwright-core").is_dir():
        return f"{PACKAGE}/node_modules is not installed (npm ci --prefix {PACKAGE}; scripts/env.sh does it)"
    if not Path(CHROMIUM).exists():
        return f"no Chromium at {CHROMIUM} (Debian: apt-get install chromium; .ci/run does it)"
    return None


@dataclass
class ConfigResult:
    """One configuration's read-back: world positions (n, 3), the camera position (3,), the light's corners (4, 3)
    in three's order, per table pair the rendered value (n_roughness, n), and per patched variant its value (n,)."""
    positions: np.ndarray
    camera: np.ndarray
    corners: np.ndarray
    values: dict
    patched: dict


@dataclass
class Run:
    """A browser run: ``info`` (the WebGL renderer, three's revision, seconds), the configurations' read-backs, and
    the tables the page loaded (``spec["loadTables"]``): {precision: {"ltc1"/"ltc2": (64, 64, 4) array, row t = 0
    first}}."""
    info: dict
    configs: list
    tables: dict


def _floats(b64):
    return np.frombuffer(base64.b64decode(b64), dtype="<f4").astype(np.float64)


def run_node_tool(tool, args, out_name, timeout=600):
    """Run ``engines/three/tools/<tool>`` with ``args`` (the output file's option last, ``--out``) and return its JSON
    output; raises with node's output when it fails or the page reported errors."""
    reason = missing()
    if reason:
        raise RuntimeError(f"three.js browser run impossible: {reason}")
    with tempfile.TemporaryDirectory(prefix="rtl-browser-") as tmp:
        out_path = Path(tmp) / out_name
        proc = subprocess.run(["node", str(PACKAGE / "tools" / tool), *[str(a) for a in args], "--out", str(out_path)],
                              cwd=PACKAGE, capture_output=True, text=True, timeout=timeout,
                              env={**os.environ, "CHROMIUM": CHROMIUM})
        if proc.returncode != 0 or not out_path.exists():
            raise RuntimeError(f"{tool} failed (exit {proc.returncode}):\n{proc.stdout}\n{proc.stderr}")
        raw = json.loads(out_path.read_text())
    if raw.get("errors"):
        raise RuntimeError(f"the page of {tool} reported errors: " + "; ".join(raw["errors"]))
    return raw


def render(spec, data_dir=None, timeout=600):
    """Run ``spec`` (harness.js' ``rtlRender`` fields, and ``loadTables``) in the browser; returns a ``Run``.

    ``data_dir`` (served at /data/): ``export_tables``' folder, the ``ltc_code`` layout's EXRs in ``ltc_code/`` (the
    ``rtl_*`` pairs) and the ``rtl`` layout's f32 EXRs in ``rtl/`` (the patched variants).
    """
    spec = dict(spec, dataUrl=spec.get("dataUrl", "/data/ltc_code/"), rtlUrl=spec.get("rtlUrl", "/data/rtl/"))
    with tempfile.TemporaryDirectory(prefix="rtl-three-") as tmp:
        spec_path = Path(tmp) / "spec.json"
        spec_path.write_text(json.dumps(spec))
        args = ["--spec", spec_path] + (["--data", data_dir] if data_dir is not None else [])
        raw = run_node_tool("render_cases.mjs", args, "result.json", timeout)
    configs = []
    for item in raw["results"]:
        positions = np.stack([_floats(item[k]) for k in ("x", "y", "z")], axis=-1)
        values = {name: np.stack([_floats(b) for b in per_r]) for name, per_r in item["values"].items()}
        patched = {name: _floats(b) for name, b in item.get("patched", {}).items()}
        configs.append(ConfigResult(positions, np.asarray(item["camera"], np.float64),
                                    np.asarray(item["corners"], np.float64), values, patched))
    info = dict(raw["info"], seconds=raw["seconds"])
    tables = {precision: {key: np.frombuffer(base64.b64decode(t["data"]), dtype="<f4" if t["type"] == "float32"
                                             else "<f2").astype(np.float64).reshape(64, 64, 4)
                          for key, t in pair.items()}
              for precision, pair in raw.get("tables", {}).items()}
    return Run(info, configs, tables)


def export_tables(folder):
    """What the page reads, into ``folder``: the shipped tables in the ``ltc_code`` layout (EXR, f32 and f16) in
    ``ltc_code/`` and in the ``rtl`` layout (EXR, f32) in ``rtl/``."""
    from ...core.export import luts

    folder = Path(folder)
    luts.export(folder / "ltc_code", formats=("exr",), precisions=("f32", "f16"), layout="ltc_code")
    luts.export(folder / "rtl", formats=("exr",), precisions=("f32",), layout="rtl")
    return folder


def pixel_frames(positions, camera, corners, normal=(0.0, 0.0, 1.0)):
    """Each pixel's shading frame as three builds it (``LTC_Evaluate``: T1 along V's tangent part, N up): the view
    direction (n, 3) and the light's corners (n, 4, 3) in that frame, with the point at the origin, wound as the
    project's integrals take a one-sided light (their Newell normal points away from the point: three's order
    reversed, three's light normal ``(c1 - c0) x (c3 - c0)`` pointing at the points it lights); and whether the
    point is in front of the one-sided light (three returns 0 behind it)."""
    n = np.broadcast_to(np.asarray(normal, np.float64), positions.shape)
    v = camera - positions
    v /= np.linalg.norm(v, axis=-1, keepdims=True)
    t1 = v - n * np.sum(v * n, axis=-1, keepdims=True)
    t1 /= np.maximum(np.linalg.norm(t1, axis=-1, keepdims=True), 1e-12)
    t2 = np.cross(n, t1)
    frame = np.stack([t1, t2, n], axis=-2)                        # (n, 3, 3): rows T1, T2, N
    rel = corners[None, :, :] - positions[:, None, :]             # (n, 4, 3)
    local = np.einsum("nij,nkj->nki", frame, rel)[:, ::-1, :]
    v_local = np.einsum("nij,nj->ni", frame, v)
    light_normal = np.cross(corners[1] - corners[0], corners[3] - corners[0])
    in_front = np.sum((positions - corners[0]) * light_normal, axis=-1) >= 0.0
    return v_local, local, in_front


# --- three.js' RectAreaLight specular, in numpy (to check what the browser rendered) -------------------------------
# three r187, lights_physical_pars_fragment: LTC_Uv, LTC_EdgeVectorFormFactor, LTC_ClippedSphereFormFactor and
# RE_Direct_RectArea_Physical.  Their sources: Heitz, Dupuy, Hill & Neubelt 2016 (the LTC), and Hill & Heitz,
# "Real-Time Area Lighting: a Journey from Research to Production" (SIGGRAPH 2016 course; its code's rational fit of
# theta / sin(theta) / 2 pi on the edge integral, and the form factor of a horizon-clipped sphere, p. 102).

def _edge_vector_form_factor(v1, v2):
    """One edge's vector form factor with the course code's rational fit of theta / sin(theta) (both unit)."""
    x = np.sum(v1 * v2, axis=-1)
    y = np.abs(x)
    a = 0.8543985 + (0.4965155 + 0.0145206 * y) * y
    b = 3.4175940 + (4.1616724 + y) * y
    v = a / b
    theta_sintheta = np.where(x > 0.0, v, 0.5 / np.sqrt(np.maximum(1.0 - x * x, 1e-7)) - v)
    return np.cross(v1, v2) * theta_sintheta[..., None]


def three_rect_area_specular(ltc1, ltc2, roughness, v_local, corners_local):
    """What three shades for an F0 = 1 metal under a RectAreaLight of radiance 1: ``ltc_2``'s magnitude times the
    clipped-sphere form factor of the transformed quad, the tables (64, 64, 4; row t = 0 first) read bilinearly at
    three's texel centres.  ``v_local`` (n, 3), ``corners_local`` (n, 4, 3) as ``pixel_frames`` gives them."""
    from ...core.ir import semantics
    from ...core.lut import lookup
    from ...core.ltc import matrix

    mu = np.clip(v_local[:, 2], 0.0, 1.0)
    u, w = lookup.ltc_lut_uv(mu, np.full_like(mu, float(roughness)))
    minv = matrix.unpack_inverse(np.stack([semantics.sample_bilinear(ltc1, u[i], w[i]) for i in range(len(mu))]))
    magnitude = np.array([semantics.sample_bilinear(ltc2, u[i], w[i])[0] for i in range(len(mu))])
    p = np.einsum("nij,nkj->nki", minv, corners_local)
    p /= np.linalg.norm(p, axis=-1, keepdims=True)
    f = sum(_edge_vector_form_factor(p[:, k], p[:, (k + 1) % 4]) for k in range(4))
    length = np.linalg.norm(f, axis=-1)
    form_factor = np.maximum((length * length + f[:, 2]) / (length + 1.0), 0.0)
    return magnitude * form_factor


# --- the patched material (engines/three/src/patch.js), in numpy -----------------------------------------------------
#: The variants the tests and benchmarks render with the patch: MeshPhysicalMaterial parameters that isolate one lobe
#: (F0 = F90 = 1 for the specular; no specular for the diffuse and the sheen; a black base under the sheen).
PATCH_VARIANTS = {
    "specular": lambda r, s: {"color": 0xFFFFFF, "metalness": 1.0, "roughness": r},
    "diffuse": lambda r, s: {"color": 0xFFFFFF, "metalness": 0.0, "roughness": r, "specularIntensity": 0.0},
    "sheen": lambda r, s: {"color": 0x000000, "metalness": 0.0, "roughness": r, "specularIntensity": 0.0,
                           "sheen": 1.0, "sheenColor": 0xFFFFFF, "sheenRoughness": s},
}


def patched_reference(tables, config, lobe, roughness, sheen_roughness=0.5, specular="turquin"):
    """What the patch computes for ``PATCH_VARIANTS[lobe]`` at each pixel of ``config``, from the same node functions
    evaluated by the numpy backend (core/export/three_area.py's list) with ``tables`` (a ``LutSet``): the
    specular (F0 = F90 = 1) Scale + Bias, times Turquin's compensation when ``specular`` is "turquin"; the CoD
    diffuse; the Zeltner sheen."""
    from ...core import multiscatter
    from ...core.materials import lobes

    n = len(config.positions)
    position = config.positions
    view = config.camera - position
    view /= np.linalg.norm(view, axis=-1, keepdims=True)
    corners = config.corners[::-1]                       # RT Lit's winding (patch.js reverses three's order too)
    geometry = {"Position": position, "N": np.tile([0.0, 0.0, 1.0], (n, 1)), "V": view,
                **{f"p{k}": np.tile(corners[k], (n, 1)) for k in range(4)},
                "Center": np.tile(config.corners.mean(axis=0), (n, 1))}
    if lobe == "specular":
        out = lobes.GGX.function("quad", exact_horizon=True)(tables, **geometry, Roughness=np.full(n, roughness))
        value = np.asarray(out["Scale"]) + np.asarray(out["Bias"])
        if specular == "turquin":
            scale = multiscatter.TURQUIN_COMPENSATION(F0=np.ones((n, 3)), E=np.asarray(out["E"]))["Scale"]
            value = value * np.asarray(scale)[..., 0]
        return value
    if lobe == "diffuse":
        return np.asarray(lobes.COD.function("quad", exact_horizon=True)(
            tables, **geometry, Roughness=np.full(n, roughness))["Diffuse"])
    if lobe == "sheen":
        return np.asarray(lobes.ZELTNER.function("quad", exact_horizon=True)(
            tables, **geometry, **{"Sheen Roughness": np.full(n, sheen_roughness)})["Sheen"])
    raise ValueError(f"unknown lobe {lobe!r}; choose from {', '.join(PATCH_VARIANTS)}")


# --- the scene viewer (engines/viewer) --------------------------------------------------------------------------

def render_viewer(bundle_dir, timeout=600):
    """The viewer's first frame of a web bundle (core/export/web_scene.py) in headless Chromium: (H, W, 3) float32
    radiance, row 0 at the top (as the standalone renderer and Blender's renders are read), and the run's info."""
    raw = run_node_tool("render_viewer.mjs", ["--bundle", bundle_dir], "frame.json", timeout)
    pixels = np.frombuffer(base64.b64decode(raw["pixels"]), dtype="<f4").reshape(raw["height"], raw["width"], 4)
    return np.flipud(pixels[..., :3]).copy(), {"renderer": raw.get("renderer"), "seconds": raw["seconds"]}
