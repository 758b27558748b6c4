#!/usr/bin/env bash
# Validation of the object-space `reference` method against the path-traced one (docs/pathtraced.md, "Reference
# validation"). For each case — builtin:halo with a skin backdrop at depth gaps 5 and 200 mm, builtin:bleed with the
# paint inside the skin mask (references: the true materials), builtin:ear, builtin:head and (with SKINLAB_ASSETS)
# the scanned head — it renders
#   - the 24 screen-space conditions of the evaluation table (gaussian-sum, separable, artistic, pscbf × none,
#     follow-surface, +cbf, +lab_weight, +curvature reduce-floor, all) and the `reference` render (1 mm edges, 0.5 mm on bleed; light at non-skin neighbours absorbed) as a
#     stimulus set;
#   - `pathtraced` with seeds 0 … SEEDS−1 (default 4; seed 1 against seed 0 measures the path tracer's own noise on
#     every score, and all of them give the debiased scores below), with
#     no interreflection, the rasterizer's specular layer and the environment unshadowed (as the rasterizer's
#     ambient term), so that the two references differ in the subsurface transport only;
# and scores, with `skinlab analyze metrics` (the bands of docs/metrics.md, from each reference's depth and mask):
#   - every condition against `reference` and against `pathtraced`;
#   - `reference` against `pathtraced` (the per-band disagreement), and `pathtraced` seed 1 against seed 0 (noise);
#   - every condition against the noise-free path-traced image (`--reference-seeds`, pairs of seeds, jackknife
#     errors) and its ranking against `reference`'s (`--compare-reference`: Kendall's τ_b with its t jackknife and
#     bootstrap intervals, over all conditions, the 16 closest to Cycles and all but the clearly worse; in Y, R, G, B
#     and CIELAB), and the evaluation table's scores against `reference` ranked against Cycles' (`--compare-metrics`).
# The table: per case and band, the leak energy and mean ΔE00 of `reference` against `pathtraced` next to the
# path tracer's own; and per case and score, Kendall's τ_b between the rankings of the 24 conditions under the
# two references.
# The scanned head's stimuli are lit with its HDR environment integrated exactly (environment.irradiance = "exact",
# as Cycles integrates it), and the table gives its ear rim's level against Cycles'.
#
#   scripts/reference-validation.sh [OUT_DIR] [SIZE] [SAMPLES]       (defaults: out/reference-validation 256 64)
#
# Environment: SKINLAB (default build/release/cli/skinlab), SEEDS (path-traced seeds, default 4, at least 2),
# TRUTH_SEEDS and TRUTH_SAMPLES (the path-traced truth of the error metrics, truth.exr: with TRUTH_SEEDS ≥ 2 the mean
# of that many renders of its own at TRUTH_SAMPLES samples, measured against the SEEDS seeds, independent of it;
# with TRUTH_SEEDS=0 the mean of the SEEDS seeds. Default: on head 10 and on scan 18 renders of 384 samples, the
# precision docs/pathtraced.md measures as enough to rank with; on the other cases 0),
# REFERENCE_EDGE_MM (the reference's tessellation, default 1.0 mm, 0.5 mm on bleed, whose paint edge needs it), REFERENCE_NON_SKIN (sss.reference_non_skin of
# the reference: default "absorbs", the path tracer's boundary; "returns" is the evaluation table's),
# REFERENCE_CONVEXITY_MM (sss.reference_convexity_mm: default [0.88, 0.32, 0.28], the path tracer's level on convex
# skin; [0, 0, 0] is the evaluation table's), HEAD_SKIN_DETAIL (builtin:head's model.skin_detail, default true;
# false gives the smooth head), EAR_KEY_LIGHT (builtin:ear's key light: back, the default, shows the through-light;
# front does not), SKIN_TONE (a [skin] tone level "I" … "VI" for every case; builtin:head's skin then takes the
# tone's albedo, the scan's map is re-toned; docs/skin-tones.md), SKINLAB_ASSETS (without the scanned head its case is
# skipped with a message), CASES (a space-separated subset of: halo-5 halo-200 bleed ear head scan).
# Every scene key that matters is written out below (model, materials, camera, lights, environment, SSS width,
# the path tracer's settings), so the numbers do not move with the built-in scenes' defaults. Rerunning resumes:
# stimuli and path-traced images already rendered with the same parameters are not rendered again.
# Writes OUT_DIR/reference-validation.md (atomically) and, per case, OUT_DIR/CASE/{*.toml,set/,pathtraced*.exr,
# metrics-*/}.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-out/reference-validation}"
size="${2:-256}"
samples="${3:-64}"
seeds="${SEEDS:-4}"
if [ -n "${TRUTH_SEEDS:-}" ]; then
  [ "$TRUTH_SEEDS" -ge 0 ] 2>/dev/null && [ "$TRUTH_SEEDS" -ne 1 ] || { echo "reference-validation: TRUTH_SEEDS=$TRUTH_SEEDS must be 0 or at least 2" >&2; exit 2; }
fi
if [ -n "${TRUTH_SAMPLES:-}" ]; then
  [ "$TRUTH_SAMPLES" -ge 1 ] 2>/dev/null || { echo "reference-validation: TRUTH_SAMPLES=$TRUTH_SAMPLES must be a positive number" >&2; exit 2; }
