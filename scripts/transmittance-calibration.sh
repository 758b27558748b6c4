#!/usr/bin/env bash
# Through-light of thin skin against the path tracer (docs/pathtraced.md, "Through-light: calibration"):
# builtin:ear (a skin fin lit from behind) at fin thicknesses 1, 2, 2.5 and 4 mm (THICKNESSES), rendered by
# `pathtraced` (SEEDS seeds, averaged), by the object-space `reference` (2 mm edges; its through-light gain 0, 1,
# the constant gain [1.72, 5.31, 9.44] fitted at 1 and 2 mm alone, the default, and gain 1 with growth k on a grid
# of K_GRID values) and by `separable` without and with screen-space transmittance at several
# `transmittance.translucency` values (TRANSLUCENCIES); prints the mean skin diffuse (R, G, B)
# of each, i.e. the diffuse averaged over the skin pixels weighted by mask.Y (a mean over thousands of pixels: the
# path tracer's per-pixel noise averages out), fits the reference's far-side kernel gain_c · exp(k_c d²)
# (sss.reference_through_gain, sss.reference_through_growth_per_mm2) to the path tracer (below), renders the
# reference with the fitted values at every thickness, and writes OUT_DIR/transmittance-calibration.md (the table,
# the fitted values and each channel's residuals). Rerunning reuses the EXRs already in OUT_DIR (delete the
# `*reference_default*` ones after changing the defaults).
#
#   scripts/transmittance-calibration.sh [OUT_DIR] [SIZE] [SAMPLES]     (defaults: out/transmittance 96 64)
#
# Environment: SKINLAB (default build/release/cli/skinlab), THICKNESSES (default "1.0 2.0 2.5 4.0"), SEEDS (path-traced
# seeds 0 … SEEDS−1, default 4), TRANSLUCENCIES (default "0.5 0.91"), K_GRID (growth values in 1/mm², default
# −0.30 … −0.12 in steps of 0.02, −0.10 … 0.06 in steps of 0.005). Needs blender, oiiotool and python3. Every scene
# key is written out below.
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
thicknesses="${THICKNESSES:-1.0 2.0 2.5 4.0}"
seeds="${SEEDS:-4}"
k_grid="${K_GRID:-$(python3 -c 'print(" ".join([f"{-0.30 + 0.02 * i:.2f}" for i in range(10)] + [f"{-0.10 + 0.005 * i:.3f}" for i in range(33)]))')}"

source "$root/scripts/lib/validation-scenes.sh"  # ear_scene (with common_tail)

# Mask-weighted mean skin diffuse of each EXR, one line each: Σ diffuse · mask.Y / Σ mask.Y, by oiiotool.
skin_means() {
  python3 - "$@" <<'PYTHON'
import re, subprocess, sys
def means(*args):
    text = subprocess.run(["oiiotool", *args, "--printstats"], check=True, capture_output=True, text=True).stdout
    return [float(v) for v in re.search(r"Stats Avg: (.*?) \(float\)", text).group(1).split()]
for exr in sys.argv[1:]:
    area = means(exr, "--ch", "mask.Y")[0]
    lit = means(exr, "--ch", "diffuse.R,diffuse.G,diffuse.B", exr, "--ch", "mask.Y,mask.Y,mask.Y", "--mul")
    print(" ".join(f"{v / area:.6f}" for v in lit))
PYTHON
}

# render NAME THICKNESS SET... : renders the ear scene at THICKNESS with the --set overrides (once: an existing EXR is
# reused) and prints its mean skin diffuse.
render() {
  local name="$1" t="$2"; shift 2
  local args=() exr
  for o in "$@"; do args+=(--set "$o"); done
  exr="$out/ear-$t-$(echo "$name" | tr ' +=,' '____').exr"
  local start=$SECONDS
  [ -e "$exr" ] || "$skinlab" render --scene "$out/ear-$t.toml" "${args[@]}" -o "$exr" > /dev/null
  local m
  m="$(skin_means "$exr")"
  echo "transmittance-calibration: $t mm, $name: $m ($((SECONDS - start)) s)" >&2
  echo "$m"
}

