#!/usr/bin/env python3
"""rtis's BVH against Embree on the same procedural mesh and the same rays (issue 13).

Not run in CI, and no timed tests. For each size N in --triangles, runs
`rtis bench --section meshes --triangles N,... --dump DIR --json`, which builds rtis's BVH over
a displaced sphere, traces 1,000,000 camera (coherent) and 1,000,000 incoherent rays, prints its
figures, and writes the mesh and both ray sets to DIR as raw little-endian arrays
(`mesh-N.vertices.f32`, `mesh-N.faces.u32`, `mesh-N.coherent.f32`, `mesh-N.incoherent.f32`).
This script then loads those arrays, builds an Embree scene over the same triangles, traces the
same rays, checks that both engines hit with the same rays, and prints one JSON line per engine
and size, then one line of ratios:

    {"engine": "rtis" | "embree", "triangles", "threads", "build_s", "bytes_per_triangle",
     "incoherent_mrays", "coherent_mrays", "incoherent_hit_mrays", "incoherent_miss_mrays",
     ... extras: hit counts, versions}
    {"ratio": "rtis_vs_embree", "triangles", "threads",
     "embree_over_rtis_build_s",               > 1: rtis builds faster
     "rtis_over_embree_incoherent_mrays",      > 1: rtis traces incoherent rays faster
     "rtis_over_embree_incoherent_hit_mrays",  the same for the incoherent rays that hit
     "rtis_over_embree_incoherent_miss_mrays", and for those that miss
     "rtis_over_embree_coherent_mrays",        > 1: rtis traces camera rays faster
     "rtis_over_embree_bytes_per_triangle"}    > 1: rtis uses more memory per triangle
    each ratio the median of the rounds' ratios, with "<name>_range" (their least and greatest)
    and, from six rounds on, "<name>_ci95": the median's 95% confidence interval (median_ci)

The temporary folder is removed at the end.

How the runs are paired: the machine's speed drifts by tens of percent over minutes, so the
engines take turns. For each size, --runs (default 5) rounds each run rtis once (a fresh
`rtis bench` process) and Embree once (a fresh worker process), in alternating order (rtis
first in even rounds); in a round each engine builds three times and traces each ray set three
times (ROUND_RUNS), after a throw-away warm-up build, and reports the medians. Each engine's
line gives the median of its rounds' figures; the ratio line gives the median of the rounds'
ratios, each taken between two measurements seconds apart.

How each engine is measured:

- build_s. rtis: its BVH build (rayon, --threads threads), from triangles already set up.
  Embree: the scene commit, i.e. its BVH build, which runs on TBB's worker pool over all the
  machine's hardware threads whatever --threads says (embreex creates its device with no
  config, so the thread count cannot be set; `build_threads` in the line says how many). The
  binding copies the arrays into Embree's buffers element by element (numpy's generic indexing)
  before that; this copy is not Embree's work and is reported apart as `mesh_copy_s`. embreex commits lazily on the
  first query, so the commit is forced (and timed) with one ray before the timed queries.
- bytes_per_triangle. rtis: its wide BVH's nodes, its leaf blocks (which hold the only copy of
  the triangles' vertices) and the 8 bytes of material and light per block lane, counted from
  the sizes of its structures. Embree: the growth of the process's resident memory
  (/proc/self/statm) across the mesh copy and the build, divided by the triangle count. It
  counts Embree's BVH (its leaves hold their own copy of the vertices) plus its copy of the
  mesh (16-byte vertices, 12-byte index triples: about 20 bytes per triangle, reported apart as
  `mesh_bytes_per_triangle`), which rtis does not keep. To make the growth the scene's alone, a
  throw-away scene is built first (so TBB's workers and Embree's per-thread state exist), each
  mesh is measured in a fresh child process (so no earlier scene's pages are reused), and
  glibc's malloc_trim hands freed pages back before the first reading and after the build (so
  neither reused nor freed-but-kept build temporaries are miscounted); of three builds kept
  alive side by side, the largest growth is a round's reading (reused pages can only hide
  growth; the three agree to a few percent except for such low outliers at 10k triangles),
  and the median of the rounds' readings is reported (rounds can also read high: one run of
  15 rounds read 119 and 117 B/triangle at 10k and 100k against 88-90 in others, cause not
  found). Linux only.
- Mrays/s: the rays of the file over the wall time of the query only. embreex's `run` loops
  rtcIntersect1 over its rays on one thread but releases the GIL, so the rays are split into
  chunks traced by --threads Python threads at once; rtis is run with RAYON_NUM_THREADS set to
  the same count. Rays are unbounded (rtis: t_max = inf; embreex: tfar = 1e37) and closest
  hit; Embree's scene is built with embreex's default RTC_SCENE_FLAG_ROBUST (rtis's triangle
  test is watertight too).
- incoherent_hit_mrays, incoherent_miss_mrays: the incoherent rays that hit, and those that
  miss, each set traced apart as above (each engine splits the rays by its own hits). A hit
  costs leaf tests and a hit record, a miss mostly the top of the tree: the two rates show
  where a gap between the engines lies.
- hits: rays with a hit. They should agree with rtis's to a tiny fraction (edge and vertex
  hits may fall either way); a larger difference is reported on stderr.

Setup: none by hand. The script uses the repository's venv `.venv` (gitignored): if `embreex`
cannot be imported, it creates `.venv` if absent (python3 -m venv), installs `numpy` and
`embreex` into it with its pip, and runs itself again under `.venv/bin/python`. embreex
4.4.0.post1 from PyPI bundles Embree 4.4.0 and its own TBB (manylinux wheel, x86_64). rtis's
release binary must exist: `cargo build --release`.

Usage:
    python3 bench/embree_compare.py [--triangles 10000,100000,1000000] [--threads T[,U...]]
                                    [--runs 5] [--rtis target/release/rtis]
"""

