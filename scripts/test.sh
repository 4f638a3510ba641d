#!/usr/bin/env bash
# Runs every test of cablemap: the Rust unit, integration and property tests,
# the Python read-back checks (pyarrow, pandas, polars, trimesh) on sweep,
# map and mould output, and the map explorer in a real browser (Debian's
# chromium and chromedriver). Ends with one line "N passed, M failed" over
# every check (CI reads that line) and exits 1 if anything failed.
#
# The machine has few cores, so nothing waits that need not: the one-time
# installs (a Python virtual environment, Chromium when run as root with
# apt-get) run while cargo builds, each announced with what it is for and
# about how long it takes; then the Rust tests run in the foreground while
# the Python and browser checks run beside them, their output printed after
# the Rust tests' in a fixed order. The virtual environment lives in cargo's
# target directory (CABLEMAP_VENV overrides), so `.ci/run`'s fresh clones,
# which share target/, reuse it and `cargo clean` removes it.
set -uo pipefail
cd "$(dirname "$0")/.."

if ! target=$(cargo metadata --format-version 1 --no-deps | python3 -c 'import json,sys; print(json.load(sys.stdin)["target_directory"])' 2>/dev/null); then
    echo "error: cannot read cargo's target directory (cargo metadata | python3): the suite needs Rust's cargo and Python 3 on PATH" >&2
    echo "0 passed, 1 failed"
    exit 1
fi
bin=$target/release/cablemap
venv=${CABLEMAP_VENV:-$target/python-venv}
artefacts=${CABLEMAP_TEST_ARTEFACTS:-$target/test-artefacts}
python_packages="pandas polars pyarrow selenium trimesh numpy maturin pytest matplotlib"
work=$(mktemp -d)
# No kill of the background jobs on exit: an install must not be cut short.
trap 'rm -rf "$work"' EXIT
mkdir -p "$work/results" "$work/logs"

# A check's outcome is a file "PASSED FAILED" in $work/results, so that
# checks running in the background are counted like the foreground ones.
record() { echo "$2 $3" > "$work/results/$1"; }

# Background installs: each writes its exit status to $work/NAME.rc when done.
install_python() {
    local start=$SECONDS
    { python3 -m venv "$venv" && "$venv/bin/python" -m pip install --quiet --disable-pip-version-check $python_packages; } \
        > "$work/logs/install-python.log" 2>&1
    local rc=$?
    echo "python packages: installed into $venv in $((SECONDS - start)) s (exit $rc)" >> "$work/logs/installs.log"
    echo $rc > "$work/python.rc"
}
install_chromium() {
    local start=$SECONDS
    { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium chromium-driver; } \
        > "$work/logs/install-chromium.log" 2>&1
    local rc=$?
    echo "chromium: installed in $((SECONDS - start)) s (exit $rc)" >> "$work/logs/installs.log"
    echo $rc > "$work/chromium.rc"
}
have_chromium() { command -v chromium && command -v chromedriver; } >/dev/null 2>&1
wait_for() { while [ ! -e "$work/$1.rc" ]; do sleep 1; done; [ "$(cat "$work/$1.rc")" = 0 ]; }

if "$venv/bin/python" -c "import ${python_packages// /, }" 2>/dev/null; then
    echo 0 > "$work/python.rc"
else
    echo "== installing Python packages for the read-back checks ($python_packages) into $venv:"
    echo "   once per target directory, about 2 minutes and 600 MB (pip, in the background while cargo builds)"
    install_python &
fi
if have_chromium; then
    echo 0 > "$work/chromium.rc"
