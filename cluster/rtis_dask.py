"""Render rtis passes on a Dask cluster and merge them bit-exactly.

rtis does the rendering and the merging (`rtis render --pass I/N`, `rtis merge`); Dask
distributed does the scheduling: it runs the passes on its workers, reschedules the passes of a
worker that dies, and retries a pass that fails. This driver:

- submits the N passes (each a subprocess `rtis render SCENE --pass I/N`, returning the pass
  file's bytes, so workers need the scene and rtis but no shared output folder);
- merges each pass as it arrives (`rtis merge --partial`), showing progress;
- writes the final image with `rtis merge`, bit-identical to `rtis render` of the same scene.

Workers must see the scene file (and what it extends or loads) at the same path, and an rtis
binary (`--rtis`, by default target/release/rtis of this checkout).

Sweeps and benchmarks fan out the same way, one task per scene:

- `rtis-dask converge SCENE... --out DIR` runs `rtis converge SCENE --out DIR/NAME` for each
  scene on a worker and brings back its folder (CSV, table, plot, report.html, reference);
- `rtis-dask bench SCENE...` runs `rtis bench --json --section effects` on each scene alone and
  prints the JSON lines, tagged with the worker that measured them.

Usage:
    rtis-dask render SCENE --passes N -o OUT [--workers K | --scheduler ADDRESS]
                   [--threads T] [-- RTIS RENDER ARGS...]
    rtis-dask converge SCENE... --out DIR [--workers K | --scheduler ADDRESS] [-- ARGS...]
    rtis-dask bench SCENE... [--workers K | --scheduler ADDRESS] [-- ARGS...]
"""

import argparse
import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_RTIS = os.path.join(ROOT, "target", "release", "rtis")


def run_pass(rtis, scene, i, n, threads, extra):
    """Render pass i of n on this worker; the pass file's bytes."""
    with tempfile.TemporaryDirectory() as d:
        out = os.path.join(d, f"pass-{i}-of-{n}.exr")
        cmd = [rtis, "render", scene, "--pass", f"{i}/{n}", "-o", out, "--force", *extra]
        if threads:
            cmd += ["--threads", str(threads)]
        done = subprocess.run(cmd, capture_output=True, text=True)
        if done.returncode != 0:
            raise RuntimeError(f"pass {i}/{n} failed ({done.returncode}): {done.stderr.strip()}")
        with open(out, "rb") as f:
            return f.read()


def merge(rtis, parts, out, partial):
    """`rtis merge` of `parts` into `out`."""
    cmd = [rtis, "merge", *parts, "-o", out] + (["--partial"] if partial else [])
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"merge failed: {done.stderr.strip()}")


def render(client, rtis, scene, passes, out, threads=None, extra=(), on_pass=None):
    """Render `scene` in `passes` passes on `client`'s cluster and merge them into `out`.

    Each result is merged as it arrives; a pass lost with its worker is rescheduled by Dask,
    a pass that fails is retried twice. `on_pass(i, done, total)` is called after each merge.
    Returns the wall seconds.
    """
    from distributed import as_completed

    start = time.time()
    scene = os.path.abspath(scene)
    futures = [
        client.submit(run_pass, rtis, scene, i, passes, threads, list(extra),
                      key=f"rtis-pass-{i}-of-{passes}-{os.getpid()}-{time.time_ns()}",
                      pure=False, retries=2)
        for i in range(passes)
    ]
    index = {f.key: i for i, f in enumerate(futures)}
    with tempfile.TemporaryDirectory() as work:
        merged = os.path.join(work, "merged.exr")
        done = 0
        for future in as_completed(futures):
            i = index[future.key]
            part = os.path.join(work, f"pass-{i}.exr")
            with open(part, "wb") as f:
                f.write(future.result())
            merge(rtis, ([merged] if done else []) + [part], merged, partial=True)
            os.remove(part)
            done += 1
            if on_pass:
                on_pass(i, done, passes)
        merge(rtis, [merged], out, partial=False)
    return time.time() - start


def run_converge(rtis, scene, extra):
    """`rtis converge` of one scene on this worker; its output folder as {file name: bytes}."""
    with tempfile.TemporaryDirectory() as d:
        done = subprocess.run([rtis, "converge", scene, "--out", d, *extra],
                              capture_output=True, text=True)
        if done.returncode != 0:
            raise RuntimeError(f"converge {scene} failed: {done.stderr.strip()}")
        files = {}
        for name in os.listdir(d):
            with open(os.path.join(d, name), "rb") as f:
                files[name] = f.read()
        return files


