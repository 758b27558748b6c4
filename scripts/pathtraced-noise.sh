#!/usr/bin/env bash
# Noise of the pathtraced method against a high-sample render of the same scene (docs/pathtraced.md, "Noise"):
# renders SCENE at SIZE² with each of SAMPLES... and with REF_SAMPLES, and prints the mean absolute difference of
# the skin diffuse layer relative to its mean (scripts/exr-skin-stats.py) with Cycles' render time.
# Usage: scripts/pathtraced-noise.sh OUT_DIR SCENE SIZE REF_SAMPLES SAMPLES...
set -euo pipefail
out=${1:?usage: pathtraced-noise.sh OUT_DIR SCENE SIZE REF_SAMPLES SAMPLES...}
scene=$2 size=$3 reference=$4
shift 4
here=$(cd "$(dirname "$0")" && pwd)
skinlab=${SKINLAB:-$here/../build/release/cli/skinlab}
mkdir -p "$out"
name=$(basename "$scene" .toml | tr ':' '-')
render() {
  "$skinlab" render --scene "$scene" --method pathtraced --width "$size" --height "$size" \
    --set pathtraced.samples="$1" --set pathtraced.seed="$2" -o "$out/$name-$1-$2.exr" --timings "$out/$name-$1-$2.json" >/dev/null
  python3 -c "import json,sys; t=json.load(open(sys.argv[1]))['pathtraced']; print('samples %s seed %s: Cycles %.1f s, Blender run %.1f s' % (sys.argv[2], sys.argv[3], t['render']/1000, t['blender_wall']/1000))" \
    "$out/$name-$1-$2.json" "$1" "$2"
}
render "$reference" 1
for s in "$@"; do
  render "$s" 0
  echo "samples $s against $reference:"
  python3 "$here/exr-skin-stats.py" "$out/$name-$reference-1.exr" "$out/$name-$s-0.exr" | grep 'mean |B-A|'
done