import argparse
import ctypes
import json
import math
import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
VENV = os.path.join(ROOT, ".venv")
VENV_PYTHON = os.path.join(VENV, "bin", "python")
# Set when the script re-executes itself under the venv, so a failed install cannot loop.
REEXEC_FLAG = "RTIS_EMBREE_COMPARE_REEXEC"
# Rays per query call: small enough to balance the threads, large enough that the call's
# Python overhead (tens of microseconds) is lost in its 16k rtcIntersect1 calls.
CHUNK = 16384
# Hit counts may differ by this fraction of the rays before a warning.
HIT_TOLERANCE = 1e-4
# Embree scenes built per mesh for the memory reading (the largest is kept).
MEMORY_BUILDS = 3
# Builds and passes of each ray set per engine in one round; the round's figures are their
# medians. Three on both sides: Embree's worker builds MEMORY_BUILDS scenes anyway, and a
# process's first build is the slowest on both sides.
ROUND_RUNS = 3


def fail(message):
    print(f"embree_compare: error: {message}", file=sys.stderr)
    sys.exit(1)


def ensure_deps():
    """Import numpy and embreex, installing them into .venv (and re-running under it) if needed."""
    try:
        import embreex  # noqa: F401
        import numpy  # noqa: F401

        return
    except ImportError:
        pass
    in_venv = os.path.realpath(sys.prefix) == os.path.realpath(VENV)
    if not in_venv:
        if os.environ.get(REEXEC_FLAG):
            fail(f"re-executed under {VENV_PYTHON} but still not running in {VENV}")
        if not os.path.exists(VENV_PYTHON):
            print(f"embree_compare: creating {VENV}", file=sys.stderr)
            subprocess.run([sys.executable, "-m", "venv", VENV], check=True)
        os.environ[REEXEC_FLAG] = "1"
        os.execv(VENV_PYTHON, [VENV_PYTHON, os.path.abspath(__file__), *sys.argv[1:]])
    print(f"embree_compare: installing numpy and embreex into {VENV}", file=sys.stderr)
    r = subprocess.run([sys.executable, "-m", "pip", "install", "--quiet", "numpy", "embreex"])
    if r.returncode != 0:
        fail("pip install embreex failed (a wheel exists for x86_64 Linux, macOS and Windows)")
    try:
        import embreex  # noqa: F401
        import numpy  # noqa: F401
    except ImportError as e:
        fail(f"embreex installed but cannot be imported: {e}")


