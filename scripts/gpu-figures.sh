#!/usr/bin/env bash
# Runs the visibility-field paper's experiments on the GPU backend, each into its own results
# folder beside (never over) the committed CPU results:
#
#   scripts/gpu-figures.sh [--out DIR] [NAME...]
#
# NAMEs default to `ao ao-bundles-gpu walkthrough scaling` (any experiment under experiments/ may
# be named).
# Each runs `sweep experiments/NAME.toml --backend gpu --fresh --out DIR/NAME`, DIR being
# `gpu-results` unless --out names another (one per device, e.g. gpu-results/h100). Every report
# opens with the adapter it ran on (and says so where it is Mesa's software driver, whose GPU
# times are a CPU's); the manifest records the adapter and its driver. A failed experiment
# leaves its earlier folder whole and the script goes on, exiting non-zero at the end.
set -euo pipefail
cd "$(dirname "$0")/.."
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}"

root=gpu-results
names=()
while [[ $# -gt 0 ]]; do
    case $1 in
        --out)
            root=${2:?--out needs a folder}
            shift 2
            ;;
        -h | --help)
            sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'
            exit 0
            ;;
        -*)
            echo "$0: unknown option $1 (usage: $0 [--out DIR] [NAME...])" >&2
            exit 2
            ;;
        *)
            name=${1#experiments/}
            names+=("${name%.toml}")
            shift
            ;;
    esac
done
[[ ${#names[@]} -gt 0 ]] || names=(ao ao-bundles-gpu walkthrough scaling)
for name in "${names[@]}"; do
    [[ -f experiments/$name.toml ]] || {
        echo "$0: no experiments/$name.toml" >&2
        exit 2
    }
done

cargo build --release --bin sweep
sweep="${CARGO_TARGET_DIR:-target}/release/sweep"

failed=()
for name in "${names[@]}"; do
    out="$root/$name"
    echo "== $name: $sweep experiments/$name.toml --backend gpu --fresh --out $out" >&2
    "$sweep" "experiments/$name.toml" --backend gpu --fresh --out "$out" || failed+=("$name")
done
if [[ ${#failed[@]} -gt 0 ]]; then
    echo "$0: failed: ${failed[*]}" >&2
    exit 1
fi
