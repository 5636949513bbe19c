#!/usr/bin/env bash
# One command sets up the Dask driver: a venv at the repository root (.venv) with rtis-dask and
# its test dependencies from PyPI, and a release build of rtis.
set -euo pipefail
cd "$(dirname "$0")/.."
python3 -m venv .venv
.venv/bin/pip install --quiet --upgrade pip
.venv/bin/pip install --quiet -e "cluster[test]"
cargo build --release
echo "ready: .venv/bin/rtis-dask render SCENE --passes N -o OUT (see cluster/README.md)"
