#!/usr/bin/env bash
# Draws results/NAME/page.png, a screenshot of each results folder's comparison page as a browser
# shows it on opening (headless chromium), for the README.
set -euo pipefail
cd "$(dirname "$0")/.."
for page in results/*/index.html; do
    dir=$(dirname "$page")
    chromium --headless --no-sandbox --disable-gpu --hide-scrollbars --virtual-time-budget=20000 \
        --window-size=1400,1100 --screenshot="$PWD/$dir/page.png" "file://$PWD/$page" 2>/dev/null
    echo "wrote $dir/page.png"
done
