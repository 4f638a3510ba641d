#!/usr/bin/env bash
# Checks the SLURM array job of the sweep on a one-node cluster on localhost:
# installs Debian's slurm-wlm and munge (root, apt-get), starts munged,
# slurmctld and slurmd with a private configuration, submits
# jobs/slurm/sweep.sbatch for jobs/quick.toml as a 3-task array, waits and
# checks the result equals a single-process run (the chunk files are byte for
# byte the same: chunking does not depend on the shard count); then runs the
# whole chain (jobs/slurm/chain.sh: sweep array → reduce array → merge, by
# afterok dependencies) and checks its map equals `cablemap map`'s; runs a
# 2 × 2 study as a 2-task array (jobs/slurm/study.sbatch) then its comparison
# and checks both equal `cablemap study` in one process; stops the
# daemons it started. Skips with a message, successfully, when the packages
# cannot be installed. About a minute on a clean machine.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)

skip() { echo "slurm-local: skipped: $*"; exit 0; }
[ "$(id -u)" = 0 ] || skip "needs root to install and run slurm"
if ! command -v slurmctld >/dev/null || ! command -v slurmd >/dev/null || ! command -v munged >/dev/null; then
    command -v apt-get >/dev/null || skip "no apt-get"
    echo "slurm-local: installing slurm-wlm and munge"
    { apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends slurm-wlm munge; } \
        >/tmp/slurm-local-apt.log 2>&1 || skip "apt-get could not install slurm-wlm munge (see /tmp/slurm-local-apt.log)"
fi

cargo build --release --quiet
target=$(cargo metadata --format-version 1 --no-deps | sed -n 's/.*"target_directory":"\([^"]*\)".*/\1/p')
bin="$target/release/cablemap"
[ -x "$bin" ] || { echo "slurm-local: no binary at $bin"; exit 1; }

work=$(mktemp -d /tmp/slurm-local.XXXXXX)
pids=()
munged_pid=""
cleanup() {
    # Stop only the daemons this script started, by pid.
    for pid in "${pids[@]}"; do kill "$pid" 2>/dev/null || true; done
    for pid in "${pids[@]}"; do wait "$pid" 2>/dev/null || true; done
    if [ -n "$munged_pid" ]; then kill "$munged_pid" 2>/dev/null || true; fi
    rm -rf "$work"
}
trap cleanup EXIT

# munge: authentication between the slurm daemons. Reuse a running munged.
if ! (munge -n | unmunge) >/dev/null 2>&1; then
    if [ ! -s /etc/munge/munge.key ]; then
        mkdir -p /etc/munge
        dd if=/dev/urandom of=/etc/munge/munge.key bs=1024 count=1 status=none
    fi
    chown munge:munge /etc/munge/munge.key && chmod 0400 /etc/munge/munge.key
    mkdir -p /run/munge /var/lib/munge /var/log/munge
    chown munge:munge /run/munge /var/lib/munge /var/log/munge
    runuser -u munge -- /usr/sbin/munged
    for _ in $(seq 50); do [ -s /run/munge/munged.pid ] && break; sleep 0.1; done
    munged_pid=$(cat /run/munge/munged.pid)
    (munge -n | unmunge) >/dev/null || { echo "slurm-local: munged does not answer"; exit 1; }
fi

# A private one-node configuration (SLURM_CONF points every command at it).
cpus=$(nproc)
mem_mb=$(awk '/MemTotal/ {print int($2 / 1024)}' /proc/meminfo)
mkdir -p "$work/ctld" "$work/d" "$work/logs"
cat >"$work/slurm.conf" <<CONF
ClusterName=cablemap-local
SlurmctldHost=localhost
SlurmUser=root
AuthType=auth/munge
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
MpiDefault=none
ReturnToService=2
StateSaveLocation=$work/ctld
SlurmdSpoolDir=$work/d
SlurmctldPidFile=$work/slurmctld.pid
SlurmdPidFile=$work/slurmd.pid
SlurmctldLogFile=$work/slurmctld.log
SlurmdLogFile=$work/slurmd.log
NodeName=localhost CPUs=$cpus RealMemory=$mem_mb State=UNKNOWN
PartitionName=local Nodes=localhost Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$work/slurm.conf"
slurmctld -D -i -f "$SLURM_CONF" >"$work/slurmctld.out" 2>&1 &
pids+=($!)
slurmd -D -N localhost -f "$SLURM_CONF" >"$work/slurmd.out" 2>&1 &
pids+=($!)
for _ in $(seq 100); do
    state=$(sinfo -h -n localhost -o %T 2>/dev/null || true)
    case "$state" in idle*|mixed*|allocated*) break ;; esac
    sleep 0.3