fi
# The truth's renders per case: TRUTH_SEEDS if given, else 10 on head and 18 on scan (at 384 samples; their measured
# precision, docs/pathtraced.md "The truth of the error metrics") and 0 (the mean of the SEEDS seeds) elsewhere.
truth_seeds_of() {
  if [ -n "${TRUTH_SEEDS:-}" ]; then echo "$TRUTH_SEEDS"; else case "$1" in head) echo 10 ;; scan) echo 18 ;; *) echo 0 ;; esac; fi
}
truth_samples_of() {
  if [ -n "${TRUTH_SAMPLES:-}" ]; then echo "$TRUTH_SAMPLES"; elif [ -z "${TRUTH_SEEDS:-}" ]; then echo 384; else echo "$samples"; fi
}
# The reference's edge length per case: REFERENCE_EDGE_MM for all, or 1 mm and 0.5 mm on bleed (the paint's edge).
edge_mm_of() { if [ -n "${REFERENCE_EDGE_MM:-}" ]; then echo "$REFERENCE_EDGE_MM"; elif [ "$1" = bleed ]; then echo 0.5; else echo 1.0; fi; }
edge_mm="${REFERENCE_EDGE_MM:-1.0 (bleed: 0.5)}"
non_skin="${REFERENCE_NON_SKIN:-absorbs}"
convexity="${REFERENCE_CONVEXITY_MM:-[0.88, 0.32, 0.28]}"
head_detail="${HEAD_SKIN_DETAIL:-true}"
ear_light="${EAR_KEY_LIGHT:-back}"
case "$ear_light" in back|front) ;; *) echo "reference-validation: EAR_KEY_LIGHT=$ear_light must be back or front" >&2; exit 2 ;; esac
case "$head_detail" in true|false) ;; *) echo "reference-validation: HEAD_SKIN_DETAIL=$head_detail must be true or false" >&2; exit 2 ;; esac
[ "$seeds" -ge 2 ] 2>/dev/null || { echo "reference-validation: SEEDS=$seeds must be at least 2" >&2; exit 2; }
skinlab="${SKINLAB:-$root/build/release/cli/skinlab}"
[ -x "$skinlab" ] || { echo "reference-validation: $skinlab not found (build it: scripts/build.sh, or set SKINLAB)" >&2; exit 2; }
command -v python3 > /dev/null || { echo "reference-validation: python3 is needed to write the table" >&2; exit 2; }
command -v "${BLENDER:-blender}" > /dev/null || { echo "reference-validation: blender not found (Debian package blender)" >&2; exit 2; }
mkdir -p "$out"
out="$(cd "$out" && pwd)"

cases="${CASES:-halo-5 halo-200 bleed ear head scan}"
if [[ " $cases " == *" scan "* ]] && { [ -z "${SKINLAB_ASSETS:-}" ] || [ ! -e "$SKINLAB_ASSETS/LeePerrySmith/LeePerrySmith.glb" ]; }; then
  echo "reference-validation: scanned head skipped (\$SKINLAB_ASSETS/LeePerrySmith/LeePerrySmith.glb not found)" >&2
  cases="${cases/scan/}"
fi

source "$root/scripts/lib/validation-scenes.sh"  # common_tail, ear_scene

# halo_scene GAP: builtin:halo with the backdrop made skin (as renderer/scenes/evaluation/halo-skin-backdrop.toml).
halo_scene() {
  cat <<EOF
mm_per_unit = 1.0

[model]
source = "builtin:halo"
depth_gap_mm = $1

[[materials]]
name = "skin"
albedo = [0.60, 0.42, 0.34]
skin = true
glossiness = 0.6
specular_intensity = 1.0

[[materials]]
name = "backdrop"
albedo = [0.5, 0.5, 0.5]
skin = true
glossiness = 0.3
specular_intensity = 1.0

[camera]
view = "explicit"
position = [0.0, 0.0, 300.0]
target = [0.0, 0.0, 0.0]
up = [0.0, 1.0, 0.0]
fov_deg = 30.0

[[lights]]
type = "directional"
direction = [0.45, -0.45, -0.77]
color = [1.0, 0.97, 0.92]
intensity = 1.2
shadow = false

[environment]
radiance = [0.08, 0.085, 0.1]
intensity = 1.0
background = "color"
background_color = [0.02, 0.02, 0.02]
EOF
  common_tail
}

# bleed_scene PAINT_IS_SKIN: builtin:bleed; true for the screen-space renders (a mask coarser than the material),
# false for the references (the true materials, so the bands come from the true mask).
bleed_scene() {
  cat <<EOF
mm_per_unit = 1.0

[model]
source = "builtin:bleed"

[[materials]]
name = "skin"
albedo = [0.60, 0.42, 0.34]
skin = true
glossiness = 0.6
specular_intensity = 1.0

[[materials]]
name = "paint-dark"
albedo = [0.02, 0.02, 0.02]
skin = $1
glossiness = 0.3
specular_intensity = 1.0

[[materials]]
name = "paint-bright"
albedo = [0.05, 0.6, 0.8]
skin = $1
glossiness = 0.3
specular_intensity = 1.0

[camera]
view = "mid"
fov_deg = 30.0
yaw_deg = 0.0
pitch_deg = 0.0

[[lights]]
type = "directional"
direction = [0.2, -0.25, -0.95]
color = [1.0, 1.0, 1.0]
intensity = 1.0
shadow = false

[environment]
radiance = [0.1, 0.1, 0.1]
intensity = 1.0
background = "color"
background_color = [0.02, 0.02, 0.02]
EOF
  common_tail
}

