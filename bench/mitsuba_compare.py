#!/usr/bin/env python3
"""Side by side: Mitsuba 3 and rtis render the same physically based Cornell box.

Not run in CI. Renders the scene of tests/data/REFERENCE-README.md (the course's box, every
sphere diffuse, three point lights) with Mitsuba 3's `path` integrator and with rtis's `Path`
shader under `model: Physical` (scenes/cornell-physical.ron) at the same samples per pixel, in
one invocation so both share the machine's state, and prints for each: wall seconds, samples per
second, and RMSE against the 4096-spp Mitsuba reference image (tests/data, mirrored left-right
to rtis's camera convention). Equal-error comparison: the ratio of samples per second, and the
time each needs to reach the other's error (RMSE falls as 1/sqrt(spp) for both).

Setup (once):
    pip install mitsuba numpy
    apt-get install libllvm19        # for the fast llvm_ad_rgb variant
    export DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so
    cargo build --release

Usage:
    python3 bench/mitsuba_compare.py [--spp 64] [--variant llvm_ad_rgb]
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
REFERENCE = os.path.join(ROOT, "tests/data/cornell_rtis_diffuse_360x288_dinf_spp4096.exr")


def mitsuba_scene(mi, spp):
    """The reference's scene as a Mitsuba dict (see tests/data/REFERENCE-README.md)."""
    T = mi.ScalarTransform4f

    def wall(to_world, rgb):
        return {
            "type": "rectangle",
            "to_world": to_world,
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": rgb}},
        }

    h = 1000.0  # half size of the rectangles standing in for infinite planes
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": -1, "rr_depth": 5},
        "sensor": {
            "type": "perspective",
            "fov": 60,
            "fov_axis": "y",
            "to_world": T().look_at(origin=[0, 0, -3], target=[0, 0, 1], up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": 360, "height": 288, "rfilter": {"type": "box"}},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        # Rectangles are the unit square in z = 0 with normal +z; orient each into the box.
        "left": wall(T().translate([-3, 0, 0]).rotate([0, 1, 0], 90).scale(h), [0.7, 0.2, 0.3]),
        "right": wall(T().translate([3, 0, 0]).rotate([0, 1, 0], -90).scale(h), [0.2, 0.7, 0.3]),
        "ceiling": wall(T().translate([0, 3, 0]).rotate([1, 0, 0], 90).scale(h), [0.8, 0.8, 0.8]),
        "floor": wall(T().translate([0, -3, 0]).rotate([1, 0, 0], -90).scale(h), [0.8, 0.8, 0.8]),
        "back": wall(T().translate([0, 0, 9]).rotate([0, 1, 0], 180).scale(h), [0.3, 0.2, 0.7]),
    }
    for name, c, r, rgb in [
        ("big", [-1.5, -1.5, 3.5], 1.5, [0.8, 0.8, 0.8]),
        ("mid", [1, 0, 2], 1.0, [0.8, 0.8, 0.8]),
        ("red", [0.3, -2, 5], 1.0, [0.7, 0.2, 0.3]),
    ]:
        scene[name] = {
            "type": "sphere",
            "center": c,
            "radius": r,
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": rgb}},
        }
    for i, z in enumerate([0, 3, 6]):
        scene[f"light{i}"] = {
            "type": "point",
            "position": [0, 2, z],
            "intensity": {"type": "rgb", "value": [7, 7, 7]},
        }
    return scene


def read_exr(path):
    import mitsuba as mi

    return np.array(mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False))


def rmse(a, b):
    return float(np.sqrt(np.mean((a - b) ** 2)))


REFERENCE_NOISE_RMSE = 0.007  # tests/data/REFERENCE-README.md


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    args = ap.parse_args()

    llvm = "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"
    if args.variant.startswith("llvm") and "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(llvm):
        os.environ["DRJIT_LIBLLVM_PATH"] = llvm
    import mitsuba as mi

    mi.set_variant(args.variant)
    ref = read_exr(REFERENCE)
    # Mitsuba's camera is right-handed: its image is rtis's mirrored left-right.
    ref_rtis = ref[:, ::-1, :]

    scene = mi.load_dict(mitsuba_scene(mi, args.spp))
    mi.render(scene, spp=1)  # compile kernels outside the timing
    t = time.perf_counter()
    img = np.array(mi.render(scene, spp=args.spp))
    t_mi = time.perf_counter() - t
    rows = [("Mitsuba 3 " + args.variant, t_mi, rmse(img, ref))]

    rtis = os.path.join(ROOT, "target/release/rtis")
    with open(os.path.join(ROOT, "scenes/cornell-physical.ron")) as f:
        text = f.read()
    with tempfile.TemporaryDirectory() as d:
        # The scene as it is (every point light at every vertex), with one light per vertex
        # chosen by power (Mitsuba's own strategy), and with one chosen by its unshadowed
        # contribution at the vertex (pbrt-v4's importance of a point light).
        for label, per_vertex in [("rtis Path, all lights", "All"), ("rtis Path, one light", "One"),
                                  ("rtis Path, one by importance", "Importance")]:
            scene_file = os.path.join(d, f"{per_vertex}.ron")
            with open(scene_file, "w") as f:
                f.write(text.replace('extends: "cornell.ron"', f'extends: "{ROOT}/scenes/cornell.ron"')
                        .replace("sampling: Brdf)", f"sampling: Brdf, lights_per_vertex: {per_vertex})"))
            out = os.path.join(d, "rtis.exr")
            cmd = [rtis, "render", scene_file, "--spp", str(args.spp), "-o", out]
            t = time.perf_counter()
            subprocess.run(cmd, check=True, stderr=subprocess.DEVNULL)
            rows.append((label, time.perf_counter() - t, rmse(read_exr(out), ref_rtis)))

    pixels = 360 * 288 * args.spp
    print(f"{'renderer':<28} {'seconds':>8} {'Msamples/s':>11} {'RMSE':>9} {'own RMSE':>9}")
    # The reference's own noise is part of every RMSE; the renderer's own error is what is
    # left, and it falls as 1/sqrt(time): time to reach a common error e is t (own / e)^2.
    own = [max(e * e - REFERENCE_NOISE_RMSE**2, 1e-12) ** 0.5 for _, _, e in rows]
    for (name, t, e), o in zip(rows, own):
        print(f"{name:<28} {t:>8.2f} {pixels / t / 1e6:>11.2f} {e:>9.5f} {o:>9.5f}")
    target = min(own)
    eq = [t * (o / target) ** 2 for (_, t, _), o in zip(rows, own)]
    for (name, _, _), q in zip(rows[1:], eq[1:]):
        print(f"at equal error (own RMSE {target:.5f}): Mitsuba {eq[0]:.2f} s, {name} {q:.2f} s: "
              f"{eq[0] / q:.2f}x Mitsuba's speed")
    print(json.dumps({"spp": args.spp, "variant": args.variant,
                      "rows": [{"renderer": n, "seconds": t, "rmse": e, "own_rmse": o, "seconds_at_equal_error": q}
                               for (n, t, e), o, q in zip(rows, own, eq)]}))


if __name__ == "__main__":
    sys.exit(main())
