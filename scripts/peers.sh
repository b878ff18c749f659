#!/usr/bin/env bash
# Penumbra side by side with Mitsuba 3 on the soft-shadow paper's scene, judged against the
# exact reference, into results/peers:
#
#   scripts/peers.sh
#
# 1. exports the sphere scene's measuring view (experiments/sphere.toml's: camera `measure`,
#    160 x 160) as a Mitsuba 3 scene (export --to mitsuba) and renders it with penumbra's f64
#    CPU backend (export --to penumbra, uniform disk sampling, one shadow ray per sample);
# 2. renders the Mitsuba scene at 16 to 4096 samples per pixel (one emitter sample each), four
#    seeds each, with Mitsuba 3 from PyPI in a virtual environment under target/ (the test
#    command never needs it);
# 3. judges every image against the exact reference (shadow rays from the surface, as penumbra
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
target/release/export experiments/scenes/sphere.toml --camera measure --size 160x160 --to penumbra \
    --spp "$SPP" --seeds "$SEEDS" --scheme uniform --out "$work/penumbra"

if [ ! -x "$venv/bin/python" ]; then
    python3 -m venv "$venv"
fi
"$venv/bin/pip" install -q "mitsuba==$MITSUBA_VERSION" numpy
"$venv/bin/python" scripts/peers-mitsuba.py "$work/mitsuba" --spp "$SPP" --seeds "$SEEDS" --variant scalar_rgb

# Images in order of sample count (the report's rows follow it), Mitsuba's then penumbra's.
images=()
for renderer in mitsuba/mitsuba penumbra/penumbra-uniform; do
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
rm -rf results/peers.new
cp -r "$work/judged" results/peers.new
rm -rf results/peers
mv results/peers.new results/peers
echo "wrote results/peers"
