#!/usr/bin/env python3
"""A generated sky with a sun (scenes/assets/sky.exr), and Mitsuba 3's image of a scene lit by it.

Not run in CI. The sky is computed here, deterministically: a blue zenith fading to a pale
horizon, a dark ground below it, and a sun about 3 degrees across, 2000 times the zenith's
radiance, 35 degrees above the horizon. It is written as a 128x64 latitude-longitude OpenEXR
(float32 RGB) in Mitsuba's `envmap` layout, which rtis's `Environment(image: ...)` shares.

One description (below) is written both as a Mitsuba dict and as an rtis scene file
(tests/data/sky.ron), so the two cannot drift apart: a grey floor with a diffuse sphere, a rough
gold sphere and a glass sphere under the sky, turned 40 degrees about the vertical. Both
renderers trace paths without a depth limit, Russian roulette from depth 5, a box pixel
filter; Mitsuba's emitter is `envmap` with the same `to_world`.

It writes tests/data/mitsuba_sky_<W>x<H>_spp<N>.exr (linear float32 RGB, Mitsuba's
orientation: flip left-right before comparing with rtis) and a .json beside it with the
version, variant, spp, seconds, the image mean and `noise_rmse` (half the RMSE between two
independent halves of the samples). tests/integration/environment.rs compares rtis with it.

Setup: pip install mitsuba numpy; apt-get install libllvm19 (else --variant scalar_rgb).

Usage:
    python3 bench/mitsuba_sky_reference.py [--spp 4096] [--variant llvm_ad_rgb]
"""

import argparse
import json
import os

import numpy as np

from mitsuba_halves import load_mitsuba, num, render_halves, rtis_head, sensor, tup, write_reference

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SKY = os.path.join(ROOT, "scenes/assets/sky.exr")
SKY_SIZE = (128, 64)
WIDTH, HEIGHT = 160, 120
EYE, TARGET, UP, FOV = [0.0, 1.4, -3.5], [0.0, 0.7, 2.0], [0, 1, 0], 45
ROTATE_Y = 40.0
FLOOR = [0.5, 0.5, 0.5]
DIFFUSE = ([-1.3, 0.6, 1.5], 0.6, [0.7, 0.25, 0.2])
GOLD = ([0.0, 0.6, 2.6], 0.6, 0.2)
GLASS = ([1.3, 0.6, 1.3], 0.6, 1.5)


def sky_texels(width, height):
    """The sky's radiance at each texel: column i at u = (i + 1/2) / w, row j at
    theta = pi j / (h - 1), direction (sin phi sin theta, cos theta, -cos phi sin theta)."""
    u = (np.arange(width) + 0.5) / width
    theta = np.pi * np.arange(height) / (height - 1)
    phi = 2 * np.pi * u
    st, ct = np.sin(theta)[:, None], np.cos(theta)[:, None]
    d = np.stack([np.sin(phi)[None, :] * st, np.broadcast_to(ct, (height, width)),
                  -np.cos(phi)[None, :] * st], axis=-1)
    up = np.clip(d[..., 1], 0, 1)[..., None]
    zenith, horizon, ground = np.array([0.12, 0.25, 0.6]), np.array([0.7, 0.75, 0.8]), \
        np.array([0.12, 0.1, 0.08])
    t = np.sqrt(up)
    img = np.where(d[..., 1:2] >= 0, horizon * (1 - t) + zenith * t, ground)
    elev, azim = np.radians(35.0), np.radians(100.0)
    sun = np.array([np.sin(azim) * np.cos(elev), np.sin(elev), -np.cos(azim) * np.cos(elev)])
    cos_sun = d @ sun
    img = img + np.where(cos_sun[..., None] > np.cos(np.radians(1.6)),
                         2000 * zenith.mean() * np.array([1.0, 0.92, 0.8]), 0.0)
    return img.astype(np.float32)


def mitsuba_dict(mi, spp, seed=0):
    T = mi.ScalarTransform4f
    rgb = lambda c: {"type": "rgb", "value": c}
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": -1, "rr_depth": 5},
        "sensor": sensor(mi, "perspective", EYE, TARGET, UP, FOV, WIDTH, HEIGHT, spp, seed),
        "sky": {"type": "envmap", "filename": SKY, "to_world": T().rotate([0, 1, 0], ROTATE_Y)},
        # The floor: a rectangle of half size 1000 in y = 0 facing up.
        "floor": {"type": "rectangle", "to_world": T().rotate([1, 0, 0], -90).scale(1000),
                  "bsdf": {"type": "diffuse", "reflectance": rgb(FLOOR)}},
        "diffuse": {"type": "sphere", "center": DIFFUSE[0], "radius": DIFFUSE[1],
                    "bsdf": {"type": "diffuse", "reflectance": rgb(DIFFUSE[2])}},
        "gold": {"type": "sphere", "center": GOLD[0], "radius": GOLD[1],
                 "bsdf": {"type": "roughconductor", "material": "Au", "distribution": "ggx",
                          "alpha": GOLD[2]}},
        "glass": {"type": "sphere", "center": GLASS[0], "radius": GLASS[1],
                  "bsdf": {"type": "dielectric", "int_ior": GLASS[2], "ext_ior": 1.0}},
    }
    return scene


def rtis_scene(spp):
    return "\n".join([
        *rtis_head([
            "// Written by bench/mitsuba_sky_reference.py; Mitsuba 3's image of the same scene is",
            "// beside it (tests/integration/environment.rs compares them). A floor and three spheres",
            "// (diffuse, rough gold, glass) under the generated sky of scenes/assets/sky.exr.",
        ], WIDTH, HEIGHT, spp, EYE, TARGET, UP, FOV),
        f"        (light: Environment(image: \"../../scenes/assets/sky.exr\", "
        f"rotate: (0, {num(ROTATE_Y)}, 0))),",
        f"        (shape: InfinitePlane(point: (0, 0, 0), normal: (0, 1, 0)), "
        f"material: Phong(kd: {tup(FLOOR)}, ks: (0, 0, 0))),",
        f"        (shape: Sphere(center: {tup(DIFFUSE[0])}, radius: {num(DIFFUSE[1])}), "
        f"material: Phong(kd: {tup(DIFFUSE[2])}, ks: (0, 0, 0))),",
        f"        (shape: Sphere(center: {tup(GOLD[0])}, radius: {num(GOLD[1])}), "
        f"material: RoughConductor(distribution: Ggx, alpha: {num(GOLD[2])}, material: \"Au\")),",
        f"        (shape: Sphere(center: {tup(GLASS[0])}, radius: {num(GLASS[1])}), "
        f"material: Transmissive(ior: {num(GLASS[2])})),",
        "    ],",
        ")",
        "",
    ])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spp", type=int, default=4096)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    args = ap.parse_args()
    mi = load_mitsuba(args.variant)
    os.makedirs(os.path.dirname(SKY), exist_ok=True)
    mi.Bitmap(sky_texels(*SKY_SIZE)).write(SKY)
    with open(os.path.join(ROOT, "tests/data", "sky.ron"), "w") as f:
        f.write(rtis_scene(64))
    img, half_rmse, seconds = render_halves(mi, lambda n, seed: mitsuba_dict(mi, n, seed), args.spp,
                                            WIDTH, HEIGHT)
    stem = os.path.join(ROOT, "tests/data", f"mitsuba_sky_{WIDTH}x{HEIGHT}_spp{args.spp}")
    meta = write_reference(mi, stem, img, half_rmse, seconds, args.variant, args.spp)
    print(json.dumps(meta))


if __name__ == "__main__":
    main()
