#!/usr/bin/env python3
"""A generated image texture (tests/data/texture.png), and Mitsuba 3's image of a textured scene.

Not run in CI. The texture is computed here, deterministically: 64x32 8-bit sRGB, coloured
bands with a grid and a dot near its top left corner, so that a flipped or shifted mapping shows.

One description (below) is written both as a Mitsuba dict and as an rtis scene file
(tests/data/texture.ron), so the two cannot drift apart: a floor with a checkerboard, a sphere
and an upright rectangle wearing the image (bilinear, repeat), lit by a constant sky and a sun.
Both renderers trace paths without a depth limit, Russian roulette from depth 5, a box pixel
filter. Mitsuba's rectangles are placed by a `to_world` whose axes are rtis's `u / 2` and `v / 2`
about their centre, so their `(u, v)` run from the corner as rtis's do; Mitsuba's spheres have
their poles on `z`, as rtis's.

With `--scene rough` the scene is the textured parameters of the other materials: the floor a
plastic whose base is the checkerboard, the sphere a rough gold whose roughness is a
generated grey map (tests/data/roughness.png, raw) and whose tint is the image, the panel the
image on a diffuse surface bent by a generated normal map (tests/data/bumps.png, Mitsuba's
`normalmap`), and a rectangle light whose radiance is a generated OpenEXR image
(tests/data/glow.exr). Its files are tests/data/texture_rough.ron and
mitsuba_texture_rough_<W>x<H>_spp<N>.exr.

With `--filter gaussian` both use Mitsuba's default pixel filter, `gaussian` (stddev 0.5), and
the files are tests/data/texture_gaussian.ron and mitsuba_texture_gaussian_<W>x<H>_spp<N>.exr.

It writes tests/data/mitsuba_texture_<W>x<H>_spp<N>.exr (linear float32 RGB, Mitsuba's
orientation: flip left-right before comparing with rtis) and a .json beside it with the
version, variant, spp, seconds, the image mean and `noise_rmse`. tests/integration/textures.rs
compares rtis with it.

Setup: pip install mitsuba numpy; apt-get install libllvm19 (else --variant scalar_rgb).

Usage:
    python3 bench/mitsuba_texture_reference.py [--spp 4096] [--variant llvm_ad_rgb] [--filter gaussian]
"""

import argparse
import json
import os

import numpy as np

from mitsuba_halves import load_mitsuba, num, render_halves, rtis_head, sensor, tup, write_reference

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TEXTURE = os.path.join(ROOT, "tests/data/texture.png")
WIDTH, HEIGHT = 160, 120
EYE, TARGET, UP, FOV = [0.0, 2.0, -4.0], [0.0, 0.8, 1.0], [0, 1, 0], 45
SKY = [0.4, 0.45, 0.5]
SUN = ([0.5, -1.0, 0.8], [2.0, 1.9, 1.7])
# The floor: corner, u, v (u x v up), checkerboard colours and scale.
FLOOR = ([-4.0, 0.0, -3.0], [0.0, 0.0, 8.0], [8.0, 0.0, 0.0])
CHECKS = ([0.8, 0.8, 0.75], [0.15, 0.2, 0.25], 8.0)
SPHERE = ([-0.9, 0.8, 1.2], 0.8)
# An upright rectangle facing the camera (u x v towards -z).
PANEL = ([0.4, 0.1, 1.6], [1.8, 0.0, 0.0], [0.0, 1.4, 0.0])


def texture_codes(width=64, height=32):
    """8-bit sRGB codes: bands across u, a grid every 8 texels, a dot near the top left."""
    x = np.arange(width)[None, :] + np.zeros((height, 1))
    y = np.arange(height)[:, None] + np.zeros((1, width))
    r = 0.2 + 0.7 * (x / width)
    g = 0.3 + 0.5 * (y / height)
    b = 0.6 - 0.4 * (x / width)
    img = np.stack([r, g, b], axis=-1)
    grid = (x % 8 == 0) | (y % 8 == 0)
    img[grid] = [0.95, 0.95, 0.9]
    dot = (x - 6) ** 2 + (y - 5) ** 2 < 9
    img[dot] = [0.9, 0.1, 0.1]
    return np.round(img * 255).astype(np.uint8)


