#!/usr/bin/env bash
# The evaluation table of the extensions (docs/extensions.md, "Scores per method and extension"): every screen-space method
# (gaussian-sum, separable, artistic, pscbf) × extension set (none, follow-surface, +cbf, +lab_weight, +curvature
# reduce-floor, all) on builtin:halo (two depth gaps), builtin:bleed and the scanned head (close view), each block
# scored against its object-space reference render by `skinlab analyze metrics`.
#
#   scripts/extensions-table.sh [OUT_DIR]          (default out/extensions)
#
# Environment: SKINLAB (the skinlab executable; default build/release/cli/skinlab), SKINLAB_ASSETS (the shared
# assets; without the scanned head its set is skipped with a message), PATHTRACED (0: no path-traced reference),
# PATHTRACED_SAMPLES (its samples, default 64), PATHTRACED_SEEDS (path-traced seeds per reference, default 4, at
# least 2: the debiased scores), TRUTH (the truth of the error metrics: auto, reference or pathtraced; below),
# EEVEE (0: no `eevee` row), SETS (a subset of the sets: "halo bleed head"). Needs python3 for the table and blender for the second reference.
# Writes, under OUT_DIR:
#   halo/, bleed/, head/   the stimulus sets (stimuli/specs/extensions-*.toml): exr/, png/, manifest, contact.png
#   */metrics/             metrics.csv, metrics.json and the ΔE00 heat maps with the bands outlined
#   */pathtraced/, */metrics-pathtraced/   each reference stimulus rendered by `pathtraced` (seed 0, and ID-seedK.exr
#                          for the other seeds), and the block's scores against seed 0
#   */metrics-debiased/    the block's squared errors against the noise-free path-traced image (`analyze metrics
#                          --reference-seeds`, jackknife over the seeds), their ranking against `reference`'s, and
#                          how each score of the table ranks the conditions against Cycles (`--compare-metrics`):
#                          a score whose τ_b over the 16 conditions closest to Cycles is below 0.8 is withdrawn
#                          from the block's tables, with the reason printed
#   */pathtraced/ID-truth.exr, */metrics-truth/   the mean of the path-traced seeds (`skinlab analyze seed-mean`)
#                          and the block's scores against it: the table's scores where `reference` is not precise
#                          enough (its debiased MSE against Cycles above half the best condition's in the skin, halo
#                          or bleed band) and the seed mean is more precise (TRUTH=auto, the default), or always
#                          (TRUTH=pathtraced), or never
#                          (TRUTH=reference); each block's tables name the truth they were scored against;
#                          */metrics-truth-debiased/ ranks those scores against Cycles' debiased ranking (the
#                          withdrawal rule below applies to them as to the scores against `reference`)
#   */eevee/, */metrics-eevee/, */metrics-eevee-pathtraced/   each block's scene rendered by `eevee`
#                          (Blender EEVEE, its own screen-space SSS), scored against the block's reference and
#                          against the path-traced one: the table's `eevee` row
#   extensions-table.md    per block: method × extension-set tables of the leak energies and the mean ΔE00 excess,
#                          then every score; with the paths of the contact sheets and heat maps
# Rerunning resumes: stimuli already rendered with the same parameters are not rendered again.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-out/extensions}"
skinlab="${SKINLAB:-$root/build/release/cli/skinlab}"
[ -x "$skinlab" ] || { echo "extensions-table: $skinlab not found (build it: scripts/build.sh, or set SKINLAB)" >&2; exit 2; }
command -v python3 > /dev/null || { echo "extensions-table: python3 is needed to write the table" >&2; exit 2; }
mkdir -p "$out"
pathtraced_seeds="${PATHTRACED_SEEDS:-4}"
[ "$pathtraced_seeds" -ge 2 ] 2>/dev/null || { echo "extensions-table: PATHTRACED_SEEDS=$pathtraced_seeds must be at least 2" >&2; exit 2; }

sets=(halo bleed)
if [ -n "${SETS:-}" ]; then
  read -r -a sets <<< "$SETS"  # a subset, e.g. SETS="bleed"
