#!/usr/bin/env python3
"""Mitsuba 3's image of a Mitsuba scene file, for the importer's side-by-side tests.

Not run in CI. Mitsuba loads the XML file itself (`mi.load_file`); rtis imports the same file
(`rtis import`, or `rtis render FILE.xml`). tests/integration/import.rs compares the two.

It writes tests/data/mitsuba_import_<NAME>_<W>x<H>_spp<N>.exr (linear float32 RGB, Mitsuba's
own orientation: an imported scene renders as Mitsuba's image, not its mirror), a .json
beside it with the version, variant, spp, seconds, the image mean and `noise_rmse`, and
docs/images/mitsuba-import-<NAME>.png (sRGB) for the README.

Setup: pip install mitsuba numpy; apt-get install libllvm19 (else --variant scalar_rgb).

Usage:
    python3 bench/mitsuba_import_reference.py tests/data/import/cbox.xml [--spp 4096]
"""

import argparse
import json
import os

import numpy as np

from mitsuba_halves import load_mitsuba, render_halves, write_reference

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene")
    ap.add_argument("--spp", type=int, default=4096)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    args = ap.parse_args()
    mi = load_mitsuba(args.variant)
    probe = mi.load_file(args.scene)
    width, height = probe.sensors()[0].film().size()
    load = lambda n, seed: mi.load_file(args.scene)
    img, half_rmse, seconds = render_halves(mi, None, args.spp, width, height, load=load)
    name = os.path.splitext(os.path.basename(args.scene))[0]
    stem = os.path.join(ROOT, "tests/data", f"mitsuba_import_{name}_{width}x{height}_spp{args.spp}")
    meta = write_reference(mi, stem, img, half_rmse, seconds, args.variant, args.spp)
    # Mitsuba's image for the README (sRGB PNG, its own orientation).
    png = os.path.join(ROOT, "docs/images", f"mitsuba-import-{name}.png")
    bitmap = mi.Bitmap(img.astype(np.float32), pixel_format=mi.Bitmap.PixelFormat.RGB)
    bitmap.convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.UInt8, srgb_gamma=True).write(png)
    print(json.dumps(meta))


if __name__ == "__main__":
    main()
