#!/usr/bin/env bash
# Draws results/NAME/page.png, a screenshot of each results folder's comparison page as a browser
# shows it on opening (headless chromium), for the README:
#
#   scripts/page-screenshots.sh [NAME...]
#
# NAMEs choose folders under results/; without them every folder with a page is drawn.
set -euo pipefail
cd "$(dirname "$0")/.."
pages=()
if [[ $# -eq 0 ]]; then
    pages=(results/*/index.html)
else
    for name in "$@"; do
        pages+=("results/$name/index.html")
    done
fi
for page in "${pages[@]}"; do
    dir=$(dirname "$page")
    [[ -f $page ]] || { echo "$0: no $page" >&2; exit 1; }
    chromium --headless --no-sandbox --disable-gpu --hide-scrollbars --virtual-time-budget=20000 \
        --window-size=1400,1100 --screenshot="$PWD/$dir/page.png" "file://$PWD/$page" 2>/dev/null
    echo "wrote $dir/page.png"
done