head_scene() {
  # With SKIN_TONE the skin material takes the tone's albedo (no albedo of its own) and [skin] is written.
  local albedo_line='albedo = [0.60, 0.42, 0.34]'
  [ -n "${SKIN_TONE:-}" ] && albedo_line='# albedo: the [skin] tone'"'"'s'
  cat <<EOF
mm_per_unit = 1.0

[model]
source = "builtin:head"
skin_detail = ${head_detail}

[[materials]]
name = "skin"
$albedo_line
skin = true
glossiness = 0.5
specular_intensity = 1.0

[[materials]]
name = "eye"
albedo = [0.8, 0.78, 0.75]
skin = false
glossiness = 0.95
specular_intensity = 1.0

[camera]
view = "mid"
fov_deg = 30.0
yaw_deg = 20.0
pitch_deg = 0.0

[[lights]]
type = "spot"
position = [-500.0, 450.0, 700.0]
target = [0.0, 0.0, 40.0]
color = [1.0, 0.95, 0.88]
intensity = 1.6
shadow = true
inner_angle_deg = 15.0
outer_angle_deg = 25.0

[[lights]]
type = "directional"
direction = [-0.7, -0.1, -0.7]
color = [0.85, 0.9, 1.0]
intensity = 0.25
shadow = false

[environment]
radiance = [0.12, 0.125, 0.14]
intensity = 1.0
background = "color"
background_color = [0.03, 0.03, 0.035]
EOF
  common_tail
}

scan_scene() {
  cat <<EOF
mm_per_unit = 47.9

[model]
source = "assets:LeePerrySmith/LeePerrySmith.glb"
flip_v = true

[textures]
albedo = "assets:LeePerrySmith/Map-COL.jpg"
normal = "assets:LeePerrySmith/Infinite-Level_02_Tangent_SmoothUV.jpg"
specular = "assets:LeePerrySmith/Map-SPEC.jpg"
normal_strength = 1.0

[[materials]]
name = "*"
albedo = [1.0, 1.0, 1.0]
skin = true
glossiness = 0.5
specular_intensity = 1.0

[camera]
view = "close"
fov_deg = 30.0
yaw_deg = 20.0
pitch_deg = 0.0

[[lights]]
type = "directional"
direction = [0.55, -0.45, -0.7]
color = [1.0, 0.95, 0.88]
intensity = 1.2
shadow = true

[environment]
file = "assets:envmaps/royal_esplanade_1k.hdr"
intensity = 1.0
rotation_deg = 0.0
background = "environment"
EOF
  common_tail
}

# The rasterizer's environment light of a case's stimuli: the scanned head's HDR environment is integrated exactly
# (environment.irradiance = "exact"), as Cycles does; its 9 SH coefficients light the head's sides and the ear a fifth
# too bright (docs/pathtraced.md, "The ear rim and the environment light"). Constant environments keep the
# coefficients, exact there. Set here, not in the scene files, which the path-traced renders' stamps hold.
environment_fixed() { if [ "$1" = scan ]; then echo 'environment = { irradiance = "exact" }'; fi; }

# The 24 screen-space conditions of stimuli/specs/extensions-*.toml and the object-space reference.
set_spec() {  # set_spec NAME TEST_SCENE REF_SCENE
  cat <<EOF
[set]
name = "validation-$1"
description = "reference validation, $1: 24 screen-space conditions + the object-space reference"
seed = 4
block = ["scene"]

[fixed]
render = { width = $size, height = $size, exposure_ev = 0.0 }
tone_map = { operator = "filmic" }
$(environment_fixed "$1")

[[factor]]
name = "scene"
levels = ["$2"]
labels = ["$1"]

[[factor]]
name = "method"
levels = ["gaussian-sum", "separable", "artistic", "pscbf"]

[[factor]]
name = "sss.follow_surface"
levels = [false, true]
labels = ["none", "follow"]

[[reference]]
scene = "$3"
method = "reference"
sss.reference_edge_mm = $(edge_mm_of "$1")
sss.reference_non_skin = "$non_skin"
sss.reference_convexity_mm = [$convexity]  # one level: the array
EOF
  for method in gaussian-sum separable artistic pscbf; do
    beta=0.09; [ "$method" = gaussian-sum ] && beta=0.5
    printf '\n[[include]]\nmethod = "%s"\nsss.cbf = true\n' "$method"
    printf '\n[[include]]\nmethod = "%s"\nsss.lab_weight = %s\n' "$method" "$beta"
    printf '\n[[include]]\nmethod = "%s"\nsss.curvature = "reduce-floor"\n' "$method"
    printf '\n[[include]]\nmethod = "%s"\nsss.cbf = true\nsss.lab_weight = %s\nsss.curvature = "reduce-floor"\n' "$method" "$beta"
  done
}

# Renders with `skinlab render` unless the EXR exists with the same scene file and overrides (stamp file).
render_once() {  # render_once OUT.exr SCENE OVERRIDES...
  local exr="$1" scene="$2"; shift 2
  local stamp="$exr.inputs"
  local inputs; inputs="$(cat "$scene"; printf '%s\n' "$@")"
  if [ -e "$exr" ] && [ -e "$stamp" ] && [ "$(cat "$stamp")" = "$inputs" ]; then return 0; fi
  local start=$SECONDS args=()
  for o in "$@"; do args+=(--set "$o"); done
  "$skinlab" render --scene "$scene" "${args[@]}" -o "$exr" > /dev/null
  printf '%s' "$inputs" > "$stamp.tmp" && mv "$stamp.tmp" "$stamp"
  echo "reference-validation: $(basename "$(dirname "$exr")")/$(basename "$exr") in $((SECONDS - start)) s" >&2
}

