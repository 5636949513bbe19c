#!/usr/bin/env python3
"""Reference image of Mitsuba 3's standard Cornell box (area light), and the same scene for rtis.

Not run in CI. Takes the scene dict of `mitsuba.cornell_box()` (the classic box: five diffuse
walls, two rotated cubes and a one-sided rectangle area light under the ceiling) and keeps its
geometry, BSDFs, emitter radiance and camera exactly; it overrides only how the image is made:
the `path` integrator unbounded (`max_depth: -1`) with Russian roulette from depth 5 and the
emitters visible, a 128x128 film with a box pixel filter, and the `independent` sampler.

It renders two independent halves of 2048 samples per pixel each (disjoint sampler seeds, each
half in chunks to bound memory) and writes:

- tests/data/mitsuba_cornell_area_128_spp4096.exr: the mean of the halves, linear float32 RGB in
  Mitsuba's own orientation (not flipped);
- tests/data/mitsuba_cornell_area_128_spp4096.json: Mitsuba version and variant, spp, size,
  render seconds, the image's mean linear RGB, `half_rmse` (RMSE between the two halves over all
  pixels and channels) and `noise_rmse` = half_rmse / 2, the RMSE of their mean against its
  expectation (each half's error has variance s^2, their difference 2 s^2, the mean s^2 / 2);
- scenes/mitsuba-cornell.ron: the same scene in rtis's format, derived from the same dict: each
  rectangle's and cube's `to_world` (Mitsuba's single-precision matrix, read exactly) applied
  with numpy in double precision to the shape's local geometry (the rectangle [-1, 1]^2 in
  z = 0 with normal +z; the cube [-1, 1]^3 as Mitsuba's own mesh, its 24 vertices merged to 8),
  numbers written as the repr of a float64 (whole ones as integers), so they parse back to
  exactly these values. The camera is look_at's origin, target and up, recovered from the
  sensor's to_world and checked to rebuild it.

Orientation: Mitsuba's camera is right-handed, so its image is rtis's mirrored left-right
(the red wall, x = -1, is on the left in Mitsuba's image and on the right in rtis's). Flip the
reference (img[:, ::-1]) before comparing with rtis; see bench/mitsuba_compare.py and
tests/data/REFERENCE-README.md.

One difference the formats cannot express: Mitsuba's `diffuse` BSDF is one-sided (black seen
from behind), rtis shades both sides. Only the back (top) of the light, 0.01 below the ceiling,
is ever hit from behind. --check-light-back renders both with the same seeds: at 4096 spp a
two-sided light BSDF raises the mean red by 7e-5 (RMSE 0.0004), far below the noise (0.005).

Setup (once; the venv is gitignored):
    python3 -m venv .venv                      # from the repository root, if absent
    .venv/bin/pip install mitsuba numpy
    # For the fast llvm_ad_rgb variant (the default): LLVM 14 and 15 abort with
    # "LLVM ERROR: Cannot select ... fminimum"; LLVM 19 works.
    apt-get install libllvm19
    export DRJIT_LIBLLVM_PATH=/usr/lib/x86_64-linux-gnu/libLLVM-19.so   # set for you if unset
    # Without LLVM, use --variant scalar_rgb (slower, same expectation).

Usage:
    .venv/bin/python bench/mitsuba_area_reference.py [--variant llvm_ad_rgb] [--spp 4096]
        [--threads 2] [--chunk-spp 256]     # render the reference and write the rtis scene
    .venv/bin/python bench/mitsuba_area_reference.py --write-scene   # only the rtis scene
    .venv/bin/python bench/mitsuba_area_reference.py --print-scene   # scene to stdout
    .venv/bin/python bench/mitsuba_area_reference.py --print-dict    # mi.cornell_box() as given
    .venv/bin/python bench/mitsuba_area_reference.py --check-light-back [--spp 4096]
"""

import argparse
import json
import os
import sys
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENE_OUT = os.path.join(ROOT, "scenes/mitsuba-cornell.ron")
LIBLLVM = "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"
WIDTH = HEIGHT = 128
ORIENTATION = (
    "Mitsuba's own (not flipped): its camera is right-handed, so the red wall (x = -1) is on "
    "the image's left; rtis's camera (image right = up x forward) puts it on the right. Flip "
    "left-right (img[:, ::-1]) before comparing with rtis."
)


# ----------------------------------------------------------------------------- Mitsuba scene