done
case "$state" in
    idle*|mixed*|allocated*) echo "slurm-local: cluster up (node localhost $state, $cpus cpus)" ;;
    *) echo "slurm-local: node did not come up (state '$state')"; tail -20 "$work"/slurm*.log "$work"/*.out; exit 1 ;;
esac

# The array job: 3 shards of the quick sweep, 1 cpu each.
out="$work/array"
SPEC="$root/jobs/quick.toml" OUT="$out" CABLEMAP="$bin" \
    sbatch --wait --array=0-2 --cpus-per-task=1 --mem-per-cpu=0 --time=5 --chdir="$root" \
    --output="$work/logs/%A_%a.out" jobs/slurm/sweep.sbatch \
    || { echo "slurm-local: array job failed"; cat "$work"/logs/*.out; exit 1; }
cat "$work"/logs/*.out

# Same sweep in one process; the outputs must be identical.
"$bin" sweep jobs/quick.toml --out "$work/single" --quiet >/dev/null
"$bin" status "$out"
"$bin" status "$out" --json | grep -q '"complete":true' || { echo "slurm-local: array run incomplete"; exit 1; }
diff <(cd "$work/single/shards" && ls) <(cd "$out/shards" && ls) >/dev/null || { echo "slurm-local: different chunk files"; exit 1; }
for f in "$work/single/shards"/*.parquet; do
    cmp -s "$f" "$out/shards/$(basename "$f")" || { echo "slurm-local: $(basename "$f") differs from the single-process run"; exit 1; }
done
echo "slurm-local: array job output equals the single-process run ($(ls "$out/shards" | wc -l) chunk files)"

# The whole chain: sweep array (3 tasks) → reduce array (2 tasks) → merge,
# each after the previous succeeded; the map must equal `cablemap map`'s.
chain="$work/chain"
SPEC="$root/jobs/quick.toml" RUN="$chain/run" MAP="$chain/map" CABLEMAP="$bin" SWEEP_TASKS=3 REDUCE_TASKS=2 WAIT=1 \
    SBATCH_ARGS="--cpus-per-task=1 --time=5 --chdir=$root --output=$work/logs/%x-%A_%a.out" \
    jobs/slurm/chain.sh || { echo "slurm-local: the chain failed"; cat "$work"/logs/cablemap-*.out; exit 1; }
cat "$work"/logs/cablemap-reduce-*.out "$work"/logs/cablemap-merge-*.out
"$bin" map jobs/quick.toml --out "$work/single-map" >/dev/null
for t in cells.parquet modes.parquet designs.parquet; do
    cmp -s "$work/single-map/map/$t" "$chain/map/$t" || { echo "slurm-local: the chain's $t differs from cablemap map's"; exit 1; }
done
diff <(grep -v '"run_dir"' "$work/single-map/map/summary.json") <(grep -v '"run_dir"' "$chain/map/summary.json") \
    || { echo "slurm-local: the chain's summary.json differs from cablemap map's"; exit 1; }
echo "slurm-local: sweep → reduce → merge chain's map equals cablemap map's ($(ls "$chain/map.parts" | grep -c json) reduce parts)"

# A 2 × 2 study of the quick grid as a 2-task array, then the comparison
# after it (afterok); equal to the study run in one process.
cat >"$work/study.toml" <<'TOML'
[grid]
levels = 3
[tension]
count = 5
[output]
chunk_routings = 16
[study]
[[study.axis]]
name = "length_mm"
values = [55.0, 75.0]
[[study.axis]]
name = "ei_n_mm2"
scale = [0.8, 1.25]
TOML
study_job=$(SPEC="$work/study.toml" OUT="$work/study" CABLEMAP="$bin" sbatch --parsable --array=0-1 --cpus-per-task=1 --mem=0 \
    --time=5 --chdir="$root" --output="$work/logs/%x-%A_%a.out" jobs/slurm/study.sbatch)
sbatch --wait --dependency=afterok:"${study_job%%;*}" --kill-on-invalid-dep=yes --time=5 --mem=0 --chdir="$root" \
    --output="$work/logs/study-compare-%j.out" --wrap "$bin study $work/study.toml --out $work/study --compare" \
    || { echo "slurm-local: the study job failed"; cat "$work"/logs/*study*.out; exit 1; }
cat "$work"/logs/cablemap-study-*.out
"$bin" study "$work/study.toml" --out "$work/study-single" >/dev/null
cmp "$work/study/comparison.csv" "$work/study-single/comparison.csv" || { echo "slurm-local: the study's comparison differs"; exit 1; }
for i in 0 1 2 3; do
    for t in cells.parquet modes.parquet designs.parquet; do
        cmp -s "$work/study/v$i/map/$t" "$work/study-single/v$i/map/$t" || { echo "slurm-local: study variant $i's $t differs"; exit 1; }
    done
done
echo "slurm-local: the study as a 2-task array then --compare equals cablemap study in one process (4 variants)"