ran=()
for name in $cases; do
  dir="$out/$name"
  mkdir -p "$dir"
  case "$name" in
    halo-5) halo_scene 5.0 > "$dir/test.toml"; cp "$dir/test.toml" "$dir/ref.toml" ;;
    halo-200) halo_scene 200.0 > "$dir/test.toml"; cp "$dir/test.toml" "$dir/ref.toml" ;;
    bleed) bleed_scene true > "$dir/test.toml"; bleed_scene false > "$dir/ref.toml" ;;
    ear) ear_scene 2.5 "$ear_light" > "$dir/test.toml"; cp "$dir/test.toml" "$dir/ref.toml" ;;
    head) head_scene > "$dir/test.toml"; cp "$dir/test.toml" "$dir/ref.toml" ;;
    scan) scan_scene > "$dir/test.toml"; cp "$dir/test.toml" "$dir/ref.toml" ;;
    *) echo "reference-validation: unknown case '$name' in CASES (halo-5 halo-200 bleed ear head scan)" >&2; exit 2 ;;
  esac
  set_spec "$name" "$dir/test.toml" "$dir/ref.toml" > "$dir/set.toml"
  echo "reference-validation: $name: stimuli" >&2
  start=$SECONDS
  "$skinlab" stimuli build "$dir/set.toml" -o "$dir/set" --progress lines
  echo "reference-validation: $name: stimuli in $((SECONDS - start)) s" >&2
  render_once "$dir/pathtraced.exr" "$dir/ref.toml" 'sss.method="pathtraced"' 'pathtraced.seed=0'
  render_once "$dir/pathtraced-seed1.exr" "$dir/ref.toml" 'sss.method="pathtraced"' 'pathtraced.seed=1'
  for seed in $(seq 2 $((seeds - 1))); do
    render_once "$dir/pathtraced-seed$seed.exr" "$dir/ref.toml" 'sss.method="pathtraced"' "pathtraced.seed=$seed"
  done
  ref_exr="$(python3 -c 'import json,sys; m=json.load(open(sys.argv[1])); print(next(s["files"]["exr"] for s in m["stimuli"] if s["reference"]))' "$dir/set/manifest.json")"
  tests=()
  while IFS= read -r f; do tests+=("$dir/set/$f"); done < <(python3 -c 'import json,sys; m=json.load(open(sys.argv[1])); [print(s["files"]["exr"]) for s in m["stimuli"] if not s["reference"]]' "$dir/set/manifest.json")
  "$skinlab" analyze metrics --reference "$dir/set/$ref_exr" "${tests[@]}" -o "$dir/metrics-reference" > /dev/null
  "$skinlab" analyze metrics --reference "$dir/pathtraced.exr" "${tests[@]}" "$dir/set/$ref_exr" "$dir/pathtraced-seed1.exr" \
    -o "$dir/metrics-pathtraced" > /dev/null
  seed_files="$dir/pathtraced.exr"
  for seed in $(seq 1 $((seeds - 1))); do seed_files+=",$dir/pathtraced-seed$seed.exr"; done
  "$skinlab" analyze metrics --reference-seeds "$seed_files" --compare-reference "$dir/set/$ref_exr" "${tests[@]}" \
    --compare-metrics "$dir/metrics-reference/metrics.json" -o "$dir/metrics-debiased" > /dev/null
  # The path-traced truth (truth.exr) and the error metrics against it (metrics-truth). With TRUTH_SEEDS > 0 it is
  # the mean of that many renders of its own (seeds 1000, 1001, …, TRUTH_SAMPLES samples each), measured against the
  # SEEDS validation seeds, which are independent of it (metrics-truth-debiased: its debiased MSE against the best
  # condition's and the rankings of the error metrics against it). Otherwise it is the mean of the validation seeds,
  # and with eight or more of them the mean of the first half (truth-half.exr) is measured against the pairs of the
  # second half.
  truth_seeds="$(truth_seeds_of "$name")"
  truth_samples="$(truth_samples_of "$name")"
  all_seeds=()
  IFS=, read -r -a all_seeds <<< "$seed_files"
  rm -rf "$dir/metrics-truth-debiased"
  if [ "$truth_seeds" -gt 0 ]; then
    truth_files=()
    for seed in $(seq 1000 $((999 + truth_seeds))); do
      render_once "$dir/truth-seed$seed.exr" "$dir/ref.toml" 'sss.method="pathtraced"' "pathtraced.seed=$seed" \
        "pathtraced.samples=$truth_samples"
      truth_files+=("$dir/truth-seed$seed.exr")
    done
    "$skinlab" analyze seed-mean "${truth_files[@]}" -o "$dir/truth.exr" > /dev/null
    "$skinlab" analyze metrics --reference "$dir/truth.exr" "${tests[@]}" -o "$dir/metrics-truth" > /dev/null
    "$skinlab" analyze metrics --reference-seeds "$seed_files" --compare-reference "$dir/truth.exr" "${tests[@]}" \
      --compare-metrics "$dir/metrics-truth/metrics.json" -o "$dir/metrics-truth-debiased" > /dev/null
  else
    "$skinlab" analyze seed-mean "${all_seeds[@]}" -o "$dir/truth.exr" > /dev/null
    "$skinlab" analyze metrics --reference "$dir/truth.exr" "${tests[@]}" -o "$dir/metrics-truth" > /dev/null
  fi
  if [ "$truth_seeds" -eq 0 ] && [ "$seeds" -ge 8 ]; then
    half=$((seeds / 2))
    "$skinlab" analyze seed-mean "${all_seeds[@]:0:$half}" -o "$dir/truth-half.exr" > /dev/null
    "$skinlab" analyze metrics --reference "$dir/truth-half.exr" "${tests[@]}" -o "$dir/metrics-truth-half" > /dev/null
    other_half="$(IFS=,; echo "${all_seeds[*]:$half}")"
    "$skinlab" analyze metrics --reference-seeds "$other_half" --compare-reference "$dir/truth-half.exr" "${tests[@]}" \
      --compare-metrics "$dir/metrics-truth-half/metrics.json" -o "$dir/metrics-truth-debiased" > /dev/null
  fi
  ran+=("$name")
done

