#!/usr/bin/env bash
# Runs a fixed set of user commands with one cablemap binary and keeps what
# they print (JSON) and the tables they write, so that two binaries (before
# and after a change of structure) can be compared with
# scripts/behaviour-compare.py. Usage:
#   scripts/behaviour.sh BIN OUT_DIR
# Takes about 2 minutes on 2 cores (the SoRoMoX diagnosis is most of it).
set -euo pipefail
bin=$(realpath "$1")
out=$2
cd "$(dirname "$0")/.."
mkdir -p "$out"
out=$(realpath "$out")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# the tentacle's files in scratch: diagnose writes its report beside its input
cp tests/data/soromox/captures.csv tests/data/soromox/markers.csv tests/data/soromox/actuator.toml "$work/"

run() { # NAME ARGS...: the command's stdout into OUT/NAME.json
    local name=$1
    shift
    local rc=0
    "$bin" "$@" > "$out/$name.json" 2> "$work/$name.err" || rc=$?
    [ "$rc" = 0 ] || echo "exit $rc" >> "$out/$name.json.rc"
}

# simulate: planar, tapered, anchored, two-cable spatial, displacement-driven
run simulate-planar simulate --routing 1,-2,3,0.5,-3 --tension-n 1.5 --json
run simulate-tapered simulate --routing 1,-2,3,0.5,-3 --tension-n 1.5 --radius-profile-mm 0:5,65:4 --json
run simulate-anchored simulate --routing 1,-2,3,0.5,-3 --tension-n 1.5 --cable-anchor-mm 50 --stiffening-alpha 2 --json
run simulate-cable simulate --cable "y=1,-2,3,0.5,-3 tension=1.5" --json
run simulate-spatial simulate --actuator tests/data/spatial/antagonistic.toml --json
run simulate-spatial-rk4 simulate --cable "y=2,3,1,-1,2 z=1,-1,2,2,0 tension=1.4" --cable "y=-2,-2,-2,-2,-2 tension=0.5" --method rk4 --json
run simulate-displaced simulate --routing 1,-2,3,0.5,-3 --displacement-mm 2 --json
run simulate-displaced-cables simulate --cable "y=2,3,1,-1,2 z=1,-1,2,2,0 displacement=2" --cable "y=-2,-2,-2,-2,-2 tension=0.5" --json
run simulate-planar-rk4 simulate --routing 1,-2,3,0.5,-3 --tension-n 1.5 --method rk4 --json
run simulate-tentacle simulate --actuator "$work/actuator.toml" --json

# design: Table 5.1 I and II, a two-cable two-target sequence
run design-5.1-I design --target x=50,y=5,a0=-0.025,a1=-0.06,a2=0.015 --json
run design-5.1-II design --target x=10,y=50,a0=0.015,a1=-0.07,a2=-0.03 --json
run design-targets design --actuator tests/data/design/two-free-cables.toml --targets tests/data/design/two-targets.toml --json
# the same one-cable design by a targets file, and designs within the moulds
run design-targets-one-cable design --targets tests/data/design/table-5-1-I.toml --json
run design-5.1-I-moulds design --target x=50,y=5,a0=-0.025,a1=-0.06,a2=0.015 --out "$work/moulds-I" --moulds --json

# a sweep and map, feasible on it; a cable sweep and its map
"$bin" map jobs/quick.toml --out "$work/quick" > /dev/null 2>&1 || echo "map quick failed" >> "$out/errors"
run feasible-I feasible --map "$work/quick/map" --target x=50,y=5,a0=-0.025,a1=-0.06 --json
run feasible-xy feasible --map "$work/quick/map" --target x=40,y=20 --json
"$bin" map jobs/antagonistic-pair.toml --out "$work/pair" > /dev/null 2>&1 || echo "map antagonistic-pair failed" >> "$out/errors"
run feasible-targets feasible --map "$work/pair/map" --targets tests/data/design/two-targets.toml --json
run design-targets-map design --actuator tests/data/spatial/antagonistic.toml --targets tests/data/design/two-targets.toml --map "$work/pair/map" --json --starts 2 --max-evaluations 200
"$bin" map jobs/spatial-pair.toml --out "$work/spatial" > /dev/null 2>&1 || echo "map spatial-pair failed" >> "$out/errors"

# calibrate and diagnose on three synth files, and on the tentacle
"$bin" synth --out "$work/none.csv" --seed 1 > /dev/null
"$bin" synth --out "$work/friction.csv" --effect friction --magnitude 0.08 --seed 3 > /dev/null
"$bin" synth --out "$work/clamp.csv" --effect clamp_compliance --magnitude 100 --seed 5 > /dev/null
for f in none friction clamp; do
    cp "$work/$f.csv" "$out/synth-$f.csv"
    run "calibrate-$f" calibrate "$work/$f.csv" --json
    run "diagnose-$f" diagnose "$work/$f.csv" --no-report --json
