#!/usr/bin/env bash
# Through-light of thin skin against the path tracer (docs/pathtraced.md, "Through-light: calibration"):
# builtin:ear (a skin fin lit from behind) at fin thicknesses 1 and 2 mm (THICKNESSES), rendered by `pathtraced`,
# by the object-space `reference` (2 mm edges; its through-light gain 1, 0 and the default) and by `separable` without and with screen-space transmittance at
# several `transmittance.translucency` values (TRANSLUCENCIES); prints the mean skin diffuse (R, G, B) of each,
# i.e. the diffuse averaged over the skin pixels weighted by mask.Y (a mean over thousands of pixels: the path
# tracer's per-pixel noise averages out), fits the reference's per-channel through-light gain
# (sss.reference_through_gain) to the path tracer, and writes OUT_DIR/transmittance-calibration.md.
#
#   scripts/transmittance-calibration.sh [OUT_DIR] [SIZE] [SAMPLES]     (defaults: out/transmittance 96 64)
#
# Environment: SKINLAB (default build/release/cli/skinlab), THICKNESSES (default "1.0 2.0"), TRANSLUCENCIES
# (default "0.5 0.7 0.8 0.9 0.95"). Needs blender, oiiotool and python3. Every scene key is written out below.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-out/transmittance}"
size="${2:-96}"
samples="${3:-64}"
skinlab="${SKINLAB:-$root/build/release/cli/skinlab}"
[ -x "$skinlab" ] || { echo "transmittance-calibration: $skinlab not found (build it: scripts/build.sh, or set SKINLAB)" >&2; exit 2; }
for program in oiiotool python3 blender; do
  command -v "$program" > /dev/null || { echo "transmittance-calibration: $program not found" >&2; exit 2; }
done
mkdir -p "$out"

source "$root/scripts/lib/validation-scenes.sh"  # ear_scene (with common_tail)

# Mask-weighted mean skin diffuse: Σ diffuse · mask.Y / Σ mask.Y, by oiiotool.
skin_mean() {
  python3 - "$1" <<'PYTHON'
import re, subprocess, sys
def means(*args):
    text = subprocess.run(["oiiotool", *args, "--printstats"], check=True, capture_output=True, text=True).stdout
    return [float(v) for v in re.search(r"Stats Avg: (.*?) \(float\)", text).group(1).split()]
exr = sys.argv[1]
area = means(exr, "--ch", "mask.Y")[0]
lit = means(exr, "--ch", "diffuse.R,diffuse.G,diffuse.B", exr, "--ch", "mask.Y,mask.Y,mask.Y", "--mul")
print(" ".join(f"{v / area:.4f}" for v in lit))
PYTHON
}

lines=("| thickness | render | mean skin diffuse R | G | B |" "|---|---|---|---|---|")
for t in ${THICKNESSES:-1.0 2.0}; do
  scene="$out/ear-$t.toml"
  ear_scene "$t" > "$scene"
  runs=("pathtraced|sss.method=\"pathtraced\""
        "reference, through gain 1|sss.method=\"reference\" sss.reference_edge_mm=2.0 sss.reference_through_gain=[1.0,1.0,1.0]"
        "reference, through gain 0|sss.method=\"reference\" sss.reference_edge_mm=2.0 sss.reference_through_gain=[0.0,0.0,0.0]"
        "reference|sss.method=\"reference\" sss.reference_edge_mm=2.0"
        "separable|sss.method=\"separable\"")
  for tr in ${TRANSLUCENCIES:-0.5 0.7 0.8 0.9 0.95}; do
    runs+=("separable + transmittance $tr|sss.method=\"separable\" transmittance.enabled=true transmittance.translucency=$tr")
  done
  for run in "${runs[@]}"; do
    name="${run%%|*}"
    args=()
    for o in ${run#*|}; do args+=(--set "$o"); done
    exr="$out/ear-$t-$(echo "$name" | tr ' +' '__').exr"
    start=$SECONDS
    [ -e "$exr" ] || "$skinlab" render --scene "$scene" "${args[@]}" -o "$exr" > /dev/null
    m="$(skin_mean "$exr")"
    echo "transmittance-calibration: $t mm, $name: $m ($((SECONDS - start)) s)" >&2
    lines+=("| $t mm | $name | ${m// / | } |")
  done
done
# The reference's through-light gain that matches the path tracer, per channel, least squares over the thicknesses:
# the reference's skin mean is F + g·B (F: gain 0, the near side's light; B: gain 1 minus gain 0, the far side's).
fit="$(python3 - "${lines[@]}" <<'PYTHON'
import sys
rows = {}
for line in sys.argv[1:]:
    cells = [c.strip() for c in line.strip("|").split("|")]
    if len(cells) == 5 and cells[0].endswith("mm"):
        rows.setdefault(cells[0], {})[cells[1]] = [float(v) for v in cells[2:]]
gains = []
for c in range(3):
    num = den = 0.0
    for r in rows.values():
        near, far = r["reference, through gain 0"][c], r["reference, through gain 1"][c] - r["reference, through gain 0"][c]
        num += (r["pathtraced"][c] - near) * far
        den += far * far
    gains.append(num / den if den > 0 else 1.0)
print("fitted through gain (R, G, B): " + ", ".join(f"{g:.3f}" for g in gains))
for t, r in rows.items():
    near = r["reference, through gain 0"]
    far = [a - b for a, b in zip(r["reference, through gain 1"], near)]
    fitted = [n + g * f for n, g, f in zip(near, gains, far)]
    print(f"{t}: reference with the fitted gain " + ", ".join(f"{v:.4f}" for v in fitted) + " against pathtraced " +
          ", ".join(f"{v:.4f}" for v in r["pathtraced"]) + " (" +
          ", ".join(f"{100 * (v / p - 1):+.1f} %" for v, p in zip(fitted, r["pathtraced"])) + ")")
PYTHON
)"
lines+=("" "$fit")
printf '%s\n' "${lines[@]}" > "$out/transmittance-calibration.md.tmp"
mv "$out/transmittance-calibration.md.tmp" "$out/transmittance-calibration.md"
cat "$out/transmittance-calibration.md"
