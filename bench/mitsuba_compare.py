#!/usr/bin/env python3
"""Side by side: Mitsuba 3 and rtis render the same scenes, samples per second and error.

Not run in CI. Three scenes, each rendered by Mitsuba 3's `path` integrator and by rtis's `Path`
shader under `model: Physical` at the same samples per pixel, in one invocation so both share the
machine's state:

- `diffuse`: the course's box with every sphere diffuse and three point lights
  (scenes/cornell-physical.ron, tests/data/REFERENCE-README.md), against the stored 4096-spp
  Mitsuba image;
- `full`: the same box with the course's mirror ball and a Fresnel glass ball (ior 1.1), against
  a Mitsuba image rendered here at --reference-spp in two independent halves (their difference
  measures its own noise);
- `area`: Mitsuba's own `cornell_box()` lit by its area light (scenes/mitsuba-cornell.ron),
  against the stored 4096-spp Mitsuba image.

For each it prints seconds (each renderer's render alone: Mitsuba's `render` call after a first
call has compiled its kernels, rtis's render from its first pixel to its last as `--stats`
reports it; neither counts loading the scene, building its BVH or writing the image), samples
per second, RMSE against the reference (over the timed image and --error-seeds more renders
under other seeds, untimed) and the
renderer's own RMSE (the reference's noise taken out), and the time each needs to reach the
smallest own error (RMSE falls as 1/sqrt(spp); exactly so for independent samplers, while a
low-discrepancy sampler's falls faster, so its row's time is exact only where its error is the
smallest). rtis renders with the same estimator as Mitsuba's `path` (one light sample per
vertex, MIS with the BSDF sample) and with its other strategies: every point light at every
vertex, one by importance, light or BSDF sampling alone, and its Sobol' sampler (on the area box
beside Mitsuba's own `ldsampler`).

Setup (once):
    .venv/bin/pip install mitsuba numpy
    apt-get install libllvm19        # for the fast llvm_ad_rgb variant
    cargo build --release

Usage:
    .venv/bin/python bench/mitsuba_compare.py [--spp 64] [--scenes diffuse,full,area]
        [--reference-spp 1024] [--variant llvm_ad_rgb] [--rounds 5] [--error-seeds 3]

Each renderer and strategy renders --rounds times, the rounds interleaved (Mitsuba first in
even rounds, last in odd ones), so that each round's ratios compare runs that saw the same
machine; the tables give the median of each round's ratio and their range.
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
REFERENCE = os.path.join(ROOT, "tests/data/cornell_rtis_diffuse_360x288_dinf_spp4096.exr")


def mitsuba_scene(mi, spp, full=False):
    """The reference's scene as a Mitsuba dict (see tests/data/REFERENCE-README.md); with
    `full`, the large sphere a tinted mirror and the middle one glass of index 1.1."""
    T = mi.ScalarTransform4f

    def wall(to_world, rgb):
        return {
            "type": "rectangle",
            "to_world": to_world,
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": rgb}},
        }

    def diffuse(rgb):
        return {"type": "diffuse", "reflectance": {"type": "rgb", "value": rgb}}

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
    mirror = {"type": "conductor", "material": "none",
              "specular_reflectance": {"type": "rgb", "value": [1, 0.9, 0.85]}}
    glass = {"type": "dielectric", "int_ior": 1.1, "ext_ior": 1.0}
    for name, c, r, bsdf in [
        ("big", [-1.5, -1.5, 3.5], 1.5, mirror if full else diffuse([0.8, 0.8, 0.8])),
        ("mid", [1, 0, 2], 1.0, glass if full else diffuse([0.8, 0.8, 0.8])),
        ("red", [0.3, -2, 5], 1.0, diffuse([0.7, 0.2, 0.3])),
    ]:
        scene[name] = {"type": "sphere", "center": c, "radius": r, "bsdf": bsdf}
    for i, z in enumerate([0, 3, 6]):
        scene[f"light{i}"] = {
            "type": "point",
            "position": [0, 2, z],
            "intensity": {"type": "rgb", "value": [7, 7, 7]},
        }
    return scene


def area_scene(mi, spp):
    """`mi.cornell_box()` as bench/mitsuba_area_reference.py renders it."""
    d = mi.cornell_box()
    d["integrator"] = {"type": "path", "max_depth": -1, "rr_depth": 5, "hide_emitters": False}
    d["sensor"]["film"].update(width=128, height=128, rfilter={"type": "box"}, pixel_format="rgb",
                               component_format="float32")
    d["sensor"]["sampler"] = {"type": "independent", "sample_count": spp}
    return d


def read_exr(path):
    import mitsuba as mi

    return np.array(mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False))


def rmse(a, b):
    return float(np.sqrt(np.mean((a - b) ** 2)))


# The rtis scene text of each comparison and its strategies: (label, what replaces the shader).
PHYSICAL = open(os.path.join(ROOT, "scenes/cornell-physical.ron")).read().replace(
    'extends: "cornell.ron"', f'extends: "{ROOT}/scenes/cornell.ron"')
FULL = (PHYSICAL
        .replace('(name: "mirror ball", shape: Sphere(center: (-1.5, -1.5, 3.5), radius: 1.5), material: Phong(kd: (0.8, 0.8, 0.8)))',
                 '(name: "mirror ball", shape: Sphere(center: (-1.5, -1.5, 3.5), radius: 1.5), material: Mirror(color: (1, 0.9, 0.85)))')
        .replace('(name: "glass ball",  shape: Sphere(center: (1, 0, 2), radius: 1),           material: Phong(kd: (0.8, 0.8, 0.8)))',
                 '(name: "glass ball",  shape: Sphere(center: (1, 0, 2), radius: 1),           material: Transmissive(ior: 1.1))'))
assert FULL.count("Mirror(") == 1 and FULL.count("Transmissive(") == 1, "cornell-physical.ron changed"
AREA = open(os.path.join(ROOT, "scenes/mitsuba-cornell.ron")).read()
# (label, what the shader adds, the film's sampler): rtis's independent sampler unless named.
POINT_STRATEGIES = [
    ("rtis Path, one light (same strategy)", "lights_per_vertex: One", None),
    ("rtis Path, all lights", "lights_per_vertex: All", None),
    ("rtis Path, one by importance", "lights_per_vertex: Importance", None),
    ("rtis Path, all lights, Sobol' sampler", "lights_per_vertex: All", "Sobol"),
]
AREA_STRATEGIES = [
    ("rtis Path, MIS (same strategy)", "lights: Mis", None),
    ("rtis Path, light sampling", "lights: Light", None),
    ("rtis Path, BSDF sampling", "lights: Brdf", None),
    ("rtis Path, MIS, Sobol' sampler", "lights: Mis", "Sobol"),
]


def rtis_runs(text, strategies, spp, d):
    """rtis's runs: for each strategy, a function that renders it once under a seed (the
    scene's, 0, by default) and returns (seconds, image), the scene file written once into the
    folder `d`."""
    rtis = os.path.join(ROOT, "target/release/rtis")
    runs = []
    for k, (label, strategy, sampler) in enumerate(strategies):
        scene_file = os.path.join(d, f"scene{k}.ron")
        scene = text.replace("sampling: Brdf)", f"sampling: Brdf, {strategy})")
        if sampler:
            assert scene.count("spp: 64),") == 1, "the scene's film changed"
            scene = scene.replace("spp: 64),", f"spp: 64, sampler: {sampler}),")
        with open(scene_file, "w") as f:
            f.write(scene)

        def run(seed=0, scene_file=scene_file):
            out, stats = os.path.join(d, "rtis.exr"), os.path.join(d, "stats.json")
            subprocess.run([rtis, "render", scene_file, "--spp", str(spp), "--seed", str(seed), "-o", out,
                            "--stats", stats], check=True, stderr=subprocess.DEVNULL)
            # The render's own seconds, from its first pixel to its last: as Mitsuba's are
            # timed, without loading the scene (its BVH built) and writing the image.
            with open(stats) as f:
                return json.load(f)["seconds"], read_exr(out)

        runs.append((label, run))
    return runs


def mitsuba_run(mi, scene, spp, variant, label=None):
    """Mitsuba's run: a function that renders once under a seed (its default, 0, unless given)
    and returns (seconds, image); its kernels
    are compiled first, outside the timing, by a render at the same spp (a kernel depends on
    it: `render` coalesces its passes from 4 spp on and folds the spp into the kernel) whose
    image is read (Dr.Jit is lazy: a render never read runs nothing, and the first timed one
    then compiled its kernels, twice the time of the others on the area box)."""
    np.array(mi.render(scene, spp=spp))

    def run(seed=0):
        t = time.perf_counter()
        img = np.array(mi.render(scene, spp=spp, seed=seed))
        return time.perf_counter() - t, img

    return (label or "Mitsuba 3 " + variant, run)


def compare(name, mi, args):
    """`measure` in a temporary folder of its own, removed after."""
    with tempfile.TemporaryDirectory() as tmp:
        return measure(name, mi, args, tmp)


def measure(name, mi, args, tmp):
    """One scene: (width, height, reference noise RMSE, rows), each row (label, seconds of each
    round, RMSE). Each round renders Mitsuba and every rtis strategy once, Mitsuba first in
    even rounds and last in odd ones; the images are the same in every round (fixed seeds).
    The RMSE is the root of the mean squared error of the first round's image and of
    `--error-seeds` more renders under other seeds (ERROR_SEEDS, none the full box's reference
    uses), untimed: one image's error swings with its few brightest pixels."""
    if name == "diffuse":
        ref = read_exr(os.path.join(ROOT, "tests/data/cornell_rtis_diffuse_360x288_dinf_spp4096.exr"))
        noise, size = 0.007, (360, 288)
        runs = [mitsuba_run(mi, mi.load_dict(mitsuba_scene(mi, args.spp)), args.spp, args.variant)]
        runs += rtis_runs(PHYSICAL, POINT_STRATEGIES, args.spp, tmp)
    elif name == "full":
        # The reference: two independent halves, their mean, and its noise from their difference.
        half = mi.load_dict(mitsuba_scene(mi, args.reference_spp // 2, full=True))
        a = np.array(mi.render(half, spp=args.reference_spp // 2, seed=1))
        b = np.array(mi.render(half, spp=args.reference_spp // 2, seed=2))
        ref, noise, size = (a + b) / 2, rmse(a, b) / 2, (360, 288)
        runs = [mitsuba_run(mi, mi.load_dict(mitsuba_scene(mi, args.spp, full=True)), args.spp, args.variant)]
        runs += rtis_runs(FULL, POINT_STRATEGIES, args.spp, tmp)
    else:
        ref = read_exr(os.path.join(ROOT, "tests/data/mitsuba_cornell_area_128_spp4096.exr"))
        with open(os.path.join(ROOT, "tests/data/mitsuba_cornell_area_128_spp4096.json")) as f:
            noise = json.load(f)["noise_rmse"]
        size = (128, 128)
        runs = [mitsuba_run(mi, mi.load_dict(area_scene(mi, args.spp)), args.spp, args.variant)]
        # Mitsuba with its own low-discrepancy sampler too, beside rtis's Sobol' sampler.
        ld = area_scene(mi, args.spp)
        ld["sensor"]["sampler"] = {"type": "ldsampler", "sample_count": args.spp}
        runs.append(mitsuba_run(mi, mi.load_dict(ld), args.spp, args.variant,
                                f"Mitsuba 3 {args.variant}, ldsampler"))
        runs += rtis_runs(AREA, AREA_STRATEGIES, args.spp, tmp)
    seconds = [[] for _ in runs]
    squared = [[] for _ in runs]

    def error(k, img):
        # rtis's camera is left-handed: its image is Mitsuba's mirrored left-right.
        mitsuba = runs[k][0].startswith("Mitsuba")
        squared[k].append(rmse(img if mitsuba else img[:, ::-1, :], ref) ** 2)

    for r in range(args.rounds):
        order = list(range(len(runs)))
        if r % 2 == 1:
            order = order[1:] + order[:1]
        for k in order:
            t, img = runs[k][1]()
            seconds[k].append(t)
            if r == 0:
                error(k, img)
    for k in range(len(runs)):
        for seed in ERROR_SEEDS[:args.error_seeds]:
            error(k, runs[k][1](seed)[1])
    errors = [float(np.sqrt(np.mean(s))) for s in squared]
    return size, noise, [(label, s, e) for (label, _), s, e in zip(runs, seconds, errors)]


# The seeds of the renders that only measure error: none of the timed renders' (0), the full
# box's Mitsuba reference halves' (1, 2) or the area box reference's (0 to 15).
ERROR_SEEDS = [100, 101, 102, 103, 104, 105, 106, 107]


def interval(values):
    """The median of `values` and their range."""
    return statistics.median(values), [min(values), max(values)]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--scenes", default="diffuse,full,area")
    ap.add_argument("--reference-spp", type=int, default=1024)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--rounds", type=int, default=5, help="renders of each renderer and strategy")
    ap.add_argument("--error-seeds", type=int, default=3, choices=range(0, 9),
                    help="more renders under other seeds for the RMSE (untimed)")
    args = ap.parse_args()
    if args.rounds < 1:
        sys.exit("--rounds must be at least 1")

    llvm = "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"
    if args.variant.startswith("llvm") and "DRJIT_LIBLLVM_PATH" not in os.environ and os.path.exists(llvm):
        os.environ["DRJIT_LIBLLVM_PATH"] = llvm
    import mitsuba as mi

    mi.set_variant(args.variant)
    report = {"spp": args.spp, "variant": args.variant, "reference_spp": args.reference_spp,
              "rounds": args.rounds, "error_seeds": args.error_seeds, "scenes": {}}
    for name in args.scenes.split(","):
        (w, h), noise, rows = compare(name, mi, args)
        samples = w * h * args.spp
        # The reference's own noise is part of every RMSE; the renderer's own error is what is
        # left, and it falls as 1/sqrt(time): time to reach a common error e is t (own / e)^2.
        own = [max(e * e - noise**2, 1e-12) ** 0.5 for _, _, e in rows]
        target = min(own)
        scale = [(o / target) ** 2 for o in own]
        mitsuba_s = rows[0][1]
        print(f"\n{name}: {w}x{h} at {args.spp} spp (reference noise RMSE {noise:.5f}), "
              f"{args.rounds} rounds (medians; ratios to Mitsuba per round, median [range])")
        print(f"{'renderer':<40} {'seconds':>8} {'Msamples/s':>11} {'vs Mitsuba':>22} {'RMSE':>9} "
              f"{'own RMSE':>9} {'equal-error vs Mitsuba':>24}")
        out = []
        for (label, secs, e), o, sc in zip(rows, own, scale):
            t = statistics.median(secs)
            # Each round's ratios: Mitsuba's seconds over this row's, at the same samples and
            # at equal error.
            rate, rate_range = interval([m / x for m, x in zip(mitsuba_s, secs)])
            eq, eq_range = interval([m * scale[0] / (x * sc) for m, x in zip(mitsuba_s, secs)])
            print(f"{label:<40} {t:>8.2f} {samples / t / 1e6:>11.2f} "
                  f"{rate:>8.2f}x [{rate_range[0]:.2f}-{rate_range[1]:.2f}] {e:>9.5f} {o:>9.5f} "
                  f"{eq:>9.2f}x [{eq_range[0]:.2f}-{eq_range[1]:.2f}]")
            out.append({"renderer": label, "seconds": t, "seconds_rounds": secs, "rmse": e, "own_rmse": o,
                        "seconds_at_equal_error": t * sc, "vs_mitsuba": rate, "vs_mitsuba_range": rate_range,
                        "equal_error_vs_mitsuba": eq, "equal_error_range": eq_range})
        report["scenes"][name] = {"width": w, "height": h, "reference_noise": noise, "rows": out}
    print(json.dumps(report))


if __name__ == "__main__":
    sys.exit(main())