done
# a fit with an effect and a held-out routing, a diagnosis with a held-out routing and markers
"$bin" synth --out "$work/shapes.csv" --effect friction --magnitude 0.08 --seed 7 --markers-out "$work/shapes-markers.csv" --centreline-out "$work/shapes-centrelines.csv" > /dev/null
cp "$work/shapes.csv" "$out/synth-shapes.csv"
cp "$work/shapes-markers.csv" "$out/synth-shapes-markers.csv"
cp "$work/shapes-centrelines.csv" "$out/synth-shapes-centrelines.csv"
run calibrate-effect-holdout calibrate "$work/friction.csv" --effect friction --holdout s_curve --json
run calibrate-shapes calibrate "$work/shapes.csv" --markers "$work/shapes-markers.csv" --centrelines "$work/shapes-centrelines.csv" --fix GA=1.7 --json
run diagnose-holdout diagnose "$work/clamp.csv" --holdout arc --out "$work/clamp-diagnosis" --json
# several-cable captures made by synth --actuator, fitted and diagnosed back
"$bin" synth --actuator tests/data/spatial/antagonistic.toml --out "$work/pair-captures.csv" --markers-out "$work/pair-markers.csv" --effect friction --magnitude 0.1 --seed 2 > /dev/null
cp "$work/pair-captures.csv" "$out/synth-pair-captures.csv"
cp "$work/pair-markers.csv" "$out/synth-pair-markers.csv"
run calibrate-pair calibrate "$work/pair-captures.csv" --actuator tests/data/spatial/antagonistic.toml --markers "$work/pair-markers.csv" --effect friction --json
run calibrate-pair-holdout calibrate "$work/pair-captures.csv" --actuator tests/data/spatial/antagonistic.toml --markers "$work/pair-markers.csv" --holdout-cable 2 --json
run diagnose-pair diagnose "$work/pair-captures.csv" --actuator tests/data/spatial/antagonistic.toml --markers "$work/pair-markers.csv" --out "$work/pair-diagnosis" --json
run predict-pair predict "$work/pair-captures.csv" --actuator tests/data/spatial/antagonistic.toml --markers "$work/pair-markers.csv" --json
run predict-soromox predict "$work/captures.csv" --actuator "$work/actuator.toml" --markers "$work/markers.csv" --json
run calibrate-soromox calibrate "$work/captures.csv" --actuator "$work/actuator.toml" --markers "$work/markers.csv" --out "$work/fit" --json
run diagnose-soromox diagnose "$work/captures.csv" --actuator "$work/actuator.toml" --markers "$work/markers.csv" --json

# the tables the maps wrote, as CSV (the Parquet files' bytes carry writer metadata)
python=${PYTHON:-python3}
for m in quick/map pair/map pair/map/planar spatial/map spatial/map/planar; do
    [ -d "$work/$m" ] || continue
    for t in "$work/$m"/*.parquet; do
        [ -e "$t" ] || continue
        name=$(echo "$m/$(basename "$t" .parquet)" | tr '/' '_')
        "$python" -c 'import sys, pyarrow.parquet as pq; pq.read_table(sys.argv[1]).to_pandas().to_csv(sys.argv[2], index=False, float_format="%.17g")' "$t" "$out/table-$name.csv"
    done
    [ ! -e "$work/$m/summary.json" ] || cp "$work/$m/summary.json" "$out/summary-$(echo "$m" | tr '/' '_').json"
done
# every sweep's rows, sorted (shards and chunks may be laid out differently)
for r in quick pair spatial; do
    [ -d "$work/$r/run" ] || continue
    "$python" -c 'import sys, pyarrow.dataset as ds; t = ds.dataset(sys.argv[1], format="parquet").to_table().to_pandas(); t.sort_values(list(t.columns)).to_csv(sys.argv[2], index=False, float_format="%.17g")' "$work/$r/run/shards" "$out/rows-$r.csv"
done
# the pictures and pages, by their bytes (the scratch folder's name left out)
grep -rlF "$work" "$work" --include='*.js' --include='*.html' --include='*.json' | xargs -r sed -i "s#$work#WORK#g"
(cd "$work" && find . -name '*.png' -o -name '*.html' -o -name 'cables.json' | sort | xargs sha256sum) > "$out/pictures.txt"
grep -rlF "$work" "$out" | xargs -r sed -i "s#$work#WORK#g"
echo "behaviour: $(ls "$out" | wc -l) files in $out"
