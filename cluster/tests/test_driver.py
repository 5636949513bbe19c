"""The Dask driver on a LocalCluster of worker processes: the merged image is bit-identical to
a single `rtis render`, also when a worker is killed in the middle of the run."""

import os
import signal
import subprocess
import sys

import pytest

sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
import rtis_dask  # noqa: E402

RTIS = rtis_dask.DEFAULT_RTIS
SCENE = os.path.join(rtis_dask.ROOT, "scenes", "cornell.ron")
# Small but not trivial: the course's box, Global n = 64, D = 2, at 60x48 with 14 spp.
ARGS = ["--width", "60", "--height", "48", "--spp", "14"]


@pytest.fixture(scope="module")
def single(tmp_path_factory):
    out = str(tmp_path_factory.mktemp("single") / "single.exr")
    subprocess.run([RTIS, "render", SCENE, "-o", out, *ARGS], check=True, capture_output=True)
    return out


@pytest.fixture(scope="module")
def client():
    from distributed import Client, LocalCluster

    cluster = LocalCluster(n_workers=3, threads_per_worker=1, processes=True,
                           dashboard_address=None)
    c = Client(cluster)
    yield c
    c.close()
    cluster.close()


def identical(a, b):
    """True when `rtis diff` finds no differing pixel (bitwise equal f32 values)."""
    out = subprocess.run([RTIS, "diff", a, b], check=True, capture_output=True, text=True).stdout
    return "pixels that differ  0 of" in out and "max error   0.000000" in out


@pytest.mark.parametrize("passes", [1, 2, 3, 7])
def test_passes_merge_bit_identically(client, single, tmp_path, passes):
    out = str(tmp_path / "merged.exr")
    rtis_dask.render(client, RTIS, SCENE, passes, out, threads=1, extra=ARGS)
    assert identical(out, single)
    with open(out, "rb") as f, open(single, "rb") as g:
        assert f.read() == g.read(), "the merged EXR has the single render's bytes"


def test_a_killed_worker_changes_nothing(client, tmp_path):
    """Kill a worker that is rendering a pass, after the first pass arrives: Dask reschedules
    the lost pass on the others, and the image is still the single render's."""
    args = ["--width", "120", "--height", "96", "--spp", "28"]
    single = str(tmp_path / "single.exr")
    subprocess.run([RTIS, "render", SCENE, "-o", single, *args], check=True, capture_output=True)
    killed = []
    merged = []

    def on_pass(i, done, total):
        merged.append(i)
        if killed:
            return
        busy = [addr for addr, tasks in client.processing().items() if tasks]
        assert busy, "every pass finished before a worker could be killed: make passes longer"
        pid = client.run(os.getpid, workers=[busy[0]])[busy[0]]
        os.kill(pid, signal.SIGKILL)
        killed.append(pid)

    out = str(tmp_path / "merged.exr")
    rtis_dask.render(client, RTIS, SCENE, 7, out, threads=1, extra=args, on_pass=on_pass)
    assert killed
    assert sorted(merged) == list(range(7))
    assert identical(out, single)
    # The cluster's nanny restarts the worker.
    client.wait_for_workers(3, timeout=60)


def csv_errors(path):
    """(family, setting) -> (rmse, rel_mse, flip, variance, bias2) of a converge.csv."""
    rows = {}
    with open(path) as f:
        next(f)
        for line in f:
            c = line.strip().split(",")
            rows[(c[0], c[1])] = tuple(c[4:7] + c[8:10])
    return rows


def test_converge_sweeps_fan_out_with_the_same_errors(client, tmp_path):
    """Two scenes' converge sweeps on the cluster, one per worker: every error figure equals a
    sweep run here (the renders are deterministic; only the seconds differ)."""
    scenes = [os.path.join(rtis_dask.ROOT, "scenes", s) for s in ["cornell-direct.ron", "spheres.ron"]]
    args = ["--width", "24", "--runs", "1", "--seeds", "2", "--reference-spp", "8"]
    rtis_dask.converge(client, RTIS, scenes, str(tmp_path / "cluster"), args)
    for scene in scenes:
        name = os.path.splitext(os.path.basename(scene))[0]
        local = tmp_path / "local" / name
        subprocess.run([RTIS, "converge", scene, "--out", str(local), *args], check=True,
                       capture_output=True)
        remote = tmp_path / "cluster" / name
        assert (remote / "report.html").exists()
        assert csv_errors(remote / "converge.csv") == csv_errors(local / "converge.csv")


def test_benchmarks_fan_out(client):
    scenes = [os.path.join(rtis_dask.ROOT, "scenes", s) for s in ["cornell-direct.ron", "spheres.ron"]]
    results = rtis_dask.fan_out(client, rtis_dask.run_bench, RTIS, scenes, ["--runs", "1", "--shrink", "8"])
    for scene, rows in zip(scenes, results):
        effects = [r for r in rows if r["section"] == "effects"]
        assert {r["scene"] for r in effects} == {os.path.basename(scene)}
        assert any(r["effect_off"] == "shadows" for r in effects)
        assert all("host" in r for r in rows)