ref=('sss.method="reference"' sss.reference_edge_mm=2.0)
data="$out/data.txt"  # THICKNESS|NAME|R G B, the input of the fit
: > "$data"
for t in $thicknesses; do
  ear_scene "$t" > "$out/ear-$t.toml"
  exrs=()
  for s in $(seq 0 $((seeds - 1))); do
    echo "$t|pathtraced seed $s|$(render "pathtraced seed $s" "$t" 'sss.method="pathtraced"' "pathtraced.seed=$s")" >> "$data"
    exrs+=("$out/ear-$t-pathtraced_seed_$s.exr")
  done
  echo "$t|pathtraced|$(skin_means "${exrs[@]}" | awk '{r += $1; g += $2; b += $3} END {printf "%.6f %.6f %.6f", r / NR, g / NR, b / NR}')" >> "$data"
  echo "$t|reference, through gain 0|$(render "reference gain 0" "$t" "${ref[@]}" 'sss.reference_through_gain=[0.0,0.0,0.0]')" >> "$data"
  echo "$t|reference, through gain 1|$(render "reference gain 1" "$t" "${ref[@]}" 'sss.reference_through_gain=[1.0,1.0,1.0]' 'sss.reference_through_growth_per_mm2=[0.0,0.0,0.0]')" >> "$data"
  echo "$t|reference, constant gain (1 and 2 mm fit)|$(render "reference constant gain" "$t" "${ref[@]}" 'sss.reference_through_gain=[1.72,5.31,9.44]' 'sss.reference_through_growth_per_mm2=[0.0,0.0,0.0]')" >> "$data"
  echo "$t|reference (default)|$(render "reference default" "$t" "${ref[@]}")" >> "$data"
  for k in $k_grid; do
    echo "$t|growth $k|$(render "reference gain 1 growth $k" "$t" "${ref[@]}" 'sss.reference_through_gain=[1.0,1.0,1.0]' "sss.reference_through_growth_per_mm2=[$k,$k,$k]")" >> "$data"
  done
  echo "$t|separable|$(render "separable" "$t" 'sss.method="separable"')" >> "$data"
  for tr in ${TRANSLUCENCIES:-0.5 0.91}; do
    echo "$t|separable + transmittance $tr|$(render "separable transmittance $tr" "$t" 'sss.method="separable"' transmittance.enabled=true "transmittance.translucency=$tr")" >> "$data"
  done
done

# The fit, per channel: for every k of the grid, the gain g that matches the path tracer in the least-squares sense
# over the thicknesses, on relative errors (the reference's skin mean is F + g·B_k, F: gain 0, the near side's light;
# B_k: gain 1 and growth k, minus F, the far side's light); the k with the smallest residual, and its g. A growth is
# kept only where it lowers the rms residual of the constant gain (k = 0) by more than twice the path tracer's own
# standard error (the seeds' standard deviation over √SEEDS, relative, rms over the thicknesses); otherwise k = 0.
python3 - "$data" > "$out/fit.txt" <<'PYTHON'
import math, sys
rows = {}
for line in open(sys.argv[1]):
    t, name, values = line.rstrip("\n").split("|")
    rows.setdefault(t, {})[name] = [float(v) for v in values.split()]
ts = list(rows)
grid = {float(n.split()[1]): n for n in rows[ts[0]] if n.startswith("growth ")}  # k → its row's name
def far(t, k, c):  # B_k: the far side's light at gain 1 and growth k
    return rows[t][grid[k]][c] - rows[t]["reference, through gain 0"][c]
def residuals(g, k, c):  # relative errors of F + g·B_k against the path tracer, per thickness
    return [(rows[t]["reference, through gain 0"][c] + g * far(t, k, c)) / rows[t]["pathtraced"][c] - 1 for t in ts]