python3 - "$out" "$size" "$samples" "$seeds" "$edge_mm" "$non_skin" "$convexity" "${ran[@]}" <<'PYTHON'
# The table: per-band disagreement of `reference` with `pathtraced` (next to the path tracer's own noise), and
# Kendall's τ_b between the rankings of the 24 conditions under the two references, per score.
import json, os, sys

out, size, samples, seeds = sys.argv[1], sys.argv[2], sys.argv[3], int(sys.argv[4])
edge_mm, non_skin, convexity, cases = sys.argv[5], sys.argv[6], sys.argv[7], sys.argv[8:]
bands = ["halo", "bleed", "spill", "interior"]

def load(path):
    m = json.load(open(path))
    return {c["test"]["name"]: c
            for c in m["comparisons"]}

def kendall_tau_b(x, y):
    n, concordant, discordant, ties_x, ties_y = len(x), 0, 0, 0, 0
    for i in range(n):
        for j in range(i + 1, n):
            dx, dy = x[i] - x[j], y[i] - y[j]
            if dx == 0 and dy == 0: continue
            if dx == 0: ties_x += 1
            elif dy == 0: ties_y += 1
            elif dx * dy > 0: concordant += 1
            else: discordant += 1
    denominator = ((concordant + discordant + ties_x) * (concordant + discordant + ties_y)) ** 0.5
    return None if denominator == 0 else (concordant - discordant) / denominator

def number(v, digits=3):
    if v is None: return "–"
    return f"{v:.{digits}e}" if v != 0 and abs(v) < 0.01 else f"{v:.{digits}f}"

def band(c, b, key):
    entry = c["bands"].get(b) if c.get("bands") else None
    return None if not entry or not entry.get("pixels") else entry.get(key)

lines = ["# Reference validation: `reference` against `pathtraced`", "",
         f"Generated by `scripts/reference-validation.sh` at {size}×{size}, `pathtraced` at {samples} samples "
         "(seed 0; seed 1 for the noise column), max_bounces 0, the rasterizer's specular layer; `reference` at "
         f"{edge_mm} mm edges, non-skin neighbours: {non_skin}, convexity {convexity} mm. Leak energy E = Σ_band |Y_test − Y_ref| / Σ_skin Y_ref; bands from the path-traced reference's "
         "depth and mask (docs/metrics.md).", "",
         "## Per band: `reference` scored against `pathtraced`", "",
         "| case | band | pixels | E(reference) | E(noise) | ΔE00 mean (reference) | ΔE00 mean (noise) |",
         "|---|---|---|---|---|---|---|"]
taus = ["", "## Rankings of the 24 conditions: Kendall's τ_b between the two references", "",
        "| case | halo E | bleed E | spill E | skin ΔE00 mean | halo ΔE00 excess | bleed ΔE00 excess | smallest halo E (vs `reference`) / noise E | smallest bleed E / noise E |",
        "|---|---|---|---|---|---|---|---|---|"]
for name in cases:
    against_ref = load(os.path.join(out, name, "metrics-reference", "metrics.json"))
    against_pt = load(os.path.join(out, name, "metrics-pathtraced", "metrics.json"))
    ref_key = next(k for k in against_pt if k not in against_ref and k != "pathtraced-seed1")
    reference, noise = against_pt[ref_key], against_pt["pathtraced-seed1"]
    for b in bands:
        if not band(reference, b, "pixels"): continue
        lines.append(f"| {name} | {b} | {band(reference, b, 'pixels')} | {number(band(reference, b, 'leak_energy'))} | "
                     f"{number(band(noise, b, 'leak_energy'))} | {number(band(reference, b, 'delta_e00_mean'))} | "
                     f"{number(band(noise, b, 'delta_e00_mean'))} |")
    lines.append(f"| {name} | skin | – | – | – | {number(reference['skin']['delta_e00_mean'])} | "
                 f"{number(noise['skin']['delta_e00_mean'])} |")
    conditions = sorted(against_ref)
    row = [name]
    scores = [("halo", "leak_energy"), ("bleed", "leak_energy"), ("spill", "leak_energy"), ("skin", "delta_e00_mean"),
              ("halo", "excess"), ("bleed", "excess")]
    for b, key in scores:
        get = (lambda c: c["skin"][key]) if b == "skin" else (lambda c: band(c, b, key))
        x = [get(against_ref[k]) for k in conditions]
        y = [get(against_pt[k]) for k in conditions]
        if any(v is None for v in x + y): row.append("–"); continue
        tau = kendall_tau_b(x, y)
        row.append("–" if tau is None else f"{tau:+.2f}")
    for b in ["halo", "bleed"]:
        values = [v for v in (band(against_ref[k], b, "leak_energy") for k in conditions) if v is not None]
        row.append("–" if not values else f"{number(min(values))} / {number(band(noise, b, 'leak_energy'))}")
    taus.append("| " + " | ".join(row) + " |")
    # The per-condition scores under both references, for the docs' discussion.
# Levels: the mask-weighted mean skin diffuse of each reference (oiiotool; a mean over thousands of pixels, so the
# path tracer's per-pixel noise averages out, unlike in the per-pixel scores above).
import re, subprocess
def skin_mean(exr):
    def means(*args):
        text = subprocess.run(["oiiotool", *args, "--printstats"], check=True, capture_output=True, text=True).stdout
        return [float(v) for v in re.search(r"Stats Avg: (.*?) \(float\)", text).group(1).split()]
    area = means(exr, "--ch", "mask.Y")[0]
    return [v / area for v in means(exr, "--ch", "diffuse.R,diffuse.G,diffuse.B", exr, "--ch", "mask.Y,mask.Y,mask.Y", "--mul")]