elif [ -n "${SKINLAB_ASSETS:-}" ] && [ -e "$SKINLAB_ASSETS/LeePerrySmith/LeePerrySmith.glb" ]; then
  sets+=(head)
else
  echo "extensions-table: scanned head skipped (\$SKINLAB_ASSETS/LeePerrySmith/LeePerrySmith.glb not found)" >&2
fi

# The second reference: for every reference stimulus, the same scene and overrides rendered by `pathtraced`
# (PATHTRACED_SAMPLES samples, default 64; no interreflection, the rasterizer's specular layer and the environment
# unshadowed like the rasterizer's ambient term, so that it
# differs from the screen-space renders in the subsurface transport only: docs/pathtraced.md), and the block's
# stimuli scored against it in OUT_DIR/SET/metrics-pathtraced/REFERENCE_ID/; with PATHTRACED_SEEDS seeds (default 4)
# also without the path tracer's noise, and ranked against `reference` (τ_b with its interval), in
# OUT_DIR/SET/metrics-debiased/REFERENCE_ID/ (docs/pathtraced.md, "Rankings without the noise: pairs of seeds").
# PATHTRACED=0 skips it (no Blender).
render_pathtraced() {  # render_pathtraced OUT.exr SCENE ARGS... (skipped when rendered with the same inputs)
  local exr="$1" scene="$2"; shift 2
  local stamp; stamp="$scene $*"
  if [ ! -e "$exr" ] || [ "$(cat "$exr.inputs" 2> /dev/null)" != "$stamp" ]; then
    "$skinlab" render --scene "$scene" "$@" -o "$exr" > /dev/null
    printf '%s' "$stamp" > "$exr.inputs"
  fi
}

