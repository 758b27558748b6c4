#!/usr/bin/env bash
# Blender EEVEE (`sss.method = "eevee"`) beside skinlab's own SSS methods on the same scene (docs/benchmarks.md,
# "EEVEE beside skinlab's methods"): one `skinlab render --timings` per method and size, each a fresh process, as a
# stimulus build runs them.
#   skinlab's methods: the SSS stage (GPU ms, GL_TIME_ELAPSED), the frame's passes (wall ms) and the whole command.
#   eevee: EEVEE's render call as timed inside Blender (shader compilation and every TAA sample), the whole Blender
#   run (start-up, scene building, render, EXR write) and the whole command (plus skinlab's passes for the AOVs).
#   EEVEE is run at eevee.taa_samples = 1 and = TAA (default 16): (render_TAA − render_1) / (TAA − 1) is the cost
#   of one more EEVEE frame, SSS included, without compilation.
# Usage: bench/render/bench_blender_methods.sh SKINLAB [SCENE=builtin:head] [SIZES="640x360 1280x720"] [TAA=16]
# Prints a Markdown table and writes blender-methods.csv in the current folder. Exits 77 when blender is missing.
set -euo pipefail
SKINLAB=$(readlink -f "$1")
SCENE=${2:-builtin:head}
SIZES=${3:-"640x360 1280x720"}
TAA=${4:-16}
command -v blender >/dev/null || { echo "SKIPPED: blender not found (scripts/install-deps.sh installs it)"; exit 77; }
WORK=$(mktemp -d "${TMPDIR:-/tmp}/skinlab-bench-blender.XXXXXX")
trap 'rm -rf "$WORK"' EXIT

echo "machine: $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg) at the start, $(date -u +%Y-%m-%dT%H:%M:%SZ)"
echo "size,method,sss_gpu_ms,passes_wall_ms,blender_render_ms,blender_wall_ms,command_ms" > "$WORK/rows.csv"
run() {  # run SIZE LABEL ARGS...
  local size=$1 label=$2; shift 2
  local w=${size%x*} h=${size#*x}
  local t0 t1
  t0=$(date +%s%N)
  "$SKINLAB" render --scene "$SCENE" --set "render.width=$w" --set "render.height=$h" "$@" \
    --timings "$WORK/t.json" -o "$WORK/out.exr" > /dev/null
  t1=$(date +%s%N)
  python3 - "$WORK/t.json" "$size" "$label" "$(( (t1 - t0) / 1000000 ))" >> "$WORK/rows.csv" <<'PYTHON'
import json, sys
t = json.load(open(sys.argv[1]))
blender = t.get("eevee", {})
print(",".join([sys.argv[2], sys.argv[3], f"{t['passes'].get('sss', 0):.1f}", f"{t['wall_total']:.1f}",
                f"{blender.get('render', 0):.0f}", f"{blender.get('blender_wall', 0):.0f}", sys.argv[4]]))
PYTHON
}
for size in $SIZES; do
  for method in none gaussian-sum separable artistic pscbf; do
    run "$size" "$method" --method "$method"
  done
  run "$size" "eevee (TAA 1)" --method eevee --set eevee.taa_samples=1
  run "$size" "eevee (TAA $TAA)" --method eevee --set "eevee.taa_samples=$TAA"
done
cp "$WORK/rows.csv" blender-methods.csv
python3 - "$WORK/rows.csv" "$TAA" <<'PYTHON'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
taa = int(sys.argv[2])
print("| size | method | SSS stage GPU ms | skinlab passes wall ms | EEVEE render s | Blender run s | command s |")
print("|---|---|---|---|---|---|---|")
for r in rows:
    eevee = r["method"].startswith("eevee")
    cells = [r["size"], r["method"], "–" if eevee else r["sss_gpu_ms"], r["passes_wall_ms"],
             f"{float(r['blender_render_ms']) / 1000:.1f}" if eevee else "–",
             f"{float(r['blender_wall_ms']) / 1000:.1f}" if eevee else "–", f"{float(r['command_ms']) / 1000:.1f}"]
    print("| " + " | ".join(cells) + " |")
for size in dict.fromkeys(r["size"] for r in rows):
    one = next(float(r["blender_render_ms"]) for r in rows if r["size"] == size and r["method"] == "eevee (TAA 1)")
    many = next(float(r["blender_render_ms"]) for r in rows if r["size"] == size and r["method"] == f"eevee (TAA {taa})")
    print(f"{size}: one more EEVEE frame (TAA sample, SSS included) {(many - one) / (taa - 1):.0f} ms; "
          f"EEVEE compilation and first frame {one:.0f} ms")
PYTHON