elif [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
    echo "== installing chromium and chromium-driver (Debian packages) for the map explorer's browser check:"
    echo "   once per machine, about 3 minutes and 400 MB (apt-get, in the background while cargo builds)"
    install_chromium &
else
    echo 1 > "$work/chromium.rc"
fi

echo "== Rust: build (cargo test --release --all-targets --no-run)"
if cargo test --release --all-targets --no-run && cargo build --release --quiet; then
    built=1
else
    built=0
    record build 0 1
fi

# The Python package (python/, pyo3 + maturin): built from this tree into
# the venv (`pip install ./python`, maturin from the venv: no download per
# run) after the main build, whose dependencies in target/ it shares.
wheel=0
if [ "$built" = 1 ]; then
    echo "== Python package: build and install (pip install ./python, maturin)"
    if wait_for python; then
        start=$SECONDS
        if PATH="$venv/bin:$PATH" CARGO_TARGET_DIR="$target" "$venv/bin/python" -m pip install --quiet --disable-pip-version-check \
            --no-build-isolation --force-reinstall --no-deps ./python > "$work/logs/wheel.log" 2>&1; then
            wheel=1
            echo "python package: built and installed in $((SECONDS - start)) s"
        else
            echo "FAIL python package: pip install ./python failed; the end of its log:"
            tail -n 30 "$work/logs/wheel.log"
            record wheel 0 1
        fi
    else
        echo "FAIL python package: not built, the Python packages could not be installed"
        record wheel 0 1
    fi
fi

# The Python checks. check NAME SCRIPT ARGS...: runs one check script, which
# prints "python: N passed, M failed"; a script that dies before that line,
# or exits non-zero with no failure counted, is one failure.
check() {
    local name=$1
    shift
    if ! wait_for python; then
        echo "FAIL $name: not run, the Python packages could not be installed (see the install log above)"
        record "$name" 0 1
        return
    fi
    "$venv/bin/python" "$@" > "$work/logs/$name.out" 2>&1
    local rc=$?
    cat "$work/logs/$name.out"
    local line passed failed
    line=$(grep -E '^python: [0-9]+ passed, [0-9]+ failed$' "$work/logs/$name.out" | tail -1)
    passed=$(echo "$line" | awk '{print $2+0}')
    failed=$(echo "$line" | awk '{print $4+0}')
    if [ -z "$line" ] || { [ "$rc" != 0 ] && [ "$failed" = 0 ]; }; then
        if [ -n "$line" ]; then
            echo "FAIL $name: exited with status $rc after \"$line\""
        else
            echo "FAIL $name: exited with status $rc before counting its checks"
        fi
        failed=$((failed + 1))
    fi
    record "$name" "$passed" "$failed"
}
# step NAME CMD...: output the checks need; a failure is counted and stops
# the group (its checks cannot run).
step() {
    local name=$1
    shift
    local out=$work/logs/step-${name//[^a-z0-9]/-}.out
    "$@" > "$out" 2>&1
    local rc=$?
    [ "$rc" != 0 ] || return 0
    echo "FAIL $name: $* exited with status $rc"
    tail -n 20 "$out"
    record "$name" 0 1
    return 1
}
# The browser check of one map page (skipped loudly where Chromium cannot be had).
explorer() {
    local name=$1 map=$2 shot=$3
    if wait_for chromium && have_chromium; then
        check "$name" tests/python/check_explorer.py "$map" "$bin" "$artefacts/$shot"
    else
        echo "!!!!!!!! SKIPPED: the map explorer's browser check ($name) did not run: chromium and chromedriver are not"
        echo "!!!!!!!! installed and cannot be installed here (needs root and apt-get: apt-get install chromium chromium-driver)"
        echo "$name" >> "$work/skipped"
    fi
}

sweeps_and_maps() {
    echo "== Python read-back of sweep output (pyarrow, pandas, polars)"
    step "sweep quick.toml" "$bin" sweep jobs/quick.toml --out "$work/quick" --quiet || return
    step "sweep failures.toml" "$bin" sweep tests/python/failures.toml --out "$work/failures" --quiet || return
    check check_sweep tests/python/check_sweep.py "$work/quick" "$work/failures"
    echo "== Python read-back of maps (pandas, polars)"
    step "reduce quick" "$bin" reduce "$work/quick" --out "$work/quick-map" --json || return
    check check_maps tests/python/check_maps.py "$work/quick-map" "$work/quick"
    echo "== Map explorer in a real browser (headless Chromium)"
    explorer explorer "$work/quick-map" explorer.png
}
cable_sweeps() {
    echo "== Python read-back of a cable sweep (pyarrow, pandas, polars)"
    step "map spatial-pair.toml" "$bin" map jobs/spatial-pair.toml --out "$work/cables" || return
    step "map antagonistic-pair.toml" "$bin" map jobs/antagonistic-pair.toml --out "$work/pair" || return
    check check_cable_sweep tests/python/check_cable_sweep.py "$work/cables" "$work/pair"
    echo "== Map explorer of a planar two-cable map in a real browser (headless Chromium)"
    explorer explorer-pair "$work/pair/map/planar" explorer-pair.png
}
moulds() {
    echo "== Python read-back of moulds (trimesh)"
    step "mould" "$bin" mould --routing 1,-2,3,0.5,-3 --out "$work/mould" || return
    step "mould planar-trio.toml" "$bin" mould --actuator tests/data/moulds/planar-trio.toml --out "$work/mould-trio" || return
    step "mould spatial-pair-tapered.toml" "$bin" mould --actuator tests/data/moulds/spatial-pair-tapered.toml --out "$work/mould-lumens" || return
    check check_moulds tests/python/check_moulds.py "$work/mould" "$work/mould-trio" "$work/mould-lumens"
}

python_package() {
    echo "== Python package (pytest python/tests: the binding against the binary)"
    [ "$wheel" = 1 ] || return
    CABLEMAP_BIN="$bin" "$venv/bin/python" -m pytest -q -p no:cacheprovider python/tests > "$work/logs/pytest.out" 2>&1
    local rc=$?
    cat "$work/logs/pytest.out"
    local line passed failed
    line=$(tail -n 1 "$work/logs/pytest.out")
    passed=$(echo "$line" | grep -oE '[0-9]+ passed' | awk '{print $1}')
    failed=$(echo "$line" | grep -oE '[0-9]+ (failed|error|errors)' | awk '{s += $1} END {print s+0}')
    passed=${passed:-0}
    if [ "$rc" != 0 ] && [ "$failed" = 0 ]; then
        echo "FAIL pytest exited with status $rc (no tests collected, or it crashed)"
        failed=1
    fi
    record pytest "$passed" "$failed"
}

groups=(sweeps_and_maps cable_sweeps moulds python_package)
declare -A group_pid
if [ "$built" = 1 ]; then
    for g in "${groups[@]}"; do
        "$g" > "$work/logs/$g.log" 2>&1 &
        group_pid[$g]=$!
    done
    echo "== Rust: tests (cargo test --release --all-targets; the Python and browser checks run meanwhile)"
    cargo test --release --all-targets --no-fail-fast 2>&1 | tee "$work/logs/rust.log"
    rc=${PIPESTATUS[0]}
    read -r rust_passed rust_failed < <(awk '/^test result:/ {
        for (i = 1; i <= NF; i++) { if ($(i) ~ /^passed;/) p += $(i-1); if ($(i) ~ /^failed;/) f += $(i-1) } }
        END { print p+0, f+0 }' "$work/logs/rust.log")
    if [ "$rc" != 0 ] && [ "$rust_failed" = 0 ]; then
        echo "FAIL cargo test exited with status $rc without a failing test result (a test binary crashed?)"
        rust_failed=1
    fi
    record rust "$rust_passed" "$rust_failed"
    for g in "${groups[@]}"; do
        wait "${group_pid[$g]}"
        cat "$work/logs/$g.log"
    done
fi
wait # an install still running (when the build failed)

echo "== Summary"
[ ! -s "$work/logs/installs.log" ] || cat "$work/logs/installs.log"
for what in python chromium; do
    if [ -e "$work/logs/install-$what.log" ] && [ "$(cat "$work/$what.rc" 2>/dev/null)" != 0 ]; then
        echo "installing $what failed; the end of its log:"
        tail -n 20 "$work/logs/install-$what.log"
    fi
done
total() { cat "$@" 2>/dev/null | awk '{ p += $1; f += $2 } END { print p+0, f+0 }'; }
read -r rust_passed rust_failed < <(total "$work/results/build" "$work/results/rust")
read -r passed failed < <(total "$work"/results/*)
for f in "$work"/results/*; do
    read -r _ n < "$f"
    [ "$n" = 0 ] || echo "failed: $(basename "$f") ($n)"
done
echo "rust: $rust_passed passed, $rust_failed failed (cargo test)"
echo "python and browser: $((passed - rust_passed)) passed, $((failed - rust_failed)) failed"
[ ! -e "$work/skipped" ] || echo "skipped (not counted): $(tr '\n' ' ' < "$work/skipped")"
echo "$passed passed, $failed failed"
[ "$failed" = 0 ]
