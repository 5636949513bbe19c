#!/usr/bin/env python3
"""Mitsuba 3's image of a scene with a thin lens and spot lights, and the same scene for rtis.

Not run in CI. One description (below) is written both as a Mitsuba dict and as an rtis scene
file (tests/data/lens_spot.ron), so the two cannot drift apart: three diffuse spheres at
depths 4.5, 7 and 10 on a grey floor, seen through a thin lens (aperture radius 0.12) focused on
the middle one, lit by two spot lights (one white with a soft edge, one coloured with a hard
one) and a faint sun (`directional`). Both renderers trace paths without a depth limit, Russian roulette from
depth 5, a box pixel filter; Mitsuba's sensor is `thinlens` with `fov_axis: y`, its emitters
`spot` oriented by `look_at` and `directional`.

It writes tests/data/mitsuba_lens_spot_<W>x<H>_spp<N>.exr (linear float32 RGB, Mitsuba's
orientation: flip left-right before comparing with rtis) and a .json beside it with the
version, variant, spp, seconds, the image mean and `noise_rmse` (half the RMSE between two
independent halves of the samples). tests/integration/cameras.rs compares rtis with it.

Setup: pip install mitsuba numpy; apt-get install libllvm19 (else --variant scalar_rgb).

Usage:
    python3 bench/mitsuba_lights_reference.py [--spp 4096] [--variant llvm_ad_rgb]
"""

import argparse
import json
import os

import numpy as np

from mitsuba_halves import load_mitsuba, num, render_halves, sensor, tup, write_reference

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
WIDTH, HEIGHT = 160, 120
EYE, TARGET, UP, FOV = [0.0, 1.2, -2.0], [0.0, 0.6, 5.0], [0, 1, 0], 40
APERTURE, FOCUS = 0.12, 7.0
FLOOR = [0.6, 0.6, 0.6]
# (centre, radius, reflectance)
SPHERES = [([-0.9, 0.6, 2.5], 0.6, [0.8, 0.3, 0.2]),
           ([0.3, 0.6, 5.0], 0.6, [0.3, 0.7, 0.3]),
           ([1.4, 0.6, 8.0], 0.6, [0.3, 0.4, 0.8])]
# (position, direction, intensity, cutoff, beam)
SPOTS = [([0.0, 4.0, 3.0], [0.05, -1.0, 0.3], [40.0, 40.0, 40.0], 40.0, 15.0),
         ([-2.5, 2.5, 6.0], [1.0, -0.6, 0.4], [40.0, 20.0, 6.0], 25.0, 25.0)]
# A faint sun: (direction it travels in, irradiance)
SUN = ([0.4, -1.0, 0.6], [0.25, 0.25, 0.3])


def mitsuba_dict(mi, spp, seed=0):
    T = mi.ScalarTransform4f
    diffuse = lambda c: {"type": "diffuse", "reflectance": {"type": "rgb", "value": c}}
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": -1, "rr_depth": 5},
        "sensor": sensor(mi, "thinlens", EYE, TARGET, UP, FOV, WIDTH, HEIGHT, spp, seed,
                         aperture_radius=APERTURE, focus_distance=FOCUS),
        # The floor: a rectangle of half size 1000 in y = 0 facing up.
        "floor": {"type": "rectangle", "to_world": T().rotate([1, 0, 0], -90).scale(1000),
                  "bsdf": diffuse(FLOOR)},
    }
    for i, (c, r, k) in enumerate(SPHERES):
        scene[f"sphere{i}"] = {"type": "sphere", "center": c, "radius": r, "bsdf": diffuse(k)}
    for i, (p, d, e, cutoff, beam) in enumerate(SPOTS):
        target = [p[j] + d[j] for j in range(3)]
        up = [0, 0, 1] if abs(d[1]) > 0.9 * np.linalg.norm(d) else [0, 1, 0]
        scene[f"spot{i}"] = {"type": "spot", "to_world": T().look_at(origin=p, target=target, up=up),
                             "intensity": {"type": "rgb", "value": e},
                             "cutoff_angle": cutoff, "beam_width": beam}
    scene["sun"] = {"type": "directional", "direction": SUN[0],
                    "irradiance": {"type": "rgb", "value": SUN[1]}}
    return scene


def rtis_scene(spp):
    lines = [
        "// Written by bench/mitsuba_lights_reference.py; Mitsuba 3's image of the same scene is",
        "// beside it (tests/integration/cameras.rs compares them). A thin lens focused on the",
        "// middle sphere, two spot lights.",
        "Scene(",
        f"    film: (width: {WIDTH}, height: {HEIGHT}, spp: {spp}),",
        f"    camera: Perspective(position: {tup(EYE)}, look_at: {tup(TARGET)}, up: {tup(UP)}, "
        f"fov: {num(FOV)}, aperture_radius: {num(APERTURE)}, focus_distance: {num(FOCUS)}),",
        "    shader: Path(rr_depth: 5),",
        "    model: Physical,",
        "    entities: [",
        f"        (shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)), "
        f"material: Phong(kd: {tup(FLOOR)}, ks: (0, 0, 0))),",
    ]
    for c, r, k in SPHERES:
        lines.append(f"        (shape: Sphere(center: {tup(c)}, radius: {num(r)}), "
                     f"material: Phong(kd: {tup(k)}, ks: (0, 0, 0))),")
    for p, d, e, cutoff, beam in SPOTS:
        lines.append(f"        (light: Spot(position: {tup(p)}, direction: {tup(d)}, intensity: {tup(e)}, "
                     f"cutoff_angle: {num(cutoff)}, beam_width: {num(beam)})),")
    lines.append(f"        (light: Directional(direction: {tup(SUN[0])}, irradiance: {tup(SUN[1])})),")
    lines += ["    ],", ")", ""]
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spp", type=int, default=4096)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    args = ap.parse_args()
    with open(os.path.join(ROOT, "tests/data", "lens_spot.ron"), "w") as f:
        f.write(rtis_scene(64))
    mi = load_mitsuba(args.variant)
    img, half_rmse, seconds = render_halves(mi, lambda n, seed: mitsuba_dict(mi, n, seed), args.spp,
                                            WIDTH, HEIGHT)
    stem = os.path.join(ROOT, "tests/data", f"mitsuba_lens_spot_{WIDTH}x{HEIGHT}_spp{args.spp}")
    meta = write_reference(mi, stem, img, half_rmse, seconds, args.variant, args.spp)
    print(json.dumps(meta))


if __name__ == "__main__":
    main()