levels = ["", "## Skin level: mask-weighted mean skin diffuse (R, G, B)", "",
          f"`pathtraced`: the mean over its {seeds} seeds, and the standard deviation of one seed's level around it "
          "(relative); the difference is against the mean.", "",
          "| case | `reference` | `pathtraced` (mean of seeds) | one seed's sd | reference − pathtraced (relative) |",
          "|---|---|---|---|---|"]
for name in cases:
    manifest = json.load(open(os.path.join(out, name, "set", "manifest.json")))
    ref_exr = os.path.join(out, name, "set", next(s["files"]["exr"] for s in manifest["stimuli"] if s["reference"]))
    r = skin_mean(ref_exr)
    per_seed = [skin_mean(os.path.join(out, name, "pathtraced.exr" if k == 0 else f"pathtraced-seed{k}.exr"))
                for k in range(seeds)]
    p = [sum(v[c] for v in per_seed) / seeds for c in range(3)]
    sd = [(sum((v[c] - p[c]) ** 2 for v in per_seed) / (seeds - 1)) ** 0.5 / p[c] * 100 for c in range(3)]
    fmt = lambda v: ", ".join(f"{x:.4f}" for x in v)
    levels.append(f"| {name} | {fmt(r)} | {fmt(p)} | " + ", ".join(f"{x:.1f} %" for x in sd) + " | "
                  + ", ".join(f"{(a - b) / b * 100:+.1f} %" for a, b in zip(r, p)) + " |")
# The scanned head's ear rim (docs/pathtraced.md, "The ear rim and the environment light"): the skin pixels within
# 3 px (at 256², scaled with the size) of the background in the ear's box (20 × 45 px at 166, 62), from Cycles' seed 0
# silhouette: mask − erode(mask); its mean diffuse in `reference` against the mean of the seeds.
def rim_region(pathtraced_exr, path):
    s = int(size) / 256
    k = 2 * max(1, round(3 * s)) + 1
    box = f"{round(20 * s)}x{round(45 * s)}+{round(166 * s)}+{round(62 * s)}"
    subprocess.run(["oiiotool", pathtraced_exr, "--ch", "mask.Y", "--dup", "--erode", f"{k}x{k}", "--sub", "--cut", box,
                    "--chnames", "Y", "-o", path], check=True)
    return box
def region_mean(exr, region, box):
    def means(*args):
        text = subprocess.run(["oiiotool", *args, "--printstats"], check=True, capture_output=True, text=True).stdout
        return [float(v) for v in re.search(r"Stats Avg: (.*?) \(float\)", text).group(1).split()]
    area = means(region)[0]
    return [v / area for v in means(exr, "--ch", "diffuse.R,diffuse.G,diffuse.B", "--cut", box, region, "--ch", "Y,Y,Y", "--mul")]
if "scan" in cases:
    manifest = json.load(open(os.path.join(out, "scan", "set", "manifest.json")))
    ref_exr = os.path.join(out, "scan", "set", next(s["files"]["exr"] for s in manifest["stimuli"] if s["reference"]))
    seed_exrs = [os.path.join(out, "scan", "pathtraced.exr" if k == 0 else f"pathtraced-seed{k}.exr") for k in range(seeds)]
    region = os.path.join(out, "scan", "ear-rim.exr")
    box = rim_region(seed_exrs[0], region)
    r = region_mean(ref_exr, region, box)
    per_seed = [region_mean(e, region, box) for e in seed_exrs]
    p = [sum(v[c] for v in per_seed) / seeds for c in range(3)]
    se = [(sum((v[c] - p[c]) ** 2 for v in per_seed) / (seeds - 1) / seeds) ** 0.5 / p[c] * 100 for c in range(3)]
    fmt = lambda v: ", ".join(f"{x:.4f}" for x in v)
    levels += ["", "## The scanned head's ear rim: mean diffuse (R, G, B)", "",
               "Skin pixels within 3 px (at 256²) of the background in the ear's box; `pathtraced`: the mean of the seeds "
               "and its standard error (relative).", "",
               "| `reference` | `pathtraced` (mean of seeds) | its standard error | reference − pathtraced (relative) |",
               "|---|---|---|---|",
               f"| {fmt(r)} | {fmt(p)} | " + ", ".join(f"{x:.1f} %" for x in se) + " | "
               + ", ".join(f"{(a - b) / b * 100:+.1f} %" for a, b in zip(r, p)) + " |"]
per_condition = ["", "## Scores per condition under both references", "",
                 "| case | condition | halo E (ref / pt) | bleed E (ref / pt) | skin ΔE00 mean (ref / pt) |", "|---|---|---|---|---|"]
for name in cases:
    against_ref = load(os.path.join(out, name, "metrics-reference", "metrics.json"))
    against_pt = load(os.path.join(out, name, "metrics-pathtraced", "metrics.json"))
    for k in sorted(against_ref):
        a, p = against_ref[k], against_pt[k]
        per_condition.append(f"| {name} | {k} | {number(band(a, 'halo', 'leak_energy'))} / {number(band(p, 'halo', 'leak_energy'))} | "
                             f"{number(band(a, 'bleed', 'leak_energy'))} / {number(band(p, 'bleed', 'leak_energy'))} | "
                             f"{number(a['skin']['delta_e00_mean'])} / {number(p['skin']['delta_e00_mean'])} |")