def reference_dict(mi, spp):
    """`mi.cornell_box()` with only the integrator, film size, filter and sampler overridden."""
    d = mi.cornell_box()
    d["integrator"] = {"type": "path", "max_depth": -1, "rr_depth": 5, "hide_emitters": False}
    film = d["sensor"]["film"]
    film.update(width=WIDTH, height=HEIGHT, rfilter={"type": "box"}, pixel_format="rgb",
                component_format="float32")
    d["sensor"]["sampler"] = {"type": "independent", "sample_count": spp}
    return d


# ------------------------------------------------------------------------------- rtis scene


def fmt(x):
    """A float64 written so that it parses back exactly (integers without a fraction)."""
    x = float(x) + 0.0  # no -0.0
    return str(int(x)) if x.is_integer() and abs(x) < 1e15 else repr(x)


def vec(v):
    return "(" + ", ".join(fmt(c) for c in v) + ")"


def matrix(t):
    """A Mitsuba transform's 4x4 matrix, its single-precision entries exactly, as float64."""
    return np.array(t.matrix, dtype=np.float64).reshape(4, 4)


def point(m, p):
    return m[:3, :3] @ np.asarray(p, dtype=np.float64) + m[:3, 3]


def reflectance(d, bsdf):
    """The linear RGB reflectance of a shape's BSDF (resolving a `ref`), checked diffuse RGB."""
    if bsdf["type"] == "ref":
        bsdf = d[bsdf["id"]]
    if bsdf["type"] != "diffuse" or bsdf["reflectance"]["type"] != "rgb":
        raise ValueError(f"only diffuse BSDFs with an rgb reflectance are mapped, got {bsdf}")
    kd = [float(c) for c in bsdf["reflectance"]["value"]]
    if not all(0.0 <= c <= 1.0 for c in kd):
        raise ValueError(f"reflectance {kd} outside [0, 1]")
    return kd


def vertical_fov(sensor):
    """The vertical field of view in degrees of a perspective sensor dict."""
    fov = float(sensor["fov"])
    w, h = sensor["film"]["width"], sensor["film"]["height"]
    axis = sensor.get("fov_axis", "x")
    if axis == "smaller":
        axis = "x" if w <= h else "y"
    elif axis == "larger":
        axis = "x" if w >= h else "y"
    if axis == "y":
        return fov
    if axis != "x":
        raise ValueError(f"fov_axis {axis!r} not mapped")
    return float(np.degrees(2 * np.arctan(np.tan(np.radians(fov) / 2) * h / w)))


def cube_mesh(mi):
    """Mitsuba's own unit cube ([-1, 1]^3): its 8 distinct corners and 12 triangles over them."""
    params = mi.traverse(mi.load_dict({"type": "cube"}))
    pos = np.array(params["vertex_positions"], dtype=np.float64).reshape(-1, 3)
    faces = np.array(params["faces"], dtype=np.int64).reshape(-1, 3)
    corners, index = np.unique(pos, axis=0, return_inverse=True)
    faces = index.reshape(-1)[faces]
    assert len(corners) == 8 and len(faces) == 12
    return corners, faces


def check_against_mitsuba(mi, d, name, world):
    """Mitsuba's own world-space cube vertices (single precision) match ours."""
    shape = dict(d[name], bsdf={"type": "diffuse"})  # alone: no reference to resolve
    params = mi.traverse(mi.load_dict({"type": "scene", name: shape}))
    theirs = np.array(params[f"{name}.vertex_positions"], dtype=np.float64).reshape(-1, 3)
    dist = np.abs(theirs[:, None, :] - world[None, :, :]).max(axis=2).min(axis=1)
    assert dist.max() < 1e-6, f"{name}: Mitsuba's vertices differ by {dist.max()}"


