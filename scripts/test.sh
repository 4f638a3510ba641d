#!/usr/bin/env bash
# Runs every test of cablemap: the Rust unit, integration and property tests,
# then the Python read-back checks (pyarrow, pandas, polars) on sweep output,
# in a private virtual environment (.venv) that this script creates when needed,
# then the map explorer in a real browser (Debian's chromium and chromedriver,
# installed with apt-get when run as root; skipped loudly where they cannot be).
set -euo pipefail
cd "$(dirname "$0")/.."

cargo test --release --all-targets 2>&1

echo "== Python read-back of sweep output (pyarrow, pandas, polars)"
venv=.venv
if ! "$venv/bin/python" -c "import pandas, polars, pyarrow, selenium" 2>/dev/null; then
    echo "creating $venv with pandas, polars, pyarrow, selenium"
    python3 -m venv "$venv"
    "$venv/bin/python" -m pip install --quiet --disable-pip-version-check pandas polars pyarrow selenium
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cargo build --release --quiet
bin=$(cargo metadata --format-version 1 --no-deps | "$venv/bin/python" -c 'import json,sys; print(json.load(sys.stdin)["target_directory"])')/release/cablemap
"$bin" sweep jobs/quick.toml --out "$work/quick" --quiet
"$bin" sweep tests/python/failures.toml --out "$work/failures" --quiet
"$venv/bin/python" tests/python/check_sweep.py "$work/quick" "$work/failures"

echo "== Python read-back of a cable sweep (pyarrow, pandas, polars)"
"$bin" map jobs/spatial-pair.toml --out "$work/cables" > /dev/null
"$bin" map jobs/antagonistic-pair.toml --out "$work/pair" > /dev/null
"$venv/bin/python" tests/python/check_cable_sweep.py "$work/cables" "$work/pair"

echo "== Python read-back of maps (pandas, polars)"
"$bin" reduce "$work/quick" --out "$work/quick-map" --json > /dev/null
"$venv/bin/python" tests/python/check_maps.py "$work/quick-map" "$work/quick"

echo "== Map explorer in a real browser (headless Chromium)"
if ! { command -v chromium && command -v chromedriver; } >/dev/null 2>&1; then
    if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
        echo "installing chromium and chromium-driver (Debian packages)"
        apt-get update -qq >/dev/null 2>&1 || true
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium chromium-driver >/dev/null 2>&1 || true
    fi
fi
if { command -v chromium && command -v chromedriver; } >/dev/null 2>&1; then
    artefacts=${CABLEMAP_TEST_ARTEFACTS:-$(cargo metadata --format-version 1 --no-deps | "$venv/bin/python" -c 'import json,sys; print(json.load(sys.stdin)["target_directory"])')/test-artefacts}
    "$venv/bin/python" tests/python/check_explorer.py "$work/quick-map" "$bin" "$artefacts/explorer.png"
    # A planar two-cable sweep's map: the same page.
    "$venv/bin/python" tests/python/check_explorer.py "$work/pair/map/planar" "$bin" "$artefacts/explorer-pair.png"
else
    echo "!!!!!!!! SKIPPED: the map explorer's browser check did not run: chromium and chromedriver are not"
    echo "!!!!!!!! installed and cannot be installed here (needs root and apt-get: apt-get install chromium chromium-driver)"
fi

echo "== Python read-back of moulds (trimesh)"
if ! "$venv/bin/python" -c "import trimesh" 2>/dev/null; then
    "$venv/bin/python" -m pip install --quiet --disable-pip-version-check trimesh numpy
fi
"$bin" mould --routing 1,-2,3,0.5,-3 --out "$work/mould" > /dev/null
"$venv/bin/python" tests/python/check_moulds.py "$work/mould"
