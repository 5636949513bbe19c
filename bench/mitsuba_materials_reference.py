#!/usr/bin/env python3
"""Reference images of rtis's rough materials by Mitsuba 3, and the same scenes for rtis.

Not run in CI. One description per scene (below) is written both as a Mitsuba dict and as an
rtis scene file, so the two cannot drift apart:

- `materials`: the material preview (scenes/materials.ron, the README's picture): a row of
  rough gold (`roughconductor`, material "Au"), a row of frosted glass (`roughdielectric`,
  int_ior 1.5, ext_ior 1) and a row of blue plastic (`roughplastic`), each at roughness 0.03,
  0.15 and 0.5 (GGX, visible normals), plus a smooth `plastic` floor, under a one-sided
  rectangular area light and a constant sky.
- `materials-beckmann`: the same with Beckmann microfacets, anisotropic gold (alpha_u 0.05,
  alpha_v 0.4) in place of the middle gold sphere, and the `nonlinear` plastic.

For each it writes tests/data/mitsuba_<name>_<W>x<H>_spp<N>.exr (linear float32 RGB, Mitsuba's
orientation: flip left-right before comparing with rtis) and a .json beside it with the
version, variant, spp, seconds, the image mean and `noise_rmse` (half the RMSE between two
independent halves of the samples: the RMSE of their mean against its expectation).

Both renderers: path tracing without a depth limit, Russian roulette from depth 5, the emitter
and the sky visible, a box pixel filter. rtis's spheres and plane are two-sided and Mitsuba's
BSDFs one-sided; the camera never sees a back face.

Setup: pip install mitsuba numpy; apt-get install libllvm19 (else --variant scalar_rgb).

Usage:
    python3 bench/mitsuba_materials_reference.py [--spp 4096] [--variant llvm_ad_rgb]
    python3 bench/mitsuba_materials_reference.py --write-scenes    # only the rtis scenes
"""

import argparse
import json
import os

import numpy as np

from mitsuba_halves import load_mitsuba, num, render_halves, rtis_head, sensor, tup, write_reference

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
WIDTH, HEIGHT = 192, 128
EYE, TARGET, UP, FOV = [0, 5.0, -4.4], [0, 0.2, 1.35], [0, 1, 0], 38
SKY = [0.25, 0.3, 0.4]
LIGHT = {"corner": [-1.5, 4.5, -0.2], "u": [3.0, 0, 0], "v": [0, 0, 3.0], "radiance": [6, 6, 6]}
ALPHAS = [0.03, 0.15, 0.5]
XS = [-1.2, 0.0, 1.2]
ROWS_Z = [0.0, 1.35, 2.7]
RADIUS = 0.45
BLUE = [0.1, 0.25, 0.7]
FLOOR = [0.5, 0.5, 0.5]


def materials(variant):
    """The nine spheres: (name, centre, material as a neutral dict)."""
    beckmann = variant == "materials-beckmann"
    dist = "beckmann" if beckmann else "ggx"
    spheres = []
    for row, z in enumerate(ROWS_Z):
        for col, (x, a) in enumerate(zip(XS, ALPHAS)):
            if row == 0:
                m = {"type": "roughconductor", "material": "Au", "alpha": a}
                if beckmann and col == 1:
                    m = {"type": "roughconductor", "material": "Au", "alpha_u": 0.05, "alpha_v": 0.4}
            elif row == 1:
                m = {"type": "roughdielectric", "alpha": a, "int_ior": 1.5, "ext_ior": 1.0}
            else:
                m = {"type": "roughplastic", "alpha": a, "diffuse_reflectance": BLUE,
                     "nonlinear": beckmann}
            m["distribution"] = dist
            spheres.append((f"{m['type']} {a}", [x, RADIUS, z], m))
    return spheres


def floor_material():
    return {"type": "plastic", "diffuse_reflectance": FLOOR, "int_ior": 1.49, "ext_ior": 1.0}


# ----------------------------------------------------------------------------- Mitsuba


def mi_bsdf(m):
    d = {"type": m["type"]}
    for k, v in m.items():
        if k == "type":
            continue
        if k in ("diffuse_reflectance",):
            d[k] = {"type": "rgb", "value": v}
        else:
            d[k] = v
    return d