def noise(c):  # rms over the thicknesses of the relative standard error of the seeds' mean
    errors = []
    for t in ts:
        seeds = [v[c] for n, v in rows[t].items() if n.startswith("pathtraced seed ")]
        if len(seeds) < 2: return 0.0
        m = sum(seeds) / len(seeds)
        sd = math.sqrt(sum((x - m) ** 2 for x in seeds) / (len(seeds) - 1))
        errors.append(sd / math.sqrt(len(seeds)) / m)
    return math.sqrt(sum(e * e for e in errors) / len(errors))
def fit_at(k, c):  # (rms, k, g): the least-squares gain at growth k
    x = [far(t, k, c) / rows[t]["pathtraced"][c] for t in ts]
    y = [1 - rows[t]["reference, through gain 0"][c] / rows[t]["pathtraced"][c] for t in ts]
    if not any(x): return None
    g = sum(a * b for a, b in zip(x, y)) / sum(a * a for a in x)
    return (math.sqrt(sum(e * e for e in residuals(g, k, c)) / len(ts)), k, g)
fit, notes = [], []
for c in range(3):
    best = min(f for f in (fit_at(k, c) for k in grid) if f)
    constant = fit_at(0.0, c)
    kept = best if constant is None or constant[0] - best[0] > 2 * noise(c) else constant
    fit.append(kept)
    notes.append(f"growth {best[1]:g} lowers the rms from {100 * constant[0]:.2f} % (k = 0) to {100 * best[0]:.2f} %, "
                 f"twice the path tracer's standard error {200 * noise(c):.2f} %: " + ("kept" if kept is best else "k = 0"))
print("gain " + " ".join(f"{g:.4g}" for _, _, g in fit))
print("growth " + " ".join(f"{k:g}" for _, k, _ in fit))
for c, (rms, k, g) in enumerate(fit):
    print(f"# channel {'RGB'[c]}: gain {g:.4f}, growth {k:g} /mm², rms {100 * rms:.2f} %, residuals " +
          ", ".join(f"{t} mm {100 * e:+.1f} %" for t, e in zip(ts, residuals(g, k, c))) + f" ({notes[c]})")
PYTHON
gain="$(sed -n 's/^gain //p' "$out/fit.txt" | tr ' ' ',')"
growth="$(sed -n 's/^growth //p' "$out/fit.txt" | tr ' ' ',')"
for t in $thicknesses; do
  echo "$t|reference, fitted|$(render "reference fitted $gain $growth" "$t" "${ref[@]}" "sss.reference_through_gain=[$gain]" "sss.reference_through_growth_per_mm2=[$growth]")" >> "$data"
done

# The table: every render but the grid, and each reference's level against the path tracer's.
python3 - "$data" "$out/fit.txt" > "$out/transmittance-calibration.md.tmp" <<'PYTHON'
import sys
rows = {}
for line in open(sys.argv[1]):
    t, name, values = line.rstrip("\n").split("|")
    rows.setdefault(t, {})[name] = [float(v) for v in values.split()]
print("| thickness | render | mean skin diffuse R | G | B | against pathtraced (R, G, B) |")
print("|---|---|---|---|---|---|")
for t, r in rows.items():
    for name, v in r.items():
        if name.startswith("growth ") or name.startswith("pathtraced seed "): continue
        against = "" if name == "pathtraced" else ", ".join(f"{100 * (a / p - 1):+.1f} %" for a, p in zip(v, r["pathtraced"]))
        print(f"| {t} mm | {name} | " + " | ".join(f"{x:.4f}" for x in v) + f" | {against} |")
print()
for line in open(sys.argv[2]):
    print(line.rstrip().lstrip("# "))
PYTHON
mv "$out/transmittance-calibration.md.tmp" "$out/transmittance-calibration.md"
cat "$out/transmittance-calibration.md"
