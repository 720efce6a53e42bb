#!/usr/bin/env bash
# Side-by-side with pyins (PyPI package `python-ins`): docs/performance.md.
# Needs PyPI, so it is not part of .ci/run. Usage: bench/compare.sh [extra args of
# bench/pyins_compare.py, e.g. --repeat 9 --algos savage --samples 1]
# Env: PYINS_VENV (default bench/.venv, reused if present), CARGO_TARGET_DIR, OUT.
set -euo pipefail
cd "$(dirname "$0")/.."
venv="${PYINS_VENV:-bench/.venv}"
out="${OUT:-bench/out/pyins}"
if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet python-ins==1.0.1 pandas
fi
"$venv/bin/python" -c 'import importlib.metadata as m; print("pyins (python-ins)", m.version("python-ins"), "numba", m.version("numba"), "numpy", m.version("numpy"))'
cargo build --release -p sdins-cli
sdins="${CARGO_TARGET_DIR:-target}/release/sdins"
"$venv/bin/python" bench/pyins_compare.py --sdins "$sdins" --out "$out" "$@"
