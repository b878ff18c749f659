#!/usr/bin/env bash
# Submits an experiment (any kind) to Slurm as a job array of N shards and a merge that runs
# after all of them:
#
#   scripts/slurm/submit.sh EXPERIMENT N [SWEEP OPTIONS...]
#
# Paths are taken from the current folder, which is where the jobs run. Builds the release
# binary first unless PENUMBRA_SWEEP names one. Extra sbatch options (a partition, a GPU:
# --gres=gpu:1) come from PENUMBRA_SBATCH_ARGS; logs go to PENUMBRA_SLURM_LOGS (default
# slurm-logs/). PENUMBRA_SHARDS=2,5 submits only those shards (to rerun them) before the merge.
# With PENUMBRA_SLURM_WAIT=1 it waits for the merge and exits with its status.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
[[ $# -ge 2 ]] || { echo "usage: $0 EXPERIMENT N [SWEEP OPTIONS...]" >&2; exit 2; }
experiment=$1 count=$2
shift 2
[[ $count =~ ^[1-9][0-9]*$ ]] || { echo "$0: N must be a positive integer, got '$count'" >&2; exit 2; }
if [[ -z ${PENUMBRA_SWEEP:-} ]]; then
    cargo build --release --bin sweep --manifest-path "$here/../../Cargo.toml"
    export PENUMBRA_SWEEP=$here/../../target/release/sweep
fi
logs=${PENUMBRA_SLURM_LOGS:-slurm-logs}
mkdir -p "$logs" # Slurm does not create the folder of a task's output file.
read -r -a extra <<<"${PENUMBRA_SBATCH_ARGS:-}"
shards=${PENUMBRA_SHARDS:-1-$count}
array=$(sbatch --parsable "${extra[@]}" --array="$shards" --output="$logs/%x-%A_%a.out" \
    "$here/sweep.sbatch" "$experiment" "$count" "$@")
array=${array%%;*}
echo "shards: job array $array (tasks $shards of $count), logs in $logs/"
wait=()
[[ ${PENUMBRA_SLURM_WAIT:-0} == 1 ]] && wait=(--wait)
echo "merge: runs after the array (afterany), log $logs/penumbra-sweep-JOB.out"
sbatch --parsable "${extra[@]}" "${wait[@]}" --dependency="afterany:$array" --output="$logs/%x-%j.out" \
    "$here/sweep.sbatch" "$experiment" "$count" merge "$@"
