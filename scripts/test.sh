#!/usr/bin/env bash
# Runs every test of cablemap: the Rust unit, integration and property tests,
# then the Python read-back checks (pyarrow, pandas, polars) on sweep output,
# in a private virtual environment (.venv) that this script creates when needed.
set -euo pipefail
cd "$(dirname "$0")/.."

cargo test --release --all-targets 2>&1

echo "== Python read-back of sweep output (pyarrow, pandas, polars)"
venv=.venv
if ! "$venv/bin/python" -c "import pandas, polars, pyarrow" 2>/dev/null; then
    echo "creating $venv with pandas, polars, pyarrow"
    python3 -m venv "$venv"
    "$venv/bin/python" -m pip install --quiet --disable-pip-version-check pandas polars pyarrow
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cargo build --release --quiet
bin=$(cargo metadata --format-version 1 --no-deps | "$venv/bin/python" -c 'import json,sys; print(json.load(sys.stdin)["target_directory"])')/release/cablemap
"$bin" sweep jobs/quick.toml --out "$work/quick" --quiet
"$bin" sweep tests/python/failures.toml --out "$work/failures" --quiet
"$venv/bin/python" tests/python/check_sweep.py "$work/quick" "$work/failures"

echo "== Python read-back of maps (pandas, polars)"
"$bin" reduce "$work/quick" --out "$work/quick-map" --json > /dev/null
"$venv/bin/python" tests/python/check_maps.py "$work/quick-map" "$work/quick"

echo "== Python read-back of moulds (trimesh)"
if ! "$venv/bin/python" -c "import trimesh" 2>/dev/null; then
    "$venv/bin/python" -m pip install --quiet --disable-pip-version-check trimesh numpy
fi
"$bin" mould --routing 1,-2,3,0.5,-3 --out "$work/mould" > /dev/null
"$venv/bin/python" tests/python/check_moulds.py "$work/mould"
