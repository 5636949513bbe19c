"""Shared by the bench/mitsuba_*_reference.py scripts: the sensor they all use, render a
Mitsuba 3 scene in two independent halves of the samples and write the image with its noise
figures; write numbers and triples as rtis scene files spell them.

The noise RMSE is half the RMSE between the halves: the RMSE of their mean against its
expectation, which the tests compare rtis's distance from the reference with.
"""

import json
import time

import numpy as np


LIBLLVM = "/usr/lib/x86_64-linux-gnu/libLLVM-19.so"


def load_mitsuba(variant):
    """Mitsuba 3 set to `variant`; an llvm variant finds Debian's libLLVM unless
    DRJIT_LIBLLVM_PATH says otherwise."""
    import os
    if variant.startswith("llvm") and "DRJIT_LIBLLVM_PATH" not in os.environ:
        os.environ["DRJIT_LIBLLVM_PATH"] = LIBLLVM
    import mitsuba as mi

    mi.set_variant(variant)
    return mi


def sensor(mi, kind, eye, target, up, fov, width, height, spp, seed, **extra):
    """A Mitsuba sensor of `kind` (`perspective`, `thinlens` with its `extra` fields) at `eye`
    looking at `target`, with a vertical `fov` as rtis's, an hdrfilm of `width x height` with
    a box filter, and an independent sampler."""
    return {
        "type": kind,
        "fov": fov,
        "fov_axis": "y",
        **extra,
        "to_world": mi.ScalarTransform4f().look_at(origin=eye, target=target, up=up),
        "film": {"type": "hdrfilm", "width": width, "height": height,
                 "rfilter": {"type": "box"}, "pixel_format": "rgb"},
        "sampler": {"type": "independent", "sample_count": spp, "seed": seed},
    }


def rtis_head(comment, width, height, spp, eye, target, up, fov, film_extra="", extra=()):
    """The opening lines of an rtis scene written beside a Mitsuba reference: the `comment`
    lines, the film, a perspective camera, Path with Russian roulette from depth 5, the
    Physical model, any `extra` top-level lines, and `entities: [`."""
    return [
        *comment,
        "Scene(",
        f"    film: (width: {width}, height: {height}, spp: {spp}{film_extra}),",
        f"    camera: Perspective(position: {tup(eye)}, look_at: {tup(target)}, up: {tup(up)}, "
        f"fov: {num(fov)}),",
        "    shader: Path(rr_depth: 5),",
        "    model: Physical,",
        *extra,
        "    entities: [",
    ]


def render_halves(mi, make_dict, spp, width, height, load=None):
    """Mitsuba's image of `make_dict(spp // 2, seed)` (or of the scene `load(spp // 2, seed)`
    returns) for seeds 0 and 1, averaged, rendered in chunks of at most 256 spp: (image, RMSE
    between the halves, seconds)."""
    halves, t = [], time.perf_counter()
    for seed in (0, 1):
        if load is not None:
            scene = load(spp // 2, seed)
        else:
            scene = mi.load_dict(make_dict(spp // 2, seed))
        acc = np.zeros((height, width, 3))
        chunk = min(256, spp // 2)
        for k in range(spp // 2 // chunk):
            acc += np.array(mi.render(scene, spp=chunk, seed=seed * 100003 + k)) * chunk
        halves.append(acc / (spp // 2))
    seconds = time.perf_counter() - t
    img = 0.5 * (halves[0] + halves[1])
    return img, float(np.sqrt(np.mean((halves[0] - halves[1]) ** 2))), seconds


def write_reference(mi, stem, img, half_rmse, seconds, variant, spp):
    """Write `stem`.exr (linear float32 RGB) and `stem`.json (version, variant, spp, seconds,
    mean, noise) and return the metadata."""
    height, width = img.shape[:2]
    mi.Bitmap(img.astype(np.float32)).write(stem + ".exr")
    meta = {
        "mitsuba": mi.__version__, "variant": variant, "spp": spp,
        "width": width, "height": height, "seconds": round(seconds, 1),
        "mean": [round(float(c), 6) for c in img.reshape(-1, 3).mean(axis=0)],
        "half_rmse": half_rmse, "noise_rmse": half_rmse / 2,
        "orientation": "Mitsuba's own: flip left-right (img[:, ::-1]) to compare with rtis",
    }
    with open(stem + ".json", "w") as f:
        json.dump(meta, f, indent=2)
    return meta


def num(v):
    """A number as an rtis scene file writes it: whole numbers without a point."""
    v = float(v)
    return str(int(v)) if v == int(v) else repr(v)


def tup(v):
    """A triple as an rtis scene file writes it: `(x, y, z)`."""
    return "(" + ", ".join(num(x) for x in v) + ")"