ROUGHNESS = os.path.join(ROOT, "tests/data/roughness.png")
BUMPS = os.path.join(ROOT, "tests/data/bumps.png")
GLOW = os.path.join(ROOT, "tests/data/glow.exr")
# A light facing the camera (u x v towards -z), its radiance the glow image.
LAMP = ([-2.3, 1.0, 2.6], [0.0, 0.8, 0.0], [0.8, 0.0, 0.0])


def roughness_codes(width=32, height=16):
    """8-bit grey codes of a roughness from 0.05 (left) to 0.6 (right), darker bands across v."""
    x = np.arange(width)[None, :] + np.zeros((height, 1))
    y = np.arange(height)[:, None] + np.zeros((1, width))
    a = 0.05 + 0.55 * x / (width - 1)
    a = np.where(y % 8 < 2, 0.02, a)
    return np.round(a * 255).astype(np.uint8)


def bump_codes(width=64, height=64):
    """8-bit RGB codes of a tangent-space normal map: bumps h = 0.015 sin(2 pi 4 u) sin(2 pi 3 v)
    over the unit square (normals within about 22 degrees of the surface's, so that rtis never
    bends them: see docs/scene-format.md, "Normal maps"), n = normalize(-dh/du, -dh/dv, 1) / 2 +
    1/2 (u along columns, v along rows from the top)."""
    u = (np.arange(width)[None, :] + 0.5) / width + np.zeros((height, 1))
    v = (np.arange(height)[:, None] + 0.5) / height + np.zeros((1, width))
    ku, kv = 2 * np.pi * 4, 2 * np.pi * 3
    dhdu = 0.015 * ku * np.cos(ku * u) * np.sin(kv * v)
    dhdv = 0.015 * kv * np.sin(ku * u) * np.cos(kv * v)
    n = np.stack([-dhdu, -dhdv, np.ones_like(u)], axis=-1)
    n /= np.linalg.norm(n, axis=-1, keepdims=True)
    return np.round((n * 0.5 + 0.5) * 255).astype(np.uint8)


def glow_values(width=16, height=8):
    """Linear RGB radiance: a warm gradient across u, a bright spot near the top left."""
    x = (np.arange(width)[None, :] + 0.5) / width + np.zeros((height, 1))
    y = (np.arange(height)[:, None] + 0.5) / height + np.zeros((1, width))
    img = np.stack([1.0 + 4.0 * x, 0.5 + 2.0 * x, 0.5 + y], axis=-1)
    spot = (x - 0.2) ** 2 + (y - 0.3) ** 2 < 0.02
    img[spot] = [8.0, 8.0, 6.0]
    return img.astype(np.float32)


def rect_to_world(mi, corner, u, v):
    """Mitsuba's `to_world` for rtis's Rectangle(corner, u, v): local x along u / 2, y along
    v / 2, z along their cross product, about the centre."""
    c, u, v = np.array(corner), np.array(u), np.array(v)
    n = np.cross(u, v)
    n = n / np.linalg.norm(n)
    centre = c + u / 2 + v / 2
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = u / 2, v / 2, n, centre
    return mi.ScalarTransform4f(m.tolist())


def rgb(c):
    return {"type": "rgb", "value": c}


def lit(mi, spp, seed, gaussian=False):
    """What both scenes share: the integrator, the camera, the sky and the sun."""
    camera = sensor(mi, "perspective", EYE, TARGET, UP, FOV, WIDTH, HEIGHT, spp, seed)
    if gaussian:
        camera["film"]["rfilter"] = {"type": "gaussian", "stddev": 0.5}
    return {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": -1, "rr_depth": 5},
        "sensor": camera,
        "sky": {"type": "constant", "radiance": rgb(SKY)},
        "sun": {"type": "directional", "direction": SUN[0], "irradiance": rgb(SUN[1])},
    }


