#!/usr/bin/env bash
# The rasterizer against Cycles on every built-in scene (docs/pathtraced.md, "Rasterizer and Cycles"): for each
# scene, `none` against `pathtraced` with SSS off, at SIZE² (default 128) and SAMPLES (default 64):
#   full    — Cycles as configured by default (bounces 8, specular on, SSS off)
#   direct  — Cycles with max_bounces = 0 (no interreflection; the environment still with its visibility)
#   agree   — direct, Cycles' specular lobe off and the environment unshadowed (pathtraced.environment_shadow =
#             false), like the rasterizer's ambient term; compare the diffuse layers (the rasterizer's specular is a
#             separate layer that does not touch its diffuse)
# Prints scripts/exr-skin-stats.py's table for each pair.
# Usage: scripts/pathtraced-compare.sh OUT_DIR [SIZE] [SAMPLES] [SCENES...]
set -euo pipefail
out=${1:?usage: pathtraced-compare.sh OUT_DIR [SIZE] [SAMPLES] [SCENES...]}
size=${2:-128}
samples=${3:-64}
shift $(( $# < 3 ? $# : 3 ))
scenes=("$@")
[ ${#scenes[@]} -eq 0 ] && scenes=(halo bleed ear head)
here=$(cd "$(dirname "$0")" && pwd)
skinlab=${SKINLAB:-$here/../build/release/cli/skinlab}
mkdir -p "$out"
r() { "$skinlab" render --width "$size" --height "$size" "$@" >/dev/null; }
for s in "${scenes[@]}"; do
  scene=builtin:$s
  r --scene "$scene" --method none -o "$out/$s-none.exr"
  r --scene "$scene" --method pathtraced --set pathtraced.samples="$samples" --set pathtraced.sss=false -o "$out/$s-pt-full.exr"
  r --scene "$scene" --method pathtraced --set pathtraced.samples="$samples" --set pathtraced.sss=false \
    --set pathtraced.max_bounces=0 -o "$out/$s-pt-direct.exr"
  r --scene "$scene" --method pathtraced --set pathtraced.samples="$samples" --set pathtraced.sss=false \
    --set pathtraced.max_bounces=0 --set pathtraced.specular=false --set pathtraced.environment_shadow=false \
    -o "$out/$s-pt-agree.exr"
  echo "== $scene: none vs Cycles, SSS off (full)"; python3 "$here/exr-skin-stats.py" "$out/$s-none.exr" "$out/$s-pt-full.exr"
  echo "== $scene: none vs Cycles, SSS off, no bounces (direct)"; python3 "$here/exr-skin-stats.py" "$out/$s-none.exr" "$out/$s-pt-direct.exr"
  echo "== $scene: none vs Cycles, SSS off, no bounces, specular off, environment unshadowed (agree: compare diffuse)"
  python3 "$here/exr-skin-stats.py" "$out/$s-none.exr" "$out/$s-pt-agree.exr"
done