def rtis_scene(mi, d):
    """The scene dict `d` (cornell_box() or its reference override) in rtis's RON format."""
    sensor = d["sensor"]
    cam = matrix(sensor["to_world"])
    # Columns: left, up, forward, origin (look_at's, in single precision: unit to 1e-7).
    origin = cam[:3, 3]
    up, forward = (cam[:3, i] / np.linalg.norm(cam[:3, i]) for i in (1, 2))
    # look_at's target is not stored; the point of the view axis nearest the world origin is
    # cornell_box()'s target (0, 0, 0) exactly.
    target = origin - np.dot(origin, forward) * forward
    again = matrix(mi.ScalarTransform4f().look_at(origin=origin, target=target, up=up))
    assert np.allclose(again, cam, rtol=0, atol=1e-6), f"camera {again} != {cam}"
    film = sensor["film"]
    corners, cube_faces = cube_mesh(mi)

    lines = [
        "// Mitsuba 3's standard Cornell box (`mitsuba.cornell_box()`, Mitsuba "
        + mi.__version__ + "): five diffuse",
        "// walls (the box spans [-1, 1]^3, open at z = +1), two rotated cubes and a one-sided",
        "// rectangle area light 0.01 under the ceiling, emitting downwards; the light's BSDF is",
        "// the white walls'. Generated by bench/mitsuba_area_reference.py from the same dict as",
        "// the reference tests/data/mitsuba_cornell_area_128_spp4096.exr: each shape's to_world",
        "// (single precision, hence offsets of order 1e-7 from round values) applied exactly to",
        "// its local shape (rectangle [-1, 1]^2 in z = 0, normal +z = u x v; cube [-1, 1]^3).",
        "// rtis's image is Mitsuba's mirrored left-right (Mitsuba's camera is right-handed: its",
        "// red wall, x = -1, is on the left, rtis's on the right); see bench/mitsuba_compare.py",
        "// and tests/data/REFERENCE-README.md. Mitsuba's diffuse BSDF is one-sided (the light's",
        "// back is black there), rtis's Phong two-sided. The large cube reaches 0.01 below the",
        "// floor, as in Mitsuba.",
        "Scene(",
        f"    film: (width: {film['width']}, height: {film['height']}, spp: 64),",
        f"    camera: Perspective(position: {vec(origin)}, look_at: {vec(target)}, "
        f"up: {vec(up)}, fov: {fmt(vertical_fov(sensor))}),",
        "    shader: Path(rr_depth: 5, sampling: Brdf),",
        "    model: Physical,",
        "    entities: [",
    ]
    for name, shape in d.items():
        if not isinstance(shape, dict) or shape.get("type") not in ("rectangle", "cube"):
            continue
        m = matrix(shape["to_world"])
        kd = reflectance(d, shape["bsdf"])
        if np.linalg.det(m[:3, :3]) <= 0:
            raise ValueError(f"{name}: mirroring to_world, u x v would flip Mitsuba's normal")
        if shape["type"] == "rectangle":
            corner = point(m, [-1, -1, 0])
            u = point(m, [1, -1, 0]) - corner
            v = point(m, [-1, 1, 0]) - corner
            # Mitsuba's normal: to_world's inverse transpose applied to +z.
            n_mi = np.linalg.inv(m[:3, :3]).T @ [0.0, 0.0, 1.0]
            n = np.cross(u, v)
            assert np.dot(n, n_mi) > 0 and np.allclose(n / np.linalg.norm(n),
                                                       n_mi / np.linalg.norm(n_mi), atol=1e-7)
            text = f"Rectangle(corner: {vec(corner)}, u: {vec(u)}, v: {vec(v)})"
        else:
            world = np.array([point(m, p) for p in corners])
            check_against_mitsuba(mi, d, name, world)
            text = ("TriangleMesh(\n            vertices: ["
                    + ", ".join(vec(p) for p in world) + "],\n            faces: ["
                    + ", ".join(vec(f) for f in cube_faces) + "],\n        )")
        entity = f'        (name: "{name}", shape: {text}, material: Phong(kd: {vec(kd)})'
        if "emitter" in shape:
            e = shape["emitter"]
            if e["type"] != "area" or e["radiance"]["type"] != "rgb":
                raise ValueError(f"{name}: only rgb area emitters are mapped, got {e}")
            if shape["type"] != "rectangle":
                raise ValueError(f"{name}: emitting {shape['type']} not mapped")
            normal = np.cross(u, v) / np.linalg.norm(np.cross(u, v))
            assert normal[1] < -0.999999, f"{name}: normal {normal} does not point down"
            entity += (f",\n         emitter: Emitter(radiance: {vec(e['radiance']['value'])}, "
                       "two_sided: false)")
        lines.append(entity + "),")
    lines += ["    ],", ")", ""]
    return "\n".join(lines)


# -------------------------------------------------------------------------------- rendering


def render(mi, scene, spp, chunk_spp, seeds):
    """Mean of len(seeds) renders of chunk_spp each (box filter: each sample is its pixel's)."""
    assert spp == chunk_spp * len(seeds)
    acc = np.zeros((HEIGHT, WIDTH, 3))
    for seed in seeds:
        acc += np.array(mi.render(scene, spp=chunk_spp, seed=seed), dtype=np.float64)
    return acc / len(seeds)