def mitsuba_dict(mi, spp, seed=0, gaussian=False):
    bitmap = {"type": "bitmap", "filename": TEXTURE, "filter_type": "bilinear", "wrap_mode": "repeat"}
    c0, c1, scale = CHECKS
    return {
        **lit(mi, spp, seed, gaussian),
        "floor": {"type": "rectangle", "to_world": rect_to_world(mi, *FLOOR),
                  "bsdf": {"type": "diffuse", "reflectance": {
                      "type": "checkerboard", "color0": rgb(c0), "color1": rgb(c1),
                      "to_uv": mi.ScalarTransform4f().scale([scale, scale, 1])}}},
        "sphere": {"type": "sphere", "center": SPHERE[0], "radius": SPHERE[1],
                   "bsdf": {"type": "diffuse", "reflectance": bitmap}},
        "panel": {"type": "rectangle", "to_world": rect_to_world(mi, *PANEL),
                  "bsdf": {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": bitmap}}},
    }


def mitsuba_rough_dict(mi, spp, seed=0):
    bitmap = lambda f, raw=False: {"type": "bitmap", "filename": f, "filter_type": "bilinear",
                                   "wrap_mode": "repeat", "raw": raw}
    c0, c1, scale = CHECKS
    return {
        **lit(mi, spp, seed),
        "floor": {"type": "rectangle", "to_world": rect_to_world(mi, *FLOOR),
                  "bsdf": {"type": "plastic",
                           "diffuse_reflectance": {
                               "type": "checkerboard", "color0": rgb(c0), "color1": rgb(c1),
                               "to_uv": mi.ScalarTransform4f().scale([scale, scale, 1])}}},
        "sphere": {"type": "sphere", "center": SPHERE[0], "radius": SPHERE[1],
                   "bsdf": {"type": "roughconductor", "material": "Au", "distribution": "ggx",
                            "alpha": bitmap(ROUGHNESS, raw=True),
                            "specular_reflectance": bitmap(TEXTURE)}},
        "panel": {"type": "rectangle", "to_world": rect_to_world(mi, *PANEL),
                  "bsdf": {"type": "twosided", "bsdf": {
                      "type": "normalmap", "normalmap": bitmap(BUMPS, raw=True),
                      "bsdf": {"type": "diffuse", "reflectance": bitmap(TEXTURE)}}}},
        "lamp": {"type": "rectangle", "to_world": rect_to_world(mi, *LAMP),
                 "emitter": {"type": "area", "radiance": bitmap(GLOW)},
                 "bsdf": {"type": "diffuse", "reflectance": rgb([0, 0, 0])}},
    }


def rtis_rough_scene(spp):
    c0, c1, scale = CHECKS
    image = 'Image(path: "texture.png")'
    return "\n".join([
        *rtis_head([
            "// Written by bench/mitsuba_texture_reference.py --scene rough; Mitsuba 3's image of the",
            "// same scene is beside it (tests/integration/material_textures.rs compares them). A",
            "// plastic floor on a checkerboard, a rough gold sphere with a roughness map and a tint",
            "// image, a panel bent by a normal map, and a light whose radiance is an image.",
        ], WIDTH, HEIGHT, spp, EYE, TARGET, UP, FOV),
        f"        (light: Environment(radiance: {tup(SKY)})),",
        f"        (light: Directional(direction: {tup(SUN[0])}, irradiance: {tup(SUN[1])})),",
        f"        (shape: Rectangle(corner: {tup(FLOOR[0])}, u: {tup(FLOOR[1])}, v: {tup(FLOOR[2])}), "
        f"material: Plastic(diffuse_reflectance: Checkerboard(color0: {tup(c0)}, "
        f"color1: {tup(c1)}, uv_transform: (scale: ({num(scale)}, {num(scale)}))))),",
        f"        (shape: Sphere(center: {tup(SPHERE[0])}, radius: {num(SPHERE[1])}), "
        f'material: RoughConductor(material: "Au", alpha: Image(path: "roughness.png", raw: true), '
        f"specular_reflectance: {image})),",
        f"        (shape: Rectangle(corner: {tup(PANEL[0])}, u: {tup(PANEL[1])}, v: {tup(PANEL[2])}), "
        f'material: NormalMap(normal_map: Image(path: "bumps.png"), material: Phong(kd: {image}))),',
        f"        (shape: Rectangle(corner: {tup(LAMP[0])}, u: {tup(LAMP[1])}, v: {tup(LAMP[2])}), "
        f'emitter: (radiance: Image(path: "glow.exr"))),',
        "    ],",
        ")",
        "",
    ])


def rtis_scene(spp, gaussian=False):
    c0, c1, scale = CHECKS
    pixel_filter = ", filter: Gaussian(stddev: 0.5)" if gaussian else ""
    image = 'Image(path: "texture.png")'
    return "\n".join([
        *rtis_head([
            "// Written by bench/mitsuba_texture_reference.py; Mitsuba 3's image of the same scene is",
            "// beside it (tests/integration/textures.rs compares them). A checkerboard floor, and a",
            "// sphere and a panel wearing tests/data/texture.png, under a constant sky and a sun.",
        ], WIDTH, HEIGHT, spp, EYE, TARGET, UP, FOV, film_extra=pixel_filter),
        f"        (light: Environment(radiance: {tup(SKY)})),",
        f"        (light: Directional(direction: {tup(SUN[0])}, irradiance: {tup(SUN[1])})),",
        f"        (shape: Rectangle(corner: {tup(FLOOR[0])}, u: {tup(FLOOR[1])}, v: {tup(FLOOR[2])}), "
        f"material: Phong(kd: Checkerboard(color0: {tup(c0)}, color1: {tup(c1)}, "
        f"uv_transform: (scale: ({num(scale)}, {num(scale)}))), ks: (0, 0, 0))),",
        f"        (shape: Sphere(center: {tup(SPHERE[0])}, radius: {num(SPHERE[1])}), "
        f"material: Phong(kd: {image}, ks: (0, 0, 0))),",
        f"        (shape: Rectangle(corner: {tup(PANEL[0])}, u: {tup(PANEL[1])}, v: {tup(PANEL[2])}), "
        f"material: Phong(kd: {image}, ks: (0, 0, 0))),",
        "    ],",
        ")",
        "",
    ])


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spp", type=int, default=4096)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--filter", choices=["box", "gaussian"], default="box")
    ap.add_argument("--scene", choices=["texture", "rough"], default="texture")
    args = ap.parse_args()
    gaussian = args.filter == "gaussian"
    rough = args.scene == "rough"
    tag = "texture_rough" if rough else "texture_gaussian" if gaussian else "texture"
    mi = load_mitsuba(args.variant)
    mi.Bitmap(texture_codes(), pixel_format=mi.Bitmap.PixelFormat.RGB).write(TEXTURE)
    if rough:
        mi.Bitmap(roughness_codes(), pixel_format=mi.Bitmap.PixelFormat.Y).write(ROUGHNESS)
        mi.Bitmap(bump_codes(), pixel_format=mi.Bitmap.PixelFormat.RGB).write(BUMPS)
        mi.Bitmap(glow_values(), pixel_format=mi.Bitmap.PixelFormat.RGB).write(GLOW)
        make = lambda n, seed: mitsuba_rough_dict(mi, n, seed)
        text = rtis_rough_scene(64)
    else:
        make = lambda n, seed: mitsuba_dict(mi, n, seed, gaussian)
        text = rtis_scene(64, gaussian)
    with open(os.path.join(ROOT, "tests/data", f"{tag}.ron"), "w") as f:
        f.write(text)
    img, half_rmse, seconds = render_halves(mi, make, args.spp, WIDTH, HEIGHT)
    stem = os.path.join(ROOT, "tests/data", f"mitsuba_{tag}_{WIDTH}x{HEIGHT}_spp{args.spp}")
    meta = write_reference(mi, stem, img, half_rmse, seconds, args.variant, args.spp)
    print(json.dumps(meta))


if __name__ == "__main__":
    main()