def run_bench(rtis, scene, extra):
    """`rtis bench --json --section effects` of one scene alone on this worker; its JSON lines,
    each tagged with the worker's host name."""
    import json
    import socket

    done = subprocess.run([rtis, "bench", "--json", "--section", "effects", "--scenes",
                           os.path.abspath(scene), *extra], capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"bench {scene} failed: {done.stderr.strip()}")
    host = socket.gethostname()
    rows = []
    for line in done.stdout.splitlines():
        if line.strip():
            row = json.loads(line)
            row["host"] = host
            rows.append(row)
    return rows


def fan_out(client, fn, rtis, scenes, extra, on_done=None):
    """Run `fn(rtis, scene, extra)` for every scene on the cluster; results in scene order.
    Lost workers' tasks are rescheduled by Dask, failed ones retried twice."""
    from distributed import as_completed

    futures = [client.submit(fn, rtis, os.path.abspath(s), list(extra), pure=False, retries=2)
               for s in scenes]
    index = {f.key: i for i, f in enumerate(futures)}
    results = [None] * len(scenes)
    for done, future in enumerate(as_completed(futures), 1):
        i = index[future.key]
        results[i] = future.result()
        if on_done:
            on_done(scenes[i], done, len(scenes))
    return results


def converge(client, rtis, scenes, out, extra=()):
    """Converge sweeps of `scenes` on the cluster, each written to out/NAME/."""
    def write(scene, done, total):
        print(f"converge {scene}: {done}/{total}", file=sys.stderr)

    results = fan_out(client, run_converge, rtis, scenes, extra, write)
    for scene, files in zip(scenes, results):
        folder = os.path.join(out, os.path.splitext(os.path.basename(scene))[0])
        os.makedirs(folder, exist_ok=True)
        for name, data in files.items():
            with open(os.path.join(folder, name), "wb") as f:
                f.write(data)
    return results


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    extra = []
    if "--" in argv:
        k = argv.index("--")
        argv, extra = argv[:k], argv[k + 1:]
    ap = argparse.ArgumentParser(prog="rtis-dask", description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="command", required=True)
    r = sub.add_parser("render", help="render a scene in passes on a Dask cluster")
    r.add_argument("scene")
    r.add_argument("--passes", type=int, required=True, help="number of passes (at most the spp)")
    r.add_argument("-o", "--output", required=True, help="the image (.png or .exr)")
    g = r.add_mutually_exclusive_group()
    g.add_argument("--workers", type=int, default=2, help="local worker processes (default 2)")
    g.add_argument("--scheduler", help="address of a running Dask scheduler (tcp://host:8786)")
    r.add_argument("--threads", type=int, help="rtis threads per pass (default: the worker's cores)")
    r.add_argument("--rtis", default=DEFAULT_RTIS, help="the rtis binary the workers run")
    for name, help_text in [("converge", "converge sweeps of several scenes, one per worker"),
                            ("bench", "the effects benchmark of several scenes, one per worker")]:
        c = sub.add_parser(name, help=help_text)
        c.add_argument("scenes", nargs="+")
        if name == "converge":
            c.add_argument("--out", required=True, help="folder for one sub-folder per scene")
        g = c.add_mutually_exclusive_group()
        g.add_argument("--workers", type=int, default=2, help="local worker processes (default 2)")
        g.add_argument("--scheduler", help="address of a running Dask scheduler")
        c.add_argument("--rtis", default=DEFAULT_RTIS, help="the rtis binary the workers run")
    a = ap.parse_args(argv)

    from distributed import Client, LocalCluster

    if a.scheduler:
        client = Client(a.scheduler)
    else:
        client = Client(LocalCluster(n_workers=a.workers, threads_per_worker=1, processes=True))

    def progress(i, done, total):
        print(f"pass {i} merged: {done}/{total}", file=sys.stderr)

    try:
        if a.command == "render":
            seconds = render(client, a.rtis, a.scene, a.passes, a.output, a.threads, extra,
                             progress)
            print(f"{a.passes} passes merged in {seconds:.2f} s -> {a.output}", file=sys.stderr)
        elif a.command == "converge":
            converge(client, a.rtis, a.scenes, a.out, extra)
            print(f"{len(a.scenes)} sweeps -> {a.out}/", file=sys.stderr)
        else:
            import json
            for rows in fan_out(client, run_bench, a.rtis, a.scenes, extra):
                for row in rows:
                    print(json.dumps(row))
    except RuntimeError as e:
        print(f"error: {e}", file=sys.stderr)
        return 1
    finally:
        client.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
