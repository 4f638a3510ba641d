#!/usr/bin/env bash
# The whole overnight job on SLURM: the sweep array, then the reduce array,
# then the merge, each starting only when the previous one succeeded in
# every task (--dependency=afterok). Prints the three job ids.
#
#   mkdir -p logs
#   jobs/slurm/chain.sh                                    # jobs/thesis.toml into runs/thesis, maps/thesis
#   SPEC=jobs/quick.toml RUN=runs/quick MAP=maps/quick SWEEP_TASKS=3 REDUCE_TASKS=2 jobs/slurm/chain.sh
#   WAIT=1 jobs/slurm/chain.sh                             # and wait for the merge to end (exit status = the chain's)
#
# SBATCH_ARGS go to every sbatch (e.g. "--partition=short --time=10");
# CABLEMAP names the binary; MAP_ARGS go to the merge (map options).
# A failed sweep or reduce task cancels the later jobs
# (--kill-on-invalid-dep): fix, and run the chain again (the sweep resumes
# where it stopped; the parts are rewritten).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)

export SPEC=${SPEC:-jobs/thesis.toml}
export RUN=${RUN:-runs/thesis}
export MAP=${MAP:-maps/thesis}
export CABLEMAP=${CABLEMAP:-cablemap}
export MAP_ARGS=${MAP_ARGS:-}
SWEEP_TASKS=${SWEEP_TASKS:-8}
REDUCE_TASKS=${REDUCE_TASKS:-4}
read -r -a extra <<<"${SBATCH_ARGS:-}"

# sweep.sbatch reads OUT as its run directory.
sweep=$(OUT="$RUN" sbatch --parsable "${extra[@]}" --array=0-$((SWEEP_TASKS - 1)) "$here/sweep.sbatch")
sweep=${sweep%%;*}
reduce=$(sbatch --parsable "${extra[@]}" --dependency=afterok:"$sweep" --kill-on-invalid-dep=yes --array=0-$((REDUCE_TASKS - 1)) "$here/reduce.sbatch")
reduce=${reduce%%;*}
wait_flag=()
[ "${WAIT:-0}" = 1 ] && wait_flag=(--wait)
echo "sweep job $sweep ($SWEEP_TASKS tasks), reduce job $reduce ($REDUCE_TASKS tasks, after the sweep)"
if [ ${#wait_flag[@]} -gt 0 ]; then
    echo "merge job: submitted after the reduce; waiting for it"
    exec sbatch "${wait_flag[@]}" "${extra[@]}" --dependency=afterok:"$reduce" --kill-on-invalid-dep=yes "$here/merge.sbatch"
fi
merge=$(sbatch --parsable "${extra[@]}" --dependency=afterok:"$reduce" --kill-on-invalid-dep=yes "$here/merge.sbatch")
echo "merge job ${merge%%;*} (after the reduce): cablemap status $RUN; the map in $MAP"
