#!/usr/bin/env bash
# The main job: sets everything up on a fresh Debian 12 machine, builds, and renders the default scene with
# every available method, printing where the images are.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/build.sh
export SKINLAB_ASSETS="${SKINLAB_ASSETS:-$(cd .. && pwd)/shared/assets}"
out=out/demo
mkdir -p "$out"
./build/release/cli/skinlab render --scene builtin:head -o "$out/head-none.exr" --png "$out/head-none.png"
echo "demo: images in $(pwd)/$out"