def mitsuba_dict(mi, variant, spp, seed=0):
    T = mi.ScalarTransform4f
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": -1, "rr_depth": 5, "hide_emitters": False},
        "sensor": sensor(mi, "perspective", EYE, TARGET, UP, FOV, WIDTH, HEIGHT, spp, seed),
        "sky": {"type": "constant", "radiance": {"type": "rgb", "value": SKY}},
        # The floor: a rectangle of half size 1000 in y = 0 facing up.
        "floor": {
            "type": "rectangle",
            "to_world": T().rotate([1, 0, 0], -90).scale(1000),
            "bsdf": mi_bsdf(floor_material()),
        },
    }
    c, u, v = (np.array(LIGHT[k], dtype=float) for k in ("corner", "u", "v"))
    centre = c + 0.5 * (u + v)
    # Mitsuba's rectangle is [-1, 1]^2 in z = 0 with normal +z; ours faces u x v.
    n = np.cross(u, v)
    n /= np.linalg.norm(n)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = 0.5 * u, 0.5 * v, n, centre
    scene["light"] = {
        "type": "rectangle",
        "to_world": T(m.tolist()),
        "emitter": {"type": "area", "radiance": {"type": "rgb", "value": LIGHT["radiance"]}},
    }
    for i, (_, centre, mat) in enumerate(materials(variant)):
        scene[f"sphere{i}"] = {"type": "sphere", "center": centre, "radius": RADIUS,
                               "bsdf": mi_bsdf(mat)}
    return scene


# ----------------------------------------------------------------------------- rtis


def rtis_material(m):
    dist = "Beckmann" if m.get("distribution") == "beckmann" else "Ggx"
    t = m["type"]
    if t == "roughconductor":
        rough = (f"alpha_u: {num(m['alpha_u'])}, alpha_v: {num(m['alpha_v'])}" if "alpha_u" in m
                 else f"alpha: {num(m['alpha'])}")
        return f'RoughConductor(distribution: {dist}, {rough}, material: "{m["material"]}")'
    if t == "roughdielectric":
        return (f"RoughDielectric(distribution: {dist}, alpha: {num(m['alpha'])}, "
                f"int_ior: {num(m['int_ior'])}, ext_ior: {num(m['ext_ior'])})")
    if t == "roughplastic":
        return (f"RoughPlastic(distribution: {dist}, alpha: {num(m['alpha'])}, "
                f"diffuse_reflectance: {tup(m['diffuse_reflectance'])}, "
                f"nonlinear: {str(m['nonlinear']).lower()})")
    if t == "plastic":
        return (f"Plastic(diffuse_reflectance: {tup(m['diffuse_reflectance'])}, "
                f"int_ior: {num(m['int_ior'])}, ext_ior: {num(m['ext_ior'])})")
    raise ValueError(t)


def rtis_scene(variant, spp):
    lines = [
        *rtis_head([
            f"// Written by bench/mitsuba_materials_reference.py ({variant}); Mitsuba 3's image of the",
            "// same scene is in tests/data (tests/integration/bsdfs.rs compares them). Rows, front to back: rough",
            "// gold, frosted glass and blue rough plastic; roughness 0.03, 0.15 and 0.5 from left to",
            "// right in rtis's image (Mitsuba's is mirrored left-right). The floor is a smooth plastic.",
        ], WIDTH, HEIGHT, spp, EYE, TARGET, UP, FOV, extra=[f"    background: {tup(SKY)},"]),
        f'        (name: "floor", shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)), '
        f"material: {rtis_material(floor_material())}),",
        f'        (name: "light", shape: Rectangle(corner: {tup(LIGHT["corner"])}, u: {tup(LIGHT["u"])}, '
        f'v: {tup(LIGHT["v"])}), emitter: Emitter(radiance: {tup(LIGHT["radiance"])})),',
    ]
    for name, centre, m in materials(variant):
        lines.append(f'        (name: "{name}", shape: Sphere(center: {tup(centre)}, radius: {num(RADIUS)}), '
                     f"material: {rtis_material(m)}),")
    lines += ["    ],", ")", ""]
    return "\n".join(lines)


# ----------------------------------------------------------------------------- main


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spp", type=int, default=4096)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--only", choices=["materials", "materials-beckmann"])
    ap.add_argument("--write-scenes", action="store_true")
    args = ap.parse_args()
    names = [args.only] if args.only else ["materials", "materials-beckmann"]
    for name in names:
        with open(os.path.join(ROOT, "scenes", f"{name}.ron"), "w") as f:
            f.write(rtis_scene(name, 64))
    if args.write_scenes:
        return
    mi = load_mitsuba(args.variant)
    for name in names:
        img, half_rmse, seconds = render_halves(
            mi, lambda n, seed: mitsuba_dict(mi, name, n, seed), args.spp, WIDTH, HEIGHT)
        stem = os.path.join(ROOT, "tests/data", f"mitsuba_{name.replace('-', '_')}_{WIDTH}x{HEIGHT}_spp{args.spp}")
        meta = write_reference(mi, stem, img, half_rmse, seconds, args.variant, args.spp)
        print(name, json.dumps(meta))


if __name__ == "__main__":
    main()
