#!/usr/bin/env python3
"""This commit's render time against another commit's, measured side by side (issue 13).

Not run in CI, and no timed tests. Builds the working tree's release binary (`cargo build
--release`) and the binary of --base (default HEAD~1) in a git worktree under
target/commit-compare/ (kept, so a second run reuses it), then renders --scene with both in
--rounds rounds and prints one JSON line per round and a summary:

    {"round", "base_s", "head_s", "ratio"}            ratio = base_s / head_s: > 1, this is faster
    {"compare": "head_vs_base", "base", "head", "scene", "width", "rounds",
     "ratio", "ratio_range", "base_s", "head_s", "same_pixels", "differ"}

How the runs are paired: the machine's speed drifts by tens of percent over minutes, so the
two binaries run at the same time, one thread each (`--threads 1`), each on its own core of
the machine; which one starts first alternates between rounds. Each round's ratio is taken
between two runs that saw the same conditions; the summary gives their median and range.
Times are the renders' own (`rtis render --stats`: from the first pixel to the last, without
loading and writing). `same_pixels` says whether the two EXR images of the first round are
identical (their linear pixel values, compared exactly by `rtis diff`: no pixel differs);
`differ` gives `rtis diff`'s count of pixels that differ, RMSE and largest error (printed to
six decimals: 0 means below 5e-7).

    python3 bench/commit_compare.py --base e3269bf --scene scenes/cornell-n-bounce.ron --width 360
"""

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile
import threading

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
WORK = os.path.join(ROOT, "target", "commit-compare")


def git(*args):
    return subprocess.run(["git", *args], cwd=ROOT, check=True, capture_output=True, text=True).stdout.strip()


def build_head():
    subprocess.run(["cargo", "build", "--release", "--quiet"], cwd=ROOT, check=True)
    return os.path.join(ROOT, "target", "release", "rtis")


def build_base(rev):
    """The release binary of `rev`, built in a worktree of its own."""
    commit = git("rev-parse", "--short", rev)
    tree = os.path.join(WORK, commit)
    if not os.path.isdir(tree):
        os.makedirs(WORK, exist_ok=True)
        git("worktree", "add", "--detach", tree, commit)
    target = os.path.join(WORK, "target")
    env = dict(os.environ, CARGO_TARGET_DIR=target)
    subprocess.run(["cargo", "build", "--release", "--quiet"], cwd=tree, check=True, env=env)
    return commit, os.path.join(target, "release", "rtis")


def render(binary, scene, film, out, stats, result, key):
    subprocess.run(
        [binary, "render", scene, *film, "--threads", "1", "-o", out, "--stats", stats],
        cwd=ROOT, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )
    with open(stats) as f:
        result[key] = json.load(f)["seconds"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--base", default="HEAD~1", help="the commit to compare with (default HEAD~1)")
    ap.add_argument("--scene", default="scenes/cornell-n-bounce.ron")
    ap.add_argument("--width", type=int, default=360, help="film width (the height keeps the aspect)")
    ap.add_argument("--height", type=int, help="film height, for commits whose --width alone keeps the scene's height")
    ap.add_argument("--rounds", type=int, default=5)
    args = ap.parse_args()
    if args.rounds < 1 or args.width < 1 or (args.height is not None and args.height < 1):
        sys.exit("--rounds, --width and --height must be at least 1")
    film = ["--width", str(args.width)] + (["--height", str(args.height)] if args.height else [])
    head = build_head()
    base_commit, base = build_base(args.base)
    head_commit = git("rev-parse", "--short", "HEAD") + ("+" if git("status", "--porcelain", "--untracked-files=no") else "")
    ratios, base_s, head_s, same = [], [], [], None
    with tempfile.TemporaryDirectory() as d:
        for r in range(args.rounds):
            result = {}
            runs = [
                (base, os.path.join(d, "base.exr"), os.path.join(d, "base.json"), "base"),
                (head, os.path.join(d, "head.exr"), os.path.join(d, "head.json"), "head"),
            ]
            if r % 2:
                runs.reverse()
            threads = [threading.Thread(target=render, args=(b, args.scene, film, o, s, result, k)) for b, o, s, k in runs]
            for t in threads:
                t.start()
            for t in threads:
                t.join()
            if set(result) != {"base", "head"}:
                sys.exit("a render failed")
            ratio = result["base"] / result["head"]
            ratios.append(ratio)
            base_s.append(result["base"])
            head_s.append(result["head"])
            print(json.dumps({"round": r, "base_s": result["base"], "head_s": result["head"], "ratio": ratio}), flush=True)
            if same is None:
                diff = subprocess.run([head, "diff", os.path.join(d, "head.exr"), os.path.join(d, "base.exr")],
                                      cwd=ROOT, capture_output=True, text=True)
                if diff.returncode != 0:
                    sys.exit("rtis diff failed: " + diff.stderr)
                # `rtis diff`'s lines "RMSE x", "max error x" (six decimals) and "pixels that
                # differ n of m".
                def field(pattern):
                    m = re.search(pattern, diff.stdout, re.M)
                    if m is None:
                        sys.exit(f"no {pattern!r} in rtis diff's output:\n{diff.stdout}")
                    return m.group(1)
                differ = {"pixels": int(field(r"^\s*pixels that differ\s+(\d+) of")),
                          "rmse": float(field(r"^\s*RMSE\s+(\S+)")),
                          "max_error": float(field(r"^\s*max error\s+(\S+)"))}
                same = differ["pixels"] == 0
    print(json.dumps({
        "compare": "head_vs_base", "base": base_commit, "head": head_commit, "scene": args.scene,
        "width": args.width, "height": args.height, "rounds": args.rounds, "ratio": statistics.median(ratios),
        "ratio_range": [min(ratios), max(ratios)], "base_s": statistics.median(base_s),
        "head_s": statistics.median(head_s), "same_pixels": same, "differ": differ,
    }))


if __name__ == "__main__":
    main()
