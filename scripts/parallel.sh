#!/usr/bin/env bash
# An experiment (any kind) as N shards run by GNU parallel, on this machine or over ssh hosts,
# then merged here:
#
#   scripts/parallel.sh EXPERIMENT N [SWEEP OPTIONS...]
#
# Paths are taken from the current folder. GNU parallel's own options come from
# PENUMBRA_PARALLEL_ARGS (split at spaces), e.g. "--jobs 2" (shards at once here) or
# "--sshlogin 1/gpu1,1/gpu2" (one shard at a time on each host). Hosts must see the current
# folder at the same path (a shared file system) and have the same kind of device: the merge
# takes only shards of the same binary, inputs and device. Rerunning the script reruns only
# what is missing: finished shards resume every group from their journals.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
[[ $# -ge 2 ]] || { echo "usage: $0 EXPERIMENT N [SWEEP OPTIONS...]" >&2; exit 2; }
experiment=$1 count=$2
shift 2
[[ $count =~ ^[1-9][0-9]*$ ]] || { echo "$0: N must be a positive integer, got '$count'" >&2; exit 2; }
command -v parallel >/dev/null || { echo "$0: GNU parallel is not installed (apt-get install parallel)" >&2; exit 1; }
if [[ -z ${PENUMBRA_SWEEP:-} ]]; then
    cargo build --release --bin sweep --manifest-path "$here/../Cargo.toml"
    PENUMBRA_SWEEP=$here/../target/release/sweep
fi
read -r -a extra <<<"${PENUMBRA_PARALLEL_ARGS:-}"
# --quote passes every word as it is (spaces included) to the shell, here or over ssh. Failed
# shards do not stop the others; the merge below names any to rerun.
parallel --will-cite --quote "${extra[@]}" --workdir "$PWD" --line-buffer --tagstring "shard {}/$count" \
    "$PENUMBRA_SWEEP" "$experiment" "$@" --shard "{}/$count" ::: $(seq 1 "$count") || true
exec "$PENUMBRA_SWEEP" "$experiment" "$@" --merge "$count"