pathtraced_references() {  # pathtraced_references SET_NAME
  local dir="$out/$1" id scene overrides
  mkdir -p "$dir/pathtraced"
  while IFS=$'\t' read -r id scene overrides; do
    local exr="$dir/pathtraced/$id.exr" args=()
    while IFS= read -r o; do [ -n "$o" ] && args+=(--set "$o"); done <<< "${overrides//$'\x1f'/$'\n'}"
    args+=(--set 'sss.method="pathtraced"' --set "pathtraced.samples=${PATHTRACED_SAMPLES:-64}"
           --set 'pathtraced.max_bounces=0' --set 'pathtraced.specular_source="rasterizer"'
           --set 'pathtraced.environment_shadow=false')
    render_pathtraced "$exr" "$scene" "${args[@]}"
    local seed_files="$exr" seed
    for seed in $(seq 1 $((pathtraced_seeds - 1))); do
      render_pathtraced "$dir/pathtraced/$id-seed$seed.exr" "$scene" "${args[@]}" --set "pathtraced.seed=$seed"
      seed_files+=",$dir/pathtraced/$id-seed$seed.exr"
    done
    local tests=()
    while IFS= read -r f; do tests+=("$dir/$f"); done < <(python3 -c '
import json, sys
m = json.load(open(sys.argv[1]))
block = next(s["block"] for s in m["stimuli"] if s["id"] == sys.argv[2])
for s in m["stimuli"]:
    if s["block"] == block and not s["reference"]: print(s["files"]["exr"])' "$dir/manifest.json" "$id")
    "$skinlab" analyze metrics --reference "$exr" "${tests[@]}" -o "$dir/metrics-pathtraced/$id" > /dev/null
    local reference; reference="$dir/$(python3 -c '
import json, sys
m = json.load(open(sys.argv[1]))
print(next(s["files"]["exr"] for s in m["stimuli"] if s["id"] == sys.argv[2]))' "$dir/manifest.json" "$id")"
    "$skinlab" analyze metrics --reference-seeds "$seed_files" --compare-reference "$reference" "${tests[@]}" \
      --compare-metrics "$dir/metrics/metrics.json" -o "$dir/metrics-debiased/$id" > /dev/null
    # The path-traced truth: the mean of the seeds (ID-truth.exr) and the block's scores against it.
    local all_seeds=()
    IFS=, read -r -a all_seeds <<< "$seed_files"
    "$skinlab" analyze seed-mean "${all_seeds[@]}" -o "$dir/pathtraced/$id-truth.exr" > /dev/null
    "$skinlab" analyze metrics --reference "$dir/pathtraced/$id-truth.exr" "${tests[@]}" -o "$dir/metrics-truth/$id" > /dev/null
    # The scores against the seed mean ranked against Cycles' debiased ranking (the same seeds: optimistic), so that a
    # score that ranks otherwise than the squared error even against Cycles is withdrawn as well.
    "$skinlab" analyze metrics --reference-seeds "$seed_files" --compare-reference "$dir/pathtraced/$id-truth.exr" \
      "${tests[@]}" --compare-metrics "$dir/metrics-truth/$id/metrics.json" -o "$dir/metrics-truth-debiased/$id" > /dev/null
  done < <(python3 -c '
import json, os, sys
m = json.load(open(sys.argv[1]))
for s in m["stimuli"]:
    if not s["reference"]: continue
    scene = s["scene"]
    if not scene.startswith("builtin:") and not os.path.isabs(scene): scene = os.path.join(sys.argv[2], scene)
    keep = [o for o in s["overrides"] if not o.startswith(("sss.method=", "sss.reference_edge_mm="))]  # reference-only keys
    print(s["id"], scene, "\x1f".join(keep), sep="\t")' \
    "$dir/manifest.json" "$root/stimuli/specs")
}

# The `eevee` row: for every block, the scene and overrides of its screen-space stimuli (without their [sss] and
# [transmittance] keys; bleed: the paint inside the mask, as the methods get it) rendered by Blender EEVEE with the
# rasterizer's specular layer (as the path-traced references)
# (sss.method = "eevee", docs/pathtraced.md "EEVEE": its own screen-space Christensen-Burley SSS with a depth
# correction, radii fitted to d'Eon's profile, no skinlab extension), scored against the block's reference in
# OUT_DIR/SET/metrics-eevee/REFERENCE_ID/ and, when rendered, against the path-traced one in
# OUT_DIR/SET/metrics-eevee-pathtraced/REFERENCE_ID/.
eevee_renders() {  # eevee_renders SET_NAME
  local dir="$out/$1" id scene overrides
  mkdir -p "$dir/eevee"
  while IFS=$'\t' read -r id scene overrides; do
    local exr="$dir/eevee/$id.exr" args=()
    while IFS= read -r o; do [ -n "$o" ] && args+=(--set "$o"); done <<< "${overrides//$'\x1f'/$'\n'}"
    args+=(--set 'sss.method="eevee"' --set 'eevee.specular_source="rasterizer"')
    local stamp; stamp="$scene ${args[*]}"
    if [ ! -e "$exr" ] || [ "$(cat "$exr.inputs" 2> /dev/null)" != "$stamp" ]; then
      "$skinlab" render --scene "$scene" "${args[@]}" -o "$exr" > /dev/null
      printf '%s' "$stamp" > "$exr.inputs"
    fi
    local reference; reference="$(python3 -c '
import json, sys
m = json.load(open(sys.argv[1]))
print(next(s["files"]["exr"] for s in m["stimuli"] if s["id"] == sys.argv[2]))' "$dir/manifest.json" "$id")"
    "$skinlab" analyze metrics --reference "$dir/$reference" "$exr" -o "$dir/metrics-eevee/$id" > /dev/null
    if [ -e "$dir/pathtraced/$id.exr" ]; then
      "$skinlab" analyze metrics --reference "$dir/pathtraced/$id.exr" "$exr" -o "$dir/metrics-eevee-pathtraced/$id" > /dev/null
    fi
    if [ -e "$dir/pathtraced/$id-truth.exr" ]; then
      "$skinlab" analyze metrics --reference "$dir/pathtraced/$id-truth.exr" "$exr" -o "$dir/metrics-eevee-truth/$id" > /dev/null
    fi
  done < <(python3 -c '
import json, os, sys
m = json.load(open(sys.argv[1]))
for r in m["stimuli"]:
    if not r["reference"]: continue
    # The scene of the block'"'"'s screen-space stimuli (bleed: the paint inside the mask), not the reference'"'"'s own.
    s = next(s for s in m["stimuli"] if s["block"] == r["block"] and not s["reference"])
    scene = s["scene"]
    if not scene.startswith("builtin:") and not os.path.isabs(scene): scene = os.path.join(sys.argv[2], scene)
    keep = [o for o in s["overrides"] if not o.startswith(("sss.", "transmittance."))]  # the methods'"'"' own keys
    print(r["id"], scene, "\x1f".join(keep), sep="\t")' \
    "$dir/manifest.json" "$root/stimuli/specs")
}

for name in "${sets[@]}"; do
  echo "extensions-table: $name" >&2
  # The scores are of the whole frame: the specs' crop and magnification are how a study presents the sets.
  size="width = 256, height = 256"
  [ "$name" = head ] && size="width = 480, height = 270"
  whole=(--set "fixed.crop={ x = 0, y = 0, $size }" --set fixed.magnification=1)
  "$skinlab" stimuli build "$root/stimuli/specs/extensions-$name.toml" -o "$out/$name" --progress lines "${whole[@]}"
  "$skinlab" analyze metrics --stimuli "$out/$name" -o "$out/$name/metrics"
  if [ "${PATHTRACED:-1}" != 0 ]; then
    echo "extensions-table: $name: path-traced references" >&2
    pathtraced_references "$name"
  fi
  if [ "${EEVEE:-1}" != 0 ]; then
    echo "extensions-table: $name: eevee" >&2
    eevee_renders "$name"
  fi
done

# The screen-space methods, from the binary's method table (one name a line).
methods="$("$skinlab" methods --list --screen-space | paste -sd, -)"
truth="${TRUTH:-auto}"
case "$truth" in auto|reference|pathtraced) ;; *) echo "extensions-table: TRUTH=$truth must be auto, reference or pathtraced" >&2; exit 2 ;; esac
python3 - "$out" "$methods" "$truth" "${sets[@]}" <<'PYTHON'
# Pivots each set's metrics.json by block × method × extension set. The extension set of a stimulus is read from
# its resolved [sss] parameters in the manifest, so the table cannot disagree with what was rendered.
import json, os, sys

out, methods, truth_choice, sets = sys.argv[1], sys.argv[2].split(","), sys.argv[3], sys.argv[4:]
extension_sets = ["none", "follow-surface", "+cbf", "+lab_weight", "+curvature", "all"]

def extension_set(sss):
    follow, cbf, lab, curvature = sss["follow_surface"], sss["cbf"], sss["lab_weight"] > 0, sss["curvature"] != "off"
    if not follow and not (cbf or lab or curvature): return "none"
    if follow and cbf and lab and curvature: return "all"
    if follow and (cbf, lab, curvature) == (False, False, False): return "follow-surface"
    if follow and (cbf, lab, curvature) == (True, False, False): return "+cbf"
    if follow and (cbf, lab, curvature) == (False, True, False): return "+lab_weight"
    if follow and (cbf, lab, curvature) == (False, False, True): return "+curvature"
    return None

def number(value, digits=3):
    return "–" if value is None else f"{value:.{digits}e}" if abs(value) < 0.01 and value != 0 else f"{value:.{digits}f}"

lines = ["# Halo / bleed / spill scores per method and extension set", "",
         "Generated by `scripts/extensions-table.sh`. Leak energy E = Σ_band |Y_test − Y_ref| / Σ_skin Y_ref "
         "(docs/metrics.md); ΔE00 excess = band mean − interior mean. Reference: the object-space `reference` render of "
         "the same block; the `pathtraced` columns score the same stimuli against a Cycles render of the reference's "
         "scene (no interreflection, the rasterizer's specular layer, seed 0), the debiased tables against the "
         "noise-free Cycles image estimated from all its seeds (docs/pathtraced.md). β: 0.5 for gaussian-sum, 0.09 for the others; curvature: reduce-floor, floor 0.5. "
         "The `eevee` row is Blender EEVEE's own screen-space SSS on the reference's scene (docs/pathtraced.md, \"EEVEE\"): it has "
         "no skinlab extension but a depth correction of its own, so it stands in the follow-surface column.", ""]
for name in sets:
    manifest = json.load(open(os.path.join(out, name, "manifest.json")))
    resolved = {s["id"]: s["resolved"] for s in manifest["stimuli"]}
    metrics = json.load(open(os.path.join(out, name, "metrics", "metrics.json")))
    # Scores against the path-traced reference of the same block (absent: PATHTRACED=0 or not rendered).
    against_pathtraced = {}
    pt_dir = os.path.join(out, name, "metrics-pathtraced")
    for ref_id in sorted(os.listdir(pt_dir)) if os.path.isdir(pt_dir) else []:
        for c in json.load(open(os.path.join(pt_dir, ref_id, "metrics.json")))["comparisons"]:
            against_pathtraced[c["test"]["name"]] = c
    # EEVEE's render of each reference's scene, scored against that reference and against the path-traced one.
    eevee = {}
    for ref_id in sorted(os.listdir(os.path.join(out, name, "metrics-eevee"))) if os.path.isdir(os.path.join(out, name, "metrics-eevee")) else []:
        c = json.load(open(os.path.join(out, name, "metrics-eevee", ref_id, "metrics.json")))["comparisons"][0]
        pt = os.path.join(out, name, "metrics-eevee-pathtraced", ref_id, "metrics.json")
        c["pathtraced"] = json.load(open(pt))["comparisons"][0] if os.path.exists(pt) else None
        block = next(s["block"] for s in manifest["stimuli"] if s["id"] == ref_id)
        c["reference_id"] = ref_id
        eevee[block] = c
    # Debiased squared errors against the noise-free path-traced image, per reference (absent: PATHTRACED=0).
    stimulus_of_file = {os.path.normpath(os.path.join(out, name, s["files"]["exr"])): s["id"] for s in manifest["stimuli"]}
    debiased = {}
    for s in manifest["stimuli"]:
        path = os.path.join(out, name, "metrics-debiased", s["id"], "debiased.json")
        if s["reference"] and os.path.exists(path):
            d = json.load(open(path))
            d["by_stimulus"] = {stimulus_of_file.get(os.path.normpath(t["test"])): t for t in d["tests"]}
            debiased[s["block"]] = d
    # The truth of each block's error metrics: `reference` where it is precise enough (its debiased MSE against
    # Cycles ≤ 0.5 × the best condition's in every band scored: debiased.json, truth_precision) or no less precise
    # than the seed mean, else the mean of the Cycles seeds (metrics-truth/); TRUTH=reference or pathtraced forces one.
    against_truth, truth_of_block = {}, {}
    for s in manifest["stimuli"]:
        if not s["reference"]: continue
        path = os.path.join(out, name, "metrics-truth", s["id"], "metrics.json")
        d = debiased.get(s["block"])
        if not os.path.exists(path) or d is None or truth_choice == "reference": continue
        precision = d["truth_precision"]["regions"]
        scored = [b for b in ["skin", "halo", "bleed"] if precision[b]["Y"]["best_condition_mse"] is not None]
        ratios = {b: precision[b]["Y"]["compared_reference"]["ratio_to_best_condition"] for b in scored}
        seed_mean = {b: precision[b]["Y"]["seed_mean"]["ratio_to_best_condition"] for b in scored}
        worst = lambda r: max((v for v in r.values() if v is not None), default=float("inf"))
        if truth_choice == "auto" and (worst(ratios) <= 0.5 or worst(ratios) <= worst(seed_mean)):
            continue  # `reference` is precise enough, or at least as precise as the seed mean
        truth_of_block[s["block"]] = (
            f"`pathtraced`, the mean of its {len(d['seeds'])} seeds (`{name}/pathtraced/{s['id']}-truth.exr`): "
            + ("forced by TRUTH=pathtraced" if truth_choice == "pathtraced" else
               "`reference` is not precise enough, its debiased MSE against Cycles over the best condition's is "
               + ", ".join(f"{b} {number(r, 2)}" for b, r in ratios.items()) + " (above 0.5 somewhere)")
            + "; the seed mean's own: " + ", ".join(f"{b} {number(r, 2)}" for b, r in seed_mean.items())
            + ("" if worst(seed_mean) <= 0.5 else
               " (**not precise enough either**: raise PATHTRACED_SEEDS or PATHTRACED_SAMPLES)"))
        for c in json.load(open(path))["comparisons"]:
            against_truth[c["test"]["name"]] = c
    table = {}
    for c in metrics["comparisons"]:
        sss = resolved[c["test"]["name"]]["sss"]
        key = (c["block"], sss["method"], extension_set(sss))
        if c["block"] in truth_of_block: c = dict(against_truth[c["test"]["name"]], block=c["block"])
        table[key] = c
        c["pathtraced"] = against_pathtraced.get(c["test"]["name"])
    for block, c in eevee.items():
        ref_id = c["reference_id"]
        truth_path = os.path.join(out, name, "metrics-eevee-truth", ref_id, "metrics.json")
        if block in truth_of_block and os.path.exists(truth_path):
            c = dict(json.load(open(truth_path))["comparisons"][0], pathtraced=c["pathtraced"])
        table[(block, "eevee", "follow-surface")] = c
    for block in sorted({k[0] for k in table}):
        reference = next(c["reference"]["name"] for k, c in table.items() if k[0] == block)
        lines += [f"## {name}: block `{block}` (reference `{reference}`)", "",
                  f"Contact sheet: `{name}/contact.png`; heat maps: `{name}/metrics/heatmaps/`.", "",
                  "Truth of the error metrics: " + truth_of_block.get(block, f"`reference` (`{reference}`)") + ".", ""]
        # Compact pivots, method × extension set, for the bands this block has: the leak energy of halo, bleed and
        # spill, and the mean ΔE00 excess (band mean − interior mean) of halo and bleed.
        pivots = [(band, "leak_energy", f"{band} leak energy") for band in ["halo", "bleed", "spill"]] + \
                 [(band, "excess", f"{band} mean ΔE00 excess") for band in ["halo", "bleed"]]
        # The same halo/bleed leak energies against the path-traced reference (its bands: from its own depth and mask).
        pivots += [(band, "leak_energy", f"{band} leak energy against `pathtraced`", "pathtraced") for band in ["halo", "bleed"]]
        # The table's scores ranked against Cycles (debiased, --compare-metrics): a score whose τ_b over the 16
        # conditions closest to Cycles is below 0.8 does not rank the conditions as the path tracer does and is
        # withdrawn from this block's tables.
        withdrawn = {}
        # Against the seed mean: its scores ranked against Cycles' debiased ranking (metrics-truth-debiased).
        agreement = (debiased.get(block) or {}).get("table_score_agreement", {})
        if block in truth_of_block:
            ref_id = next(s["id"] for s in manifest["stimuli"] if s["reference"] and s["block"] == block)
            path = os.path.join(out, name, "metrics-truth-debiased", ref_id, "debiased.json")
            agreement = json.load(open(path)).get("table_score_agreement", {}) if os.path.exists(path) else {}
        if agreement:
            against = "the Cycles seed mean" if block in truth_of_block else "`reference`"
            lines += [f"Scores against {against} ranked against Cycles (τ_b [seed jackknife, t] [bootstrap over conditions "
                      "and seeds], 95 %; 16 closest: the conditions with the smallest debiased error against Cycles in the "
                      "score's band; withdrawn below 0.8 there; docs/pathtraced.md, \"Reading the agreement\"):", "",
                      "| score | τ_b all | τ_b 16 closest | kept |", "|---|---|---|---|"]
            def tau_text(a):
                if a["tau_b"]["value"] is None: return "–"
                jack, boot = a.get("tau_b_interval_95"), a.get("tau_b_bootstrap_interval_95")
                return (f"{a['tau_b']['value']:+.2f}" + (f" [{jack[0]:+.2f}, {jack[1]:+.2f}]" if jack else " [–]")
                        + (f" [{boot[0]:+.2f}, {boot[1]:+.2f}]" if boot else " [–]"))
            for score, a in agreement.items():
                tau = a["competitive"]["tau_b"]["value"]
                if tau is None: continue
                if tau < 0.8:
                    withdrawn[score] = f"τ_b {tau:+.2f} over the 16 conditions closest to Cycles"
                lines.append(f"| {score} | {tau_text(a)} | {tau_text(a['competitive'])} | "
                             + ("**withdrawn**" if tau < 0.8 else "yes") + " |")
            lines.append("")
        for band, score, caption, *against in pivots:
            pick = (lambda c: c.get("pathtraced")) if against else (lambda c: c)
            cells = [pick(c) for k, c in table.items() if k[0] == block]
            if not any(c is not None and c["bands"][band]["pixels"] > 0 for c in cells): continue
            if not against and f"{band}_{score}" in withdrawn:
                lines += [f"{caption}: withdrawn ({withdrawn[f'{band}_{score}']}, below 0.8: it does not rank the "
                          "conditions as the path tracer does).", ""]
                continue
            lines += [f"{caption}:", "", "| method | " + " | ".join(extension_sets) + " |",
                      "|---|" + "---|" * len(extension_sets)]
            for method in methods + ["eevee"]:
                row = [table.get((block, method, e)) for e in extension_sets]
                row = [None if c is None else pick(c) for c in row]
                if all(c is None for c in row): continue
                lines.append(f"| {method} | " + " | ".join(
                    "–" if c is None else number(c["bands"][band][score], 2) for c in row) + " |")
            lines.append("")
        d = debiased.get(block)
        for band in ["halo", "bleed"] if d else []:
            own = d["compared_reference"]["regions"][band]
            if not own["pixels"]: continue
            agree = d["ranking_agreement"][band]
            interval = agree["tau_b_interval_95"]  # none with two seeds (no jackknife)
            interval = "[–]" if not interval else f"[{interval[0]:+.2f}, {interval[1]:+.2f}]"
            lines += [f"{band} band, MSE of Y against the noise-free path-traced image ({len(d['seeds'])} seeds, "
                      f"debiased): `reference` itself {number(own['mse']['value'])} ± {number(own['mse']['standard_error'])}; "
                      f"τ_b between the conditions' rankings under the two references {agree['tau_b']['value']:+.2f} "
                      f"{interval}, {agree['concordant_separated_pairs']} of {agree['separated_pairs']} "
                      "pairs the path tracer separates ordered alike:", "",
                      "| method | " + " | ".join(extension_sets) + " |", "|---|" + "---|" * len(extension_sets)]
            for method in methods:
                row = [table.get((block, method, e)) for e in extension_sets]
                row = [None if c is None else d["by_stimulus"].get(c["test"]["name"]) for c in row]
                if all(t is None for t in row): continue
                lines.append(f"| {method} | " + " | ".join(
                    "–" if t is None else number(t["regions"][band]["mse"]["value"], 2) for t in row) + " |")
            lines.append("")
        lines += ["All scores:", "",
                  "| method | extensions | halo E | bleed E | spill E | halo ΔE00 excess | bleed ΔE00 excess | skin ΔE00 mean "
                  "| halo E (pathtraced) | bleed E (pathtraced) |",
                  "|---|---|---|---|---|---|---|---|---|---|"]
        for method in methods + ["eevee"]:
            for extension in extension_sets:
                c = table.get((block, method, extension))
                if c is None: continue
                b = c["bands"]
                kept = lambda name, value: "withdrawn" if name in withdrawn else number(value)
                lines.append(f"| {method} | {extension} | {kept('halo_leak_energy', b['halo']['leak_energy'])} | "
                             f"{kept('bleed_leak_energy', b['bleed']['leak_energy'])} | {kept('spill_leak_energy', b['spill']['leak_energy'])} | "
                             f"{kept('halo_excess', b['halo']['excess'])} | {kept('bleed_excess', b['bleed']['excess'])} | "
                             f"{kept('skin_delta_e00_mean', c['skin']['delta_e00_mean'])} | "
                             f"{'–' if c['pathtraced'] is None else number(c['pathtraced']['bands']['halo']['leak_energy'])} | "
                             f"{'–' if c['pathtraced'] is None else number(c['pathtraced']['bands']['bleed']['leak_energy'])} |")
        lines.append("")
path = os.path.join(out, "extensions-table.md")
with open(path + ".tmp", "w") as f:
    f.write("\n".join(lines))
os.replace(path + ".tmp", path)  # atomic, as every output of the project
print(f"extensions-table: {path}")
PYTHON