# Debiased: every condition's squared error against the noise-free path-traced image (pairs of seeds,
# `analyze metrics --reference-seeds`), the reference's own, and the rankings' agreement: τ_b with the seed
# jackknife's interval (t quantile, S − 1 degrees of freedom) and the bootstrap's over conditions and seeds, over
# all 24 conditions, the 16 closest to Cycles ("competitive") and all but the clearly worse (debiased MSE above
# Q3 + 1.5 IQR of the 24); the same competitive τ_b per channel and in CIELAB; the evaluation table's scores.
def tau_text(a):
    tau = a["tau_b"]["value"]
    if tau is None: return "–"
    text = f"{tau:+.2f}"
    jack, boot = a.get("tau_b_interval_95"), a.get("tau_b_bootstrap_interval_95")
    text += f" [{jack[0]:+.2f}, {jack[1]:+.2f}]" if jack else " [–]"
    text += f" [{boot[0]:+.2f}, {boot[1]:+.2f}]" if boot else " [–]"
    return text
debiased = ["", f"## Debiased rankings against `pathtraced` ({seeds} seeds): Kendall's τ_b", "",
            "MSE of Y over the band against the noise-free path-traced image (mean over pairs of seeds of "
            "(a − r_i)(a − r_j)); `reference`'s own MSE ± its standard error; τ_b between the conditions' MSE against "
            "`reference` and their debiased MSE against `pathtraced`, each as τ_b [seed jackknife, t quantile] "
            "[bootstrap over conditions and seeds], 95 %: over all 24 conditions, the 16 closest to `pathtraced` and all "
            "but the clearly worse (debiased MSE above Q3 + 1.5 IQR; their count in brackets); pairs Cycles separates "
            "(|D| > t·SE) and the share of them ranked the same way by `reference`; conditions scoring better than "
            "`reference` itself.", "",
            "| case | band | `reference` MSE ± SE | conditions' MSE min / median / max | τ_b all | τ_b 16 closest | τ_b without clearly worse | separated pairs: same order | better than `reference` |",
            "|---|---|---|---|---|---|---|---|---|"]
colour = ["", "## Competitive rankings per channel and in CIELAB", "",
          "τ_b over the 16 conditions closest to `pathtraced` in each quantity (squared error of linear R, G, B × "
          "exposure, and ΔE*ab² of the display encoding), with the bootstrap interval; Y for comparison.", "",
          "| case | band | Y | R | G | B | CIELAB |", "|---|---|---|---|---|---|---|"]
table_scores = ["", "## The evaluation table's scores against `reference`, ranked against Cycles", "",
                "Each score of the conditions against `reference` (metrics-reference/metrics.json) against the "
                "debiased ranking of Cycles in the same band: leak energies against the MSE of Y, ΔE00 means against "
                "the MSE in CIELAB, ΔE00 excesses against √MSE(band) − √MSE(interior) in CIELAB. τ_b [t jackknife] "
                "[bootstrap], 95 %; agrees: τ_b ≥ 0.8 over the 16 closest.", "",
                "| case | score | τ_b all | τ_b 16 closest | τ_b without clearly worse | agrees |", "|---|---|---|---|---|---|"]
for name in cases:
    path_json = os.path.join(out, name, "metrics-debiased", "debiased.json")
    if not os.path.exists(path_json): continue
    d = json.load(open(path_json))
    for b in bands + ["skin"]:
        ref = d["compared_reference"]["regions"][b]
        if not ref["pixels"]: continue
        values = sorted(t["regions"][b]["mse"]["value"] for t in d["tests"])
        agree = d["ranking_agreement"][b]
        worse = agree["without_clearly_worse"]
        t_quantile = agree.get("jackknife_t_quantile") or 1.96
        better = sum(1 for t in d["tests"] if t["regions"][b]["difference_from_compared"]["value"] is not None
                     and t["regions"][b]["difference_from_compared"]["value"] + t_quantile * (t["regions"][b]["difference_from_compared"]["standard_error"] or 0) < 0)
        sep, same = agree["separated_pairs"], agree["concordant_separated_pairs"]
        debiased.append(f"| {name} | {b} | {number(ref['mse']['value'])} ± {number(ref['mse']['standard_error'])} | "
                        f"{number(values[0])} / {number(values[len(values) // 2])} / {number(values[-1])} | "
                        f"{tau_text(agree)} | {tau_text(agree['competitive'])} | {tau_text(worse)} ({worse['conditions']}) | "
                        f"{same}/{sep} | {better} |")
        by_quantity = d.get("ranking_agreement_by_quantity", {})
        if by_quantity:
            cells = []
            for q in ["Y", "R", "G", "B", "Lab"]:
                a = by_quantity[q][b]["competitive"]
                boot = a.get("tau_b_bootstrap_interval_95")
                cells.append("–" if a["tau_b"]["value"] is None else f"{a['tau_b']['value']:+.2f}"
                             + (f" [{boot[0]:+.2f}, {boot[1]:+.2f}]" if boot else ""))
            colour.append(f"| {name} | {b} | " + " | ".join(cells) + " |")
    for score, a in d.get("table_score_agreement", {}).items():
        if a["tau_b"]["value"] is None and a["competitive"]["tau_b"]["value"] is None: continue
        tau = a["competitive"]["tau_b"]["value"]
        worse = a["without_clearly_worse"]
        table_scores.append(f"| {name} | {score} | {tau_text(a)} | {tau_text(a['competitive'])} | "
                            f"{tau_text(worse)} ({worse['conditions']}) | " + ("–" if tau is None else "yes" if tau >= 0.8 else "**no**") + " |")