def rmse(a, b):
    return float(np.sqrt(np.mean((a - b) ** 2)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--variant", default="llvm_ad_rgb", help="llvm_ad_rgb or scalar_rgb")
    ap.add_argument("--spp", type=int, default=4096, help="total samples per pixel (two halves)")
    ap.add_argument("--chunk-spp", type=int, default=256, help="samples per pixel per render call")
    ap.add_argument("--threads", type=int, default=0, help="Dr.Jit threads (0: all cores)")
    ap.add_argument("--write-scene", action="store_true", help="only write " + SCENE_OUT)
    ap.add_argument("--print-scene", action="store_true", help="only print the rtis scene")
    ap.add_argument("--print-dict", action="store_true", help="only print mi.cornell_box()")
    ap.add_argument("--check-light-back", action="store_true",
                    help="only measure what a one-sided vs two-sided light BSDF changes")
    args = ap.parse_args()
    if args.spp % 2 or (args.spp // 2) % args.chunk_spp:
        ap.error("--spp must be twice a multiple of --chunk-spp")

    if args.variant.startswith("llvm") and "DRJIT_LIBLLVM_PATH" not in os.environ \
            and os.path.exists(LIBLLVM):
        os.environ["DRJIT_LIBLLVM_PATH"] = LIBLLVM
    import drjit as dr
    import mitsuba as mi

    mi.set_variant(args.variant)
    if args.threads:
        dr.set_thread_count(args.threads)

    if args.print_dict:
        import pprint

        pprint.pprint(mi.cornell_box(), width=100)
        return 0
    d = reference_dict(mi, args.spp // 2)
    ron = rtis_scene(mi, d)
    if args.print_scene:
        sys.stdout.write(ron)
        return 0
    with open(SCENE_OUT, "w") as f:
        f.write(ron)
    print(f"wrote {os.path.relpath(SCENE_OUT, ROOT)}")
    if args.write_scene:
        return 0

    n = args.spp // 2 // args.chunk_spp
    if args.check_light_back:
        # Same seeds, so the two renders share every path until one reaches the light's back.
        d2 = reference_dict(mi, args.spp)
        d2["light"]["bsdf"] = {"type": "twosided", "bsdf": d2["white"]}
        a = render(mi, mi.load_dict(d), args.spp, args.chunk_spp, range(2 * n))
        b = render(mi, mi.load_dict(d2), args.spp, args.chunk_spp, range(2 * n))
        print(f"one-sided light BSDF (Mitsuba) mean RGB {a.mean(axis=(0, 1))}")
        print(f"two-sided light BSDF (as rtis)  mean RGB {b.mean(axis=(0, 1))}")
        print(f"difference: mean RGB {(b - a).mean(axis=(0, 1))}, RMSE {rmse(a, b):.6f}")
        return 0

    scene = mi.load_dict(d)
    mi.render(scene, spp=1, seed=2**31)  # compile kernels outside the timing
    t = time.perf_counter()
    halves = [render(mi, scene, args.spp // 2, args.chunk_spp, range(h * n, (h + 1) * n))
              for h in range(2)]
    seconds = time.perf_counter() - t
    img = (halves[0] + halves[1]) / 2
    half_rmse = rmse(halves[0], halves[1])

    stem = os.path.join(ROOT, f"tests/data/mitsuba_cornell_area_{WIDTH}_spp{args.spp}")
    mi.Bitmap(img.astype(np.float32), pixel_format=mi.Bitmap.PixelFormat.RGB).write(stem + ".exr")
    meta = {
        "scene": "mitsuba.cornell_box(): geometry, BSDFs, emitter and camera unchanged",
        "rtis_scene": os.path.relpath(SCENE_OUT, ROOT),
        "mitsuba": mi.__version__,
        "drjit": dr.__version__,
        "variant": args.variant,
        "integrator": d["integrator"],
        "sampler": "independent",
        "rfilter": "box",
        "spp": args.spp,
        "halves": 2,
        "chunk_spp": args.chunk_spp,
        "seeds": f"half 0: 0 to {n - 1}, half 1: {n} to {2 * n - 1}, one per chunk",
        "width": WIDTH,
        "height": HEIGHT,
        "threads": dr.thread_count(),
        "seconds": seconds,
        "mean_rgb": [float(c) for c in img.mean(axis=(0, 1))],
        "half_rmse": half_rmse,
        "noise_rmse": half_rmse / 2,
        "orientation": ORIENTATION,
    }
    with open(stem + ".json", "w") as f:
        json.dump(meta, f, indent=1)
        f.write("\n")
    print(json.dumps(meta, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
