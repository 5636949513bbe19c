#!/usr/bin/env python3
"""Time a newcomer's first builds of some commits, each from nothing, one after the other.

For each commit: a git worktree of it and a target folder of its own, then
1. `cargo build --release` (what `cargo run --release`, the README's render command, builds);
2. `cargo test --release --no-run` after it (what the README's test command then compiles).
Prints a JSON line per commit: the seconds of each build, the test binaries the second made,
and the size of the target folder. Run it with nothing else compiling: the two cores are the
measure. `bench/readme_figures.py --only build` writes its README block from it.

Usage:
    python3 bench/build_times.py REV [REV ...]
"""

import json
import os
import shutil
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def du(path):
    total = 0
    for d, _, files in os.walk(path):
        for f in files:
            try:
                total += os.lstat(os.path.join(d, f)).st_size
            except OSError:
                pass
    return total


def timed(args, cwd, env):
    start = time.monotonic()
    p = subprocess.run(args, cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if p.returncode != 0:
        sys.exit(f"{' '.join(args)} failed in {cwd}:\n{p.stderr[-4000:]}")
    return time.monotonic() - start, p.stderr


def measure(rev):
    short = subprocess.run(["git", "rev-parse", "--short", rev], cwd=ROOT, check=True, capture_output=True,
                           text=True).stdout.strip()
    base = os.path.join(ROOT, "target", "build-times")
    tree = os.path.join(base, short)
    target = os.path.join(base, short + "-target")
    for p in (tree, target):
        shutil.rmtree(p, ignore_errors=True)
    subprocess.run(["git", "worktree", "prune"], cwd=ROOT, check=True)
    subprocess.run(["git", "worktree", "add", "--detach", "-f", tree, short], cwd=ROOT, check=True,
                   capture_output=True)
    env = dict(os.environ, CARGO_TARGET_DIR=target, CARGO_TERM_COLOR="never")
    try:
        run_s, _ = timed(["cargo", "build", "--release", "--locked"], tree, env)
        test_s, log = timed(["cargo", "test", "--release", "--locked", "--no-run"], tree, env)
        binaries = sum(1 for l in log.splitlines() if l.strip().startswith("Executable tests/")
                       or "Executable tests" in l and "(tests/" in l)
        size = du(target)
    finally:
        subprocess.run(["git", "worktree", "remove", "--force", tree], cwd=ROOT, capture_output=True)
        shutil.rmtree(target, ignore_errors=True)
    return {"commit": short, "build_s": run_s, "test_build_s": test_s, "test_binaries": binaries,
            "target_bytes": size}


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    for rev in sys.argv[1:]:
        print(json.dumps(measure(rev)), flush=True)


if __name__ == "__main__":
    main()
