#!/usr/bin/env python3
"""Wall time against worker count: the course's box at 720x576, Global n = 64 D = 2, 16 spp,
rendered in 16 passes on a LocalCluster of 1, 2, ... workers (one rtis thread each), plus the
time of one pass alone and of merging. Prints a Markdown table (cluster/README.md's figure).

    .venv/bin/python cluster/scaling.py [--max-workers 2] [--spp 16]
"""

import argparse
import os
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import rtis_dask  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--max-workers", type=int, default=os.cpu_count())
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--passes", type=int, default=16)
    a = ap.parse_args()
    from distributed import Client, LocalCluster

    rtis, scene = rtis_dask.DEFAULT_RTIS, os.path.join(rtis_dask.ROOT, "scenes", "cornell.ron")
    extra = ["--spp", str(a.spp)]
    with tempfile.TemporaryDirectory() as d:
        t = time.time()
        subprocess.run([rtis, "render", scene, "-o", f"{d}/single.exr", "--threads", "1", *extra],
                       check=True, capture_output=True)
        single = time.time() - t
        t = time.time()
        subprocess.run([rtis, "render", scene, "--pass", f"0/{a.passes}", "-o", f"{d}/p.exr",
                        "--threads", "1", *extra], check=True, capture_output=True)
        one_pass = time.time() - t
        t = time.time()
        subprocess.run([rtis, "merge", f"{d}/p.exr", "-o", f"{d}/m.exr", "--partial"],
                       check=True, capture_output=True)
        merge = time.time() - t
        rows = []
        for workers in range(1, a.max_workers + 1):
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                   dashboard_address=None)
            client = Client(cluster)
            wall = rtis_dask.render(client, rtis, scene, a.passes, f"{d}/out.exr", threads=1,
                                    extra=extra)
            client.close()
            cluster.close()
            rows.append((workers, wall))
    print(f"720x576, Global n = 64 D = 2, {a.spp} spp in {a.passes} passes, one rtis thread per "
          f"worker, on {os.cpu_count()} cores. One thread without Dask: {single:.1f} s; one pass "
          f"alone: {one_pass:.2f} s; one partial merge: {merge:.2f} s.\n")
    print("| workers | wall s | speed-up |\n|---|---|---|")
    for w, wall in rows:
        print(f"| {w} | {wall:.1f} | {rows[0][1] / wall:.2f}x |")


if __name__ == "__main__":
    main()
