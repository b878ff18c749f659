#!/usr/bin/env bash
# Whether a results folder's words hold on rerun: runs experiments/NAME.toml K times on this
# host (each a whole fresh run into target/stability/NAME/run-k; the non-timing numbers are
# deterministic, so what can move is what timing decides), reads every verdict word of each
# report (faster, slower, better, worse, equivalent, undecided, yes, no, in table cells and bold
# answers) and writes, per word of the committed report results/NAME/report.md, in how many of
# the K reruns the same place held the same word:
#
#   scripts/stability.sh [--reuse] NAME K
#
# --reuse compares the K runs already in target/stability/NAME instead of running them again.
# Output: target/stability/NAME/stability.csv (place, committed word, words of the reruns,
# held), copied to results/NAME-stability.csv (a plain file beside the folder, which holds only
# what the binary writes) with the host and commit in target/stability/NAME/host.txt, and a
# one-line tally on stdout. A committed word held in fewer than K runs is a finding: the README
# quotes the tally beside each answer.
set -euo pipefail
cd "$(dirname "$0")/.."
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}"

reuse=false
if [[ ${1:-} == --reuse ]]; then
    reuse=true
    shift
fi
if [[ $# -ne 2 || ! $2 =~ ^[1-9][0-9]*$ ]]; then
    echo "usage: $0 [--reuse] NAME K   (K >= 1 reruns of experiments/NAME.toml)" >&2
    exit 2
fi
name=$1
runs=$2
experiment=experiments/$name.toml
committed=results/$name/report.md
[[ -f $experiment ]] || { echo "$0: no $experiment" >&2; exit 2; }
[[ -f $committed ]] || { echo "$0: no committed $committed to compare with" >&2; exit 2; }

out=target/stability/$name
mkdir -p "$out"
if ! $reuse; then
    cargo build --release --bin sweep
    for k in $(seq 1 "$runs"); do
        echo "run $k of $runs" >&2
        target/release/sweep "$experiment" --fresh --out "$out/run-$k" -q
    done
fi

# Every word with its place: the section it sits under (the last heading or bold line, without
# the times a heading states, which differ from run to run) and, in a table, the row's first
# cell and the column's header; outside tables, the word's order in the section.
words() {
    awk '
        function trim(s) { gsub(/^[ \t*]+|[ \t*]+$/, "", s); return s }
        /^#+ / { section = $0; gsub(/,? *[0-9.]+ ms \[[^]]*\]/, "", section); n = 0; header = ""; next }
        /^\*\*[^|]*\*\*/ && !/^\*\*Answer/ { section = $0; sub(/ \(.*$/, "", section); n = 0; header = ""; next }
        /^\|/ {
            cells = split($0, c, "|")
            if (header == "") { header = $0; split($0, h, "|"); next }
            if ($0 ~ /^\|[-| ]+\|$/) next
            for (i = 3; i < cells; i++) {
                if (match(c[i], /(faster|slower|better|worse|equivalent|undecided)/)) {
                    print section " | " trim(c[2]) " | " trim(h[i]) "\t" substr(c[i], RSTART, RLENGTH)
                }
            }
            next
        }
        { header = "" }
        {
            line = $0
            while (match(line, /\*\*(faster|slower|better|worse|equivalent|undecided|yes|no)\*\*/)) {
                n++
                print section " | #" n "\t" substr(line, RSTART + 2, RLENGTH - 4)
                line = substr(line, RSTART + RLENGTH)
            }
        }
    ' "$1"
}

words "$committed" > "$out/committed.tsv"
for k in $(seq 1 "$runs"); do
    words "$out/run-$k/report.md" > "$out/run-$k.tsv"
done

{
    printf 'place,committed'
    for k in $(seq 1 "$runs"); do printf ',run_%s' "$k"; done
    printf ',held\n'
    while IFS=$'\t' read -r place word; do
        held=0
        printf '"%s",%s' "${place//\"/\"\"}" "$word"
        for k in $(seq 1 "$runs"); do
            again=$(awk -F'\t' -v p="$place" '$1 == p { print $2; exit }' "$out/run-$k.tsv")
            printf ',%s' "${again:-missing}"
            [[ $again == "$word" ]] && held=$((held + 1))
        done
        printf ',%s\n' "$held"
    done < "$out/committed.tsv"
} > "$out/stability.csv"

cp "$out/stability.csv" "results/$name-stability.csv"
{
    echo "commit $(git rev-parse HEAD)"
    grep -m1 'model name' /proc/cpuinfo || true
    echo "cores $(nproc)"
} > "$out/host.txt"

total=$(($(wc -l < "$out/stability.csv") - 1))
all=$(awk -F, -v k="$runs" 'NR > 1 && $NF == k' "$out/stability.csv" | wc -l)
# Places hold commas inside their quotes, so the committed word is counted from the right.
undecided=$(awk -F, -v k="$runs" 'NR > 1 && $NF == k && $(NF - k - 1) == "undecided"' \
    "$out/stability.csv" | wc -l)
echo "$name: $all of $total committed words held in all $runs reruns ($undecided of those undecided); $out/stability.csv"
