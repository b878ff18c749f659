#!/usr/bin/env bash
# Penumbra side by side with Mitsuba 3 (and pbrt-v4 where one is installed) on the soft-shadow
# paper's scene, judged against the exact reference, into results/peers:
#
#   scripts/peers.sh
#
# 1. exports the sphere scene's measuring view (experiments/sphere.toml's: camera `measure`,
#    160 x 160) as a Mitsuba 3 scene (export --to mitsuba) and renders it with penumbra's f64
#    CPU backend (export --to penumbra, uniform disk sampling, one shadow ray per sample);
# 2. renders the Mitsuba scene at 16 to 4096 samples per pixel (one emitter sample each), four
#    seeds each, with Mitsuba 3 from PyPI in a virtual environment under target/ (the test
#    command never needs it);
# 3. exports the view as a pbrt-v4 scene (export --to pbrt) and, where a `pbrt` binary is on
#    PATH (or named by $PBRT), renders it at the same counts and seeds (`pbrt --spp N --seed K`).
#    pbrt-v4 has no package in Debian or on PyPI and its build downloads its submodules, so the
#    committed results hold no pbrt images unless the machine had one;
# 4. judges every image against the exact reference (shadow rays from the surface, as penumbra
#    traces them) and Mitsuba's also against the answer for shadow rays lifted as Mitsuba 3
#    lifts them (its export records the lift).
#
# results/peers is replaced only when everything succeeded; the renders stay in target/peers.
# Run it from a clean checkout of the commit the results will name, as scripts/regenerate.sh.
set -euo pipefail
cd "$(dirname "$0")/.."
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}"
MITSUBA_VERSION=3.9.1
SPP=16,64,256,1024,4096
SEEDS=4
work=target/peers
venv=target/peers-venv

cargo build --release --bins
rm -rf "$work"
target/release/export experiments/scenes/sphere.toml --camera measure --size 160x160 --to mitsuba --out "$work/mitsuba"
target/release/export experiments/scenes/sphere.toml --camera measure --size 160x160 --to pbrt --out "$work/pbrt"
target/release/export experiments/scenes/sphere.toml --camera measure --size 160x160 --to penumbra \
    --spp "$SPP" --seeds "$SEEDS" --scheme uniform --out "$work/penumbra"

if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/pip" install -q "mitsuba==$MITSUBA_VERSION" numpy
"$venv/bin/python" scripts/peers-mitsuba.py "$work/mitsuba" --spp "$SPP" --seeds "$SEEDS" --variant scalar_rgb

renderers=(mitsuba/mitsuba)
pbrt="${PBRT:-$(command -v pbrt || true)}"
if [ -n "$pbrt" ]; then
    pbrt=$(realpath "$pbrt")
    echo "image,spp,seed,seconds" >"$work/pbrt/pbrt-times.csv"
    for spp in ${SPP//,/ }; do
        for seed in $(seq 1 "$SEEDS"); do
            image="pbrt-spp$spp-seed$seed.exr"
            started=$(date +%s.%N)
            (cd "$work/pbrt" && "$pbrt" --quiet --spp "$spp" --seed "$seed" --outfile "$image" scene.pbrt)
            awk -v a="$started" -v b="$(date +%s.%N)" -v i="$image,$spp,$seed" 'BEGIN { printf "%s,%.6f\n", i, b - a }' >>"$work/pbrt/pbrt-times.csv"
        done
    done
    renderers+=(pbrt/pbrt)
else
    echo "no pbrt on PATH (set PBRT to one): $work/pbrt/scene.pbrt is exported, not rendered"
fi

# Images in order of sample count (the report's rows follow it), Mitsuba's, pbrt's, penumbra's.
images=()
renderers+=(penumbra/penumbra-uniform)
for renderer in "${renderers[@]}"; do
    for spp in ${SPP//,/ }; do
        for seed in $(seq 1 "$SEEDS"); do
            images+=("$work/$renderer-spp$spp-seed$seed.exr")
        done
    done
done
target/release/judge "${images[@]}" --out "$work/judged"
# The times and Mitsuba's pixel centres travel with the judged folder.
cp "$work/mitsuba/scene.xml" "$work/judged/mitsuba-scene.xml"
cp "$work/mitsuba/mitsuba-times.csv" "$work/mitsuba/mitsuba-pixel-centres.csv" "$work/penumbra/penumbra-times.csv" "$work/judged/"
if [ -n "$pbrt" ]; then
    cp "$work/pbrt/scene.pbrt" "$work/judged/pbrt-scene.pbrt"
    cp "$work/pbrt/pbrt-times.csv" "$work/judged/"
fi
rm -rf results/peers.new
cp -r "$work/judged" results/peers.new
rm -rf results/peers
mv results/peers.new results/peers
echo "wrote results/peers"
