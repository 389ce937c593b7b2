"""World shadows by the ratio estimator (prototype) on the floor study, against the path-traced twin.

    .venv/bin/python scripts/world_ratio_study.py --res 320 200 --samples 64 --threads 2 --out out/world_ratio.json \
        [--rows best,wr4,wr16,w_cc,w_wr4,w_wr16,w_none]

Each row is one ``lookdev_twin.shadow_study`` (one run, so its time is one measurement); WORLD_RATIO_REPORT.md.
"""
import argparse
import functools
import json
import sys
import time
from pathlib import Path

import numpy as np

from rt_lookdev.core.materials.rt_lit_interface import Features
from rt_lookdev.validation.checks import lookdev_twin
from rt_lookdev.validation.harness import render_setup

#: name -> (lights, occlusion, shadow options or None)
ROWS = {
    "none": (True, "none", None),
    "best": (True, "cones_clipped", {"samples": 4, "denoise": True}),
    "wr4": (True, "none", {"samples": 4, "denoise": True, "world": True}),
    "wr16": (True, "none", {"samples": 16, "denoise": True, "world": True}),
    "wr16raw": (True, "none", {"samples": 16, "denoise": False, "world": True}),
    "wr_cc4": (True, "cones_clipped", {"samples": 4, "denoise": True, "world": True}),
    "wr4_brute": (True, "none", {"samples": 4, "denoise": True, "world": True}),
    "wrd4": (True, "none", {"samples": 4, "denoise": True, "world": "diffuse"}),
    "w_wrd4": (False, "none", {"samples": 4, "denoise": True, "world": "diffuse"}),
    "w_none": (False, "none", None),
    "w_cc": (False, "cones_clipped", None),
    "w_wr4": (False, "none", {"samples": 4, "denoise": True, "world": True}),
    "w_wr16": (False, "none", {"samples": 16, "denoise": True, "world": True}),
    "w_wr64raw": (False, "none", {"samples": 64, "denoise": False, "world": True}),
    "w_wr4_brute": (False, "none", {"samples": 4, "denoise": True, "world": True}),
}


def _brute_scale():
    """E_brute(up) / E_SH(up) of the studio HDRI (the floor's normal; its world is rotated about z only)."""
    from rt_lookdev.core.environment import equirect, sh
    env = equirect.Environment(np.asarray(equirect.read_equirect(equirect.resolve_hdri("studio"))))
    up = np.array([[0.0, 0.0, 1.0]])
    return tuple(float(x) for x in (sh.irradiance_brute_force(env, up) / sh.sh_irradiance(sh.sh_project(env), up))[0])


def main(argv):
    p = argparse.ArgumentParser()
    p.add_argument("--res", type=int, nargs=2, default=(96, 60))
    p.add_argument("--samples", type=int, default=8, help="the twin's spp (x 2 seeds)")
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--rows", default=",".join(ROWS))
    p.add_argument("--out", type=Path, default=Path("out/world_ratio.json"))
    args = p.parse_args(argv)
    lookdev_twin.configure_cycles_measurement = functools.partial(render_setup.configure_cycles_measurement,
                                                                  threads=args.threads)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    results = json.loads(args.out.read_text()) if args.out.exists() else {}
    images = {}
    for name in args.rows.split(","):
        lights, occlusion, shadow = ROWS[name]
        from rt_lookdev.addon import shadows
        shadows.WORLD_DENOMINATOR_SCALE = _brute_scale() if name.endswith("_brute") else (1.0, 1.0, 1.0)
        t0 = time.perf_counter()
        study = lookdev_twin.shadow_study(None, tuple(args.res), args.samples, print, Features(occlusion=occlusion),
                                          lights=lights, light_shadows=shadow)
        floor, dark = study["floor_with_shadows"], study["floor_darkened"]
        mask = study["floor_mask"]
        im = study["images"]
        ratio = im["rt_lit"][mask].mean(-1) / np.maximum(im["path_traced"][mask].mean(-1), 1e-9)
        row = {"lights": lights, "occlusion": occlusion, "shadows": shadow,
               "median": floor["median"], "p90": floor["p90"], "noise_median": floor["noise_median"],
               "darkened_median": dark["median"], "darkened_p90": dark["p90"],
               "floor_unshadowed_twin_median": study["floor_without_shadows"]["median"],
               "floor_mean_ratio_rt_over_twin": float(ratio.mean()),
               "floor_ratio_p10_p50_p90": [float(np.percentile(ratio, q)) for q in (10, 50, 90)],
               "rt_lit_seconds": study["seconds"]["rt_lit_cycles"], "rt_lit_samples": study["rt_lit_samples"],
               "study_seconds": time.perf_counter() - t0, "res": list(args.res), "twin_spp": args.samples,
               "threads": args.threads}
        results[f"{name}@{args.res[0]}x{args.res[1]}"] = row
        images[name] = {k: v for k, v in im.items()}
        images[name]["mask"] = mask
        print(f"[world ratio] {name}: floor {row['median']:.1%} / {row['p90']:.1%}; darkened {row['darkened_median']:.1%}"
              f" / {row['darkened_p90']:.1%}; mean RT/twin {row['floor_mean_ratio_rt_over_twin']:.3f}; "
              f"RT Lit {row['rt_lit_seconds']:.2f} s", flush=True)
        args.out.write_text(json.dumps(results, indent=1))
        np.savez_compressed(args.out.with_name(f"{args.out.stem}_{name}_{args.res[0]}x{args.res[1]}.npz"),
                            **{f"{k}": v for k, v in images[name].items()})
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
