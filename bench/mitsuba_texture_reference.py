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

from mitsuba_halves import load_mitsuba, num, render_halves, sensor, tup, write_reference

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


def mitsuba_dict(mi, spp, seed=0, gaussian=False):
    rgb = lambda c: {"type": "rgb", "value": c}
    camera = sensor(mi, "perspective", EYE, TARGET, UP, FOV, WIDTH, HEIGHT, spp, seed)
    if gaussian:
        camera["film"]["rfilter"] = {"type": "gaussian", "stddev": 0.5}
    bitmap = {"type": "bitmap", "filename": TEXTURE, "filter_type": "bilinear", "wrap_mode": "repeat"}
    c0, c1, scale = CHECKS
    return {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": -1, "rr_depth": 5},
        "sensor": camera,
        "sky": {"type": "constant", "radiance": rgb(SKY)},
        "sun": {"type": "directional", "direction": SUN[0], "irradiance": rgb(SUN[1])},
        "floor": {"type": "rectangle", "to_world": rect_to_world(mi, *FLOOR),
                  "bsdf": {"type": "diffuse", "reflectance": {
                      "type": "checkerboard", "color0": rgb(c0), "color1": rgb(c1),
                      "to_uv": mi.ScalarTransform4f().scale([scale, scale, 1])}}},
        "sphere": {"type": "sphere", "center": SPHERE[0], "radius": SPHERE[1],
                   "bsdf": {"type": "diffuse", "reflectance": bitmap}},
        "panel": {"type": "rectangle", "to_world": rect_to_world(mi, *PANEL),
                  "bsdf": {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": bitmap}}},
    }


def rtis_scene(spp, gaussian=False):
    c0, c1, scale = CHECKS
    pixel_filter = ", filter: Gaussian(stddev: 0.5)" if gaussian else ""
    image = 'Image(path: "texture.png")'
    return "\n".join([
        "// Written by bench/mitsuba_texture_reference.py; Mitsuba 3's image of the same scene is",
        "// beside it (tests/integration/textures.rs compares them). A checkerboard floor, and a",
        "// sphere and a panel wearing tests/data/texture.png, under a constant sky and a sun.",
        "Scene(",
        f"    film: (width: {WIDTH}, height: {HEIGHT}, spp: {spp}{pixel_filter}),",
        f"    camera: Perspective(position: {tup(EYE)}, look_at: {tup(TARGET)}, up: {tup(UP)}, "
        f"fov: {num(FOV)}),",
        "    shader: Path(rr_depth: 5),",
        "    model: Physical,",
        "    entities: [",
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
    args = ap.parse_args()
    gaussian = args.filter == "gaussian"
    tag = "texture_gaussian" if gaussian else "texture"
    mi = load_mitsuba(args.variant)
    mi.Bitmap(texture_codes(), pixel_format=mi.Bitmap.PixelFormat.RGB).write(TEXTURE)
    with open(os.path.join(ROOT, "tests/data", f"{tag}.ron"), "w") as f:
        f.write(rtis_scene(64, gaussian))
    img, half_rmse, seconds = render_halves(mi, lambda n, seed: mitsuba_dict(mi, n, seed, gaussian),
                                            args.spp, WIDTH, HEIGHT)
    stem = os.path.join(ROOT, "tests/data", f"mitsuba_{tag}_{WIDTH}x{HEIGHT}_spp{args.spp}")
    meta = write_reference(mi, stem, img, half_rmse, seconds, args.variant, args.spp)
    print(json.dumps(meta))


if __name__ == "__main__":
    main()