def positive_ints(text):
    try:
        values = [int(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected comma-separated integers, got {text!r}")
    if not values or any(v < 1 for v in values):
        raise argparse.ArgumentTypeError(f"expected positive integers, got {text!r}")
    return values


def available_threads():
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


def resident_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def run_rtis(rtis, sizes, threads, dump, runs):
    """rtis's JSON rows for `sizes`, in order, traced on `threads` threads, each figure the
    median of `runs` builds and passes; dumps into `dump`."""
    cmd = [rtis, "bench", "--section", "meshes", "--json", "--runs", str(runs),
           "--triangles", ",".join(map(str, sizes))]
    if dump:
        cmd += ["--dump", dump]
    env = dict(os.environ, RAYON_NUM_THREADS=str(threads))
    r = subprocess.run(cmd, env=env, capture_output=True, text=True)
    if r.returncode != 0:
        fail(f"{' '.join(cmd)} exited with {r.returncode}:\n{r.stderr.strip()}")
    rows = []
    for line in r.stdout.splitlines():
        try:
            row = json.loads(line)
        except json.JSONDecodeError:
            fail(f"rtis printed a line that is not JSON: {line!r}")
        if row.get("section") == "meshes":
            rows.append(row)
    if len(rows) != len(sizes):
        fail(f"rtis printed {len(rows)} mesh rows for {len(sizes)} sizes:\n{r.stdout}")
    for row in rows:
        if row.get("threads") != threads:
            fail(f"rtis ran on {row.get('threads')} threads, not the {threads} asked for")
    return rows


def load(dump, n):
    import numpy as np

    def raw(suffix, dtype, width):
        path = os.path.join(dump, f"mesh-{n}.{suffix}")
        if not os.path.exists(path):
            fail(f"rtis did not write {path} (is target/release/rtis older than --dump?)")
        a = np.fromfile(path, dtype=dtype)
        if a.size % width:
            fail(f"{path}: {a.size} values, not a multiple of {width}")
        return a.reshape(-1, width)

    vertices = raw("vertices.f32", "<f4", 3).astype(np.float32)
    faces = raw("faces.u32", "<u4", 3)
    if faces.size and faces.max() >= len(vertices):
        fail(f"mesh-{n}: a face index {faces.max()} is past the {len(vertices)} vertices")
    rays = {}
    for kind in ("coherent", "incoherent"):
        r = raw(f"{kind}.f32", "<f4", 6)
        # Contiguous origin and direction arrays, as embreex's run wants; slices of rows stay so.
        rays[kind] = (np.ascontiguousarray(r[:, :3]), np.ascontiguousarray(r[:, 3:]))
    return vertices, faces.astype(np.int32), rays


def main():
    p = argparse.ArgumentParser(
        description="Compare rtis's BVH with Embree (embreex) on the same mesh and rays; "
        "prints JSON lines. See the module docstring for what each figure measures.")
    p.add_argument("--triangles", type=positive_ints, default=[10_000, 100_000, 1_000_000],
                   metavar="N[,M...]",
                   help="mesh sizes in triangles (default 10000,100000,1000000)")
    p.add_argument("--threads", type=positive_ints, default=None, metavar="T[,U...]",
                   help="ray-tracing threads for both engines, one run per count "
                   f"(default: all available, here {available_threads()})")
    p.add_argument("--runs", type=int, default=5,
                   help="rounds per mesh, the engines taking turns (each builds and traces "
                   f"{ROUND_RUNS} times per round); each figure is the median over the rounds "
                   "(default 5: on a shared machine single timings vary by tens of percent)")
    p.add_argument("--rtis", default=os.path.join(ROOT, "target", "release", "rtis"),
                   help="rtis binary (default target/release/rtis)")
    # Internal: measure Embree on one dumped mesh in this (fresh) process; see embree_worker.
    p.add_argument("--embree-worker", nargs=4, metavar=("DIR", "N", "THREADS", "RUNS"),
                   help=argparse.SUPPRESS)
    a = p.parse_args()
    if a.embree_worker:
        ensure_deps()
        dump, n, threads, runs = a.embree_worker
        print(json.dumps(embree_worker(dump, int(n), int(threads), int(runs))))
        return
    if a.runs < 1:
        fail(f"--runs must be at least 1, not {a.runs}")
    if not (os.path.isfile(a.rtis) and os.access(a.rtis, os.X_OK)):
        fail(f"no rtis binary at {a.rtis}: run `cargo build --release` first, or pass --rtis")
    ensure_deps()
    threads_list = a.threads or [available_threads()]
    sizes = list(dict.fromkeys(a.triangles))
    with tempfile.TemporaryDirectory(prefix="rtis-embree-") as dump:
        for t_index, threads in enumerate(threads_list):
            for n in sizes:
                rounds = []
                for k in range(a.runs):
                    # The first round of the first thread count writes the mesh and rays; rtis
                    # goes first in it (k = 0 is even), before the Embree worker reads them.
                    write = dump if t_index == 0 and k == 0 else None
                    ours = lambda: run_rtis(a.rtis, [n], threads, write, ROUND_RUNS)[0]  # noqa: E731
                    theirs = lambda: run_worker(dump, n, threads, ROUND_RUNS)  # noqa: E731
                    if k % 2 == 0:
                        r = ours()
                        e = theirs()
                    else:
                        e = theirs()
                        r = ours()
                    rounds.append((r, e))
                compare(n, rounds)


def run_worker(dump, n, threads, runs):
    """Embree's row for mesh-N, measured in a child process so its memory baseline is clean
    (no pages left by an earlier scene for this one to reuse)."""
    cmd = [sys.executable, os.path.abspath(__file__), "--embree-worker", dump, str(n),
           str(threads), str(runs)]
    r = subprocess.run(cmd, stdout=subprocess.PIPE, text=True)
    if r.returncode != 0:
        fail(f"the Embree measurement of mesh-{n} failed (exit status {r.returncode})")
    try:
        return json.loads(r.stdout.strip().splitlines()[-1])
    except (json.JSONDecodeError, IndexError):
        fail(f"the Embree measurement of mesh-{n} printed no JSON: {r.stdout!r}")


def median_row(rows):
    """The first row with each numeric figure replaced by its median over `rows` (Embree's byte
    counts included: each round's is already the largest of its builds, see measure_embree;
    rtis's are the same in every round)."""
    out = dict(rows[0])
    for k, v in out.items():
        if isinstance(v, (int, float)) and not isinstance(v, bool):
            out[k] = median([row[k] for row in rows])
    return out


def compare(n, rounds):
    """Print rtis's row, Embree's row (medians over the rounds) and the medians of the rounds'
    ratios for mesh-N; warn if the hits differ."""
    r = median_row([r for r, _ in rounds])
    e = median_row([e for _, e in rounds])
    e["rounds"] = len(rounds)
    if e["triangles"] != r["triangles"]:
        print(f"embree_compare: warning: mesh-{n} has {e['triangles']} faces, "
              f"rtis kept {r['triangles']} triangles", file=sys.stderr)
    ours = {"engine": "rtis"}
    for k in ("isa", "triangles", "threads", "build_s", "bytes_per_triangle", "incoherent_mrays",
              "coherent_mrays", "incoherent_hit_mrays", "incoherent_miss_mrays", "coherent_hits",
              "incoherent_hits"):
        ours[k] = r.get(k)  # an older binary (--rtis) prints no isa and no hit and miss rates
    ours["build_threads"] = r["threads"]  # rtis builds its BVH with rayon too
    for kind in ("coherent", "incoherent"):
        rays = e[f"{kind}_rays"]
        if abs(ours[f"{kind}_hits"] - e[f"{kind}_hits"]) > HIT_TOLERANCE * rays:
            print(f"embree_compare: warning: {kind} hits differ at N={n}: "
                  f"rtis {ours[f'{kind}_hits']}, embree {e[f'{kind}_hits']} of {rays} rays",
                  file=sys.stderr)
    print(json.dumps(ours), flush=True)
    print(json.dumps(e), flush=True)

    embree_bytes = e["bytes_per_triangle"]
    ratios = {
        "embree_over_rtis_build_s": lambda r, e: e["build_s"] / r["build_s"],
        "rtis_over_embree_incoherent_mrays":
            lambda r, e: r["incoherent_mrays"] / e["incoherent_mrays"],
        "rtis_over_embree_incoherent_hit_mrays":
            lambda r, e: r["incoherent_hit_mrays"] / e["incoherent_hit_mrays"],
        "rtis_over_embree_incoherent_miss_mrays":
            lambda r, e: r["incoherent_miss_mrays"] / e["incoherent_miss_mrays"],
        "rtis_over_embree_coherent_mrays": lambda r, e: r["coherent_mrays"] / e["coherent_mrays"],
        # Against the median of Embree's readings (median_row), as its line reports.
        "rtis_over_embree_bytes_per_triangle":
            lambda r, _: r["bytes_per_triangle"] / embree_bytes,
    }
    line = {
        "ratio": "rtis_vs_embree",
        "triangles": ours["triangles"],
        "threads": ours["threads"],
        "rounds": len(rounds),
    }
    for name, f in ratios.items():
        try:
            each = [f(r, e) for r, e in rounds]
        except KeyError:
            continue  # a figure an older rtis binary (--rtis) does not print
        line[name] = median(each)
        # The spread of the rounds' ratios: how far one round can be trusted.
        line[name + "_range"] = [min(each), max(each)]
        # How far the median can be trusted: its 95% confidence interval (none for fewer than
        # six rounds), if the rounds are independent draws (the engines take turns within
        # each, so the machine's drift falls on both). For a speed ratio, "rtis no slower than
        # Embree" holds at that confidence when the interval lies at or above 1.
        ci = median_ci(each)
        if ci is not None:
            line[name + "_ci95"] = ci
    print(json.dumps(line), flush=True)


def embree_worker(dump, n, threads, runs):
    """Embree's row for mesh-N of `dump`, on `threads` query threads, in this process, each
    figure the median of `runs`."""
    import embreex
    import numpy as np
    from concurrent.futures import ThreadPoolExecutor
    from embreex import rtcore as rtc
    from embreex import rtcore_scene as rtcs
    from embreex.mesh_construction import TriangleMesh

    device = rtc.EmbreeDevice()
    # Warm-up: a throw-away scene big enough for Embree to build it in parallel, so TBB's
    # workers (and their stacks) and Embree's per-thread state exist before the measured build.
    warm = rtcs.EmbreeScene(device)
    TriangleMesh(warm, np.random.default_rng(1).random((30_000, 3, 3), dtype=np.float32))
    warm.run(np.zeros((1, 3), np.float32), np.ones((1, 3), np.float32))
    del warm
    vertices, faces, rays = load(dump, n)
    with ThreadPoolExecutor(max_workers=threads) as pool:
        pool.submit(int).result()  # start a worker before any timing
        row = measure_embree(device, vertices, faces, rays, threads, pool, runs)
    row.update({
        "embree_version": repr(device).split(":")[-1].strip(),  # "Embree version:  4.4.0"
        "embreex_version": embreex.__version__,
        "robust": True,
        "coherent_rays": len(rays["coherent"][0]),
        "incoherent_rays": len(rays["incoherent"][0]),
    })
    return row


def median(values):
    """The middle value (the upper one of the two middle values for an even count, as rtis
    bench takes it)."""
    return sorted(values)[len(values) // 2]


def median_ci(values, level=0.95):
    """A confidence interval for the median of the distribution `values` were drawn from, with
    no assumption on its shape: the k-th smallest and the k-th largest value, for the largest k
    such that a Binomial(n, 1/2) count falls below k with probability at most (1 - level) / 2
    (each value lies below the true median with probability 1/2, so the interval misses it
    with probability at most 1 - level). None if there are too few values for `level` (fewer
    than 6 at 95%). For 15 values at 95% this is the 4th and the 12th (coverage 96.5%), for 25
    the 8th and the 18th (95.7%)."""
    n, xs = len(values), sorted(values)
    k, below = 0, 0.0
    for j in range(n + 1):
        below += math.comb(n, j) / 2 ** n  # P(count <= j)
        if below > (1 - level) / 2:
            break
        k = j + 1
    return [xs[k - 1], xs[n - k]] if k > 0 else None


def measure_embree(device, vertices, faces, rays, threads, pool, runs):
    """Embree's figures for one mesh: build, memory, both ray sets on `threads` threads;
    times are medians of `runs` builds and passes."""
    import numpy as np
    from embreex import rtcore_scene as rtcs
    from embreex.mesh_construction import TriangleMesh

    # Resident memory before, with the arrays loaded, TBB's workers started (by the warm-up in
    # embree_worker) and the allocator's free pages handed back, so the growth is the scene's:
    # Embree's copy of the mesh and its BVH. Trimming again after the build drops the build's
    # freed temporaries that the allocator would otherwise keep resident. The scene is built
    # MEMORY_BUILDS times, all kept alive (so none reuses another's freed pages), and the largest
    # growth is kept: a build can land partly in pages already resident (a single reading at 10k
    # triangles, under 1 MB, is now and then a third to a half low), never the other way, and
    # the readings agree to a few percent otherwise. build_s is the median of max(runs, 3)
    # builds' times, as rtis's is the median of its `runs` builds.
    scenes, builds, grown, mesh_bytes = [], [], [], []
    for _ in range(max(MEMORY_BUILDS, runs)):
        trim_heap()
        before = resident_bytes()
        start = time.perf_counter()
        scene = rtcs.EmbreeScene(device)  # robust=True, embreex's default
        TriangleMesh(scene, vertices, faces)
        copied = time.perf_counter()
        mesh_bytes.append(resident_bytes() - before)
        # embreex commits the scene (builds its BVH) on the first query: force it with one ray.
        scene.run(np.zeros((1, 3), np.float32), np.ones((1, 3), np.float32))
        builds.append((copied - start, time.perf_counter() - copied))
        trim_heap()
        grown.append(resident_bytes() - before)
        scenes.append(scene)
    scene = scenes[0]

    def trace(o, d):
        """The median rate of `runs` passes over the rays `o`, `d` (Mrays/s), and which hit."""
        chunks = [(o[i:i + CHUNK], d[i:i + CHUNK]) for i in range(0, len(o), CHUNK)]
        rates = []
        for _ in range(runs):
            t0 = time.perf_counter()
            # run() releases the GIL around its rtcIntersect1 loop, so the chunks run in
            # parallel.
            ids = list(pool.map(lambda c: scene.run(c[0], c[1], query="INTERSECT"), chunks))
            rates.append(len(o) / (time.perf_counter() - t0) / 1e6)
        return median(rates), np.concatenate(ids) != -1

    mrays, hits = {}, {}
    for kind in ("incoherent", "coherent"):
        mrays[kind], hit = trace(*rays[kind])
        hits[kind] = int(np.count_nonzero(hit))
        if kind == "incoherent":
            o, d = rays[kind]
            for part, rows in (("hit", hit), ("miss", ~hit)):
                sub = (np.ascontiguousarray(o[rows]), np.ascontiguousarray(d[rows]))
                mrays[f"incoherent_{part}"] = trace(*sub)[0]
    del scene, scenes
    return {
        "engine": "embree",
        "triangles": len(faces),
        "threads": threads,
        "build_s": median([b[1] for b in builds]),
        "bytes_per_triangle": max(grown) / len(faces),
        "incoherent_mrays": mrays["incoherent"],
        "coherent_mrays": mrays["coherent"],
        "incoherent_hit_mrays": mrays["incoherent_hit"],
        "incoherent_miss_mrays": mrays["incoherent_miss"],
        "coherent_hits": hits["coherent"],
        "incoherent_hits": hits["incoherent"],
        # TBB's default pool: every hardware thread of the process's affinity mask.
        "build_threads": available_threads(),
        "mesh_copy_s": median([b[0] for b in builds]),
        "mesh_bytes_per_triangle": max(mesh_bytes) / len(faces),
        "bytes_per_triangle_builds": [round(g / len(faces), 1) for g in grown],
    }


def trim_heap():
    """Return the C heap's free pages to the system (glibc's malloc_trim), if there is one."""
    try:
        ctypes.CDLL(None).malloc_trim(0)
    except (OSError, AttributeError):
        pass


if __name__ == "__main__":
    main()