# The truth of the error metrics: how close each candidate comes to the noise-free Cycles image against the best
# condition (debiased.json, truth_precision): `reference` (its debiased MSE), the mean of all seeds (σ̄²/S from the
# seeds' pairs) and, with eight or more seeds, the mean of the first half measured against the second half's pairs;
# a truth is precise enough at ≤ 0.5 × the best condition's MSE. The truth used (metrics-truth/ when it is the seed
# mean) is `reference` where it is precise enough in every band scored, else the seed mean.
truth_lines = ["", "## The truth of the error metrics: precision against the best condition", "",
               "Squared error of each truth against the noise-free Cycles image over the best condition's debiased "
               "MSE (Y; R in brackets): `reference`; the mean of the validation seeds (σ̄²/S, from the seeds' "
               "pairs); the path-traced truth measured against independent seeds (with TRUTH_SEEDS: truth.exr, its "
               "own renders, against the validation seeds; else, with eight or more seeds, the mean of the first half "
               "against the second half). Precise enough: ≤ 0.50. τ_b: the conditions' squared error (Y) and the error metrics "
               "against that truth ranked against the independent seeds (16 closest, bootstrap interval).", "",
               "| case | band | best condition MSE | `reference` | seed mean (validation seeds) | path-traced truth, measured | τ_b 16 closest: squared error against it | τ_b skin ΔE00 / halo E / bleed E against it | truth used |",
               "|---|---|---|---|---|---|---|---|---|"]
def ratio_text(entry, red):
    if not entry: return "–"
    r, rr = entry["ratio_to_best_condition"], (red or {}).get("ratio_to_best_condition")
    if r is None: return "–"
    return f"{r:.2f}" + (f" ({rr:.2f})" if rr is not None else "")
def competitive_tau(d, score):
    a = (d or {}).get("table_score_agreement", {}).get(score)
    if not a or a["competitive"]["tau_b"]["value"] is None: return "–"
    boot = a["competitive"].get("tau_b_bootstrap_interval_95")
    return f"{a['competitive']['tau_b']['value']:+.2f}" + (f" [{boot[0]:+.2f}, {boot[1]:+.2f}]" if boot else "")
def band_tau(d, band):
    # The conditions' squared error against the measured truth ranked against the independent seeds (16 closest).
    a = (d or {}).get("ranking_agreement", {}).get(band)
    if not a or a["competitive"]["tau_b"]["value"] is None: return "–"
    boot = a["competitive"].get("tau_b_bootstrap_interval_95")
    return f"{a['competitive']['tau_b']['value']:+.2f}" + (f" [{boot[0]:+.2f}, {boot[1]:+.2f}]" if boot else "")
def truth_seeds_used(name):
    # The truth measured in metrics-truth-debiased is truth.exr itself (TRUTH_SEEDS) rather than a half of the seeds.
    record = json.load(open(os.path.join(out, name, "metrics-truth", "metrics.json")))["comparisons"][0]["reference"]["truth"]
    return all(isinstance(k, int) and k >= 1000 for k in record.get("seeds", []))
for name in cases:
    path_json = os.path.join(out, name, "metrics-debiased", "debiased.json")
    if not os.path.exists(path_json): continue
    precision = json.load(open(path_json))["truth_precision"]["regions"]
    half_json = os.path.join(out, name, "metrics-truth-debiased", "debiased.json")
    half = json.load(open(half_json)) if os.path.exists(half_json) else None
    half_precision = half["truth_precision"]["regions"] if half else None
    scored = [b for b in ["skin", "halo", "bleed"] if (precision[b]["Y"]["best_condition_mse"] is not None)]
    # `reference` where it is precise enough, or no less precise than the path-traced truth (measured against
    # independent seeds when they exist, else the validation seeds' mean from their pairs).
    worst = lambda ratios: max((r for r in ratios if r is not None), default=float("inf"))
    reference_worst = worst(precision[b]["Y"]["compared_reference"]["ratio_to_best_condition"] for b in scored)
    truth_worst = worst((half_precision[b]["Y"]["compared_reference"] if half_precision and os.path.exists(
                         os.path.join(out, name, "metrics-truth-debiased")) and truth_seeds_used(name) else
                         precision[b]["Y"]["seed_mean"])["ratio_to_best_condition"] for b in scored)
    reference_ok = reference_worst <= 0.5 or reference_worst <= truth_worst
    truth_record = json.load(open(os.path.join(out, name, "metrics-truth", "metrics.json")))["comparisons"][0]["reference"]["truth"]
    used = "`reference`" if reference_ok else (f"`pathtraced`, mean of {len(truth_record['seeds'])} seeds × "
                                               f"{truth_record['samples']} samples")
    half_taus = " / ".join(competitive_tau(half, s) for s in ["skin_delta_e00_mean", "halo_leak_energy", "bleed_leak_energy"]) if half else "–"
    for b in scored:
        p, hp = precision[b], (half_precision or {}).get(b)
        truth_lines.append(f"| {name} | {b} | {number(p['Y']['best_condition_mse'])} | "
                           f"{ratio_text(p['Y'].get('compared_reference'), p['R'].get('compared_reference'))} | "
                           f"{ratio_text(p['Y']['seed_mean'], p['R']['seed_mean'])} | "
                           + (ratio_text(hp['Y'].get('compared_reference'), hp['R'].get('compared_reference')) if hp else "–")
                           + f" | {band_tau(half, b)} | {half_taus if b == 'skin' else ''} | {used} |")
    with open(os.path.join(out, name, "truth.json") + ".tmp", "w") as f:
        json.dump({"truth": "reference" if reference_ok else "pathtraced-seed-mean",
                   "record": {"kind": "render", "method": "reference"} if reference_ok else truth_record,
                   "metrics": "metrics-reference" if reference_ok else "metrics-truth"}, f, indent=2)
    os.replace(os.path.join(out, name, "truth.json") + ".tmp", os.path.join(out, name, "truth.json"))
debiased += colour + table_scores + truth_lines
lines += debiased
path = os.path.join(out, "reference-validation.md")
with open(path + ".tmp", "w") as f:
    f.write("\n".join(lines + taus + levels + per_condition) + "\n")
os.replace(path + ".tmp", path)
print(f"reference-validation: {path}")
PYTHON
