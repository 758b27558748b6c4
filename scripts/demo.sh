#!/usr/bin/env bash
# The main job, end to end, on a fresh Debian 12 machine (no GPU needed):
#   1. installs missing packages and builds (scripts/build.sh);
#   2. builds the demo stimulus set (every SSS method and the main extensions, each in a view where it makes a
#      visible difference, cropped and magnified) with a contact sheet: stimuli/specs/demo-scan.toml, with the scanned
#      head's face, when its assets are found ($SKINLAB_ASSETS, default ../shared/assets), otherwise
#      stimuli/specs/demo.toml (built-in scenes only), with a message saying so;
#   3. creates a 2AFC study from it, estimates how many observers it needs for the differences ColorVideoVDP
#      predicts (study plan), serves it on loopback and runs 20 simulated observers through the real HTTP API, who
#      answer from those predictions (study simulate --truth predicted);
#   4. scales the answers to JOD with confidence intervals;
#   5. writes the study report (HTML + PDF): stimuli, scale, objective errors against the object-space reference,
#      metrics against the scale, findings;
# and prints where everything is, and the command for a session with a real participant.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/lib/progress.sh
# Only what the main job uses: the packages of the "demo" profile and the `skinlab` executable.
SKINLAB_DEPS=demo bash scripts/build.sh skinlab
export SKINLAB_ASSETS="${SKINLAB_ASSETS:-$(cd .. && pwd)/shared/assets}"
skinlab=./build/release/cli/skinlab
out=out/demo
mkdir -p "$out"

# Each method and extension where it makes a visible difference (docs/stimuli.md, "Measured visibility"): a
# silhouette over a backdrop at a depth gap and paint inside the skin mask (built-in scenes), and with the scanned
# head its nose and lips.
if [ -e "$SKINLAB_ASSETS/LeePerrySmith/LeePerrySmith.glb" ]; then
  stimuli_spec=stimuli/specs/demo-scan.toml design=experiments/designs/demo-scan.toml
  echo "demo: with the scanned head (assets in $SKINLAB_ASSETS)"
else
  stimuli_spec=stimuli/specs/demo.toml design=experiments/designs/demo.toml
  echo "demo: scanned head not found (\$SKINLAB_ASSETS/LeePerrySmith/LeePerrySmith.glb, SKINLAB_ASSETS=$SKINLAB_ASSETS);" \
    "built-in scenes only"
fi
# A rerun after a switch between the two sets starts from an empty stimulus folder (a set folder holds one set).
set_name=$(sed -n 's/^name = "\(.*\)"$/\1/p' "$stimuli_spec" | head -n 1)  # [set] comes first
if [ -e "$out/stimuli/manifest.json" ] && ! grep -q "\"set\": *\"$set_name\"" "$out/stimuli/manifest.json"; then
  rm -rf "$out/stimuli"
fi
echo "demo: rendering the stimulus set $stimuli_spec (every block, each with its reference; then each stimulus's" \
  "visibility against its block's reference, predicted by ColorVideoVDP)"
run_with_heartbeat demo "$skinlab" stimuli build "$stimuli_spec" -o "$out/stimuli"

# A demo study is recreated on every run (a real study is never overwritten by `study create`).
rm -f "$out/study.db" "$out/study.db-wal" "$out/study.db-shm"
echo "demo: a 2AFC study of every block ($design)"
"$skinlab" study create --stimuli "$out/stimuli" --design "$design" -o "$out/study.db"
# Before recruiting: which predicted differences would a study of this design resolve, with how many observers?
echo "demo: study plan: how many observers this design needs for the predicted differences (100 simulated studies" \
  "per observer count)"
run_with_heartbeat demo "$skinlab" study plan "$out/study.db" --simulations 100 --observers 10,20,40,80,160

"$skinlab" study serve "$out/study.db" --port 0 > "$out/serve.log" 2>&1 &
server=$!
trap 'kill $server 2>/dev/null || true' EXIT
url=""
for _ in $(seq 1 100); do
  url=$(sed -n 's/^serving .* on \(http[^ ]*\)$/\1/p' "$out/serve.log" | head -n 1)
  [ -n "$url" ] && break
  sleep 0.1
done
[ -n "$url" ] || { echo "demo: the study server did not start:" >&2; cat "$out/serve.log" >&2; exit 1; }
echo "demo: 20 simulated observers answer through the real HTTP API, from the same predictions"
run_with_heartbeat demo "$skinlab" study simulate "$out/study.db" --observer-count 20 --truth predicted \
  --seed 7 --label-prefix demo --url "$url"
kill $server; wait $server 2>/dev/null || true
trap - EXIT

"$skinlab" study export "$out/study.db" --format csv -o "$out/responses.csv"
echo "demo: the answers scaled to JOD with intervals"
run_with_heartbeat demo "$skinlab" analyze scale "$out/study.db" -o "$out/scale"
cat <<TXT
demo: reading the outcome against the plan: the plan's "significant neighbouring pairs to expect" at 20 observers is
  what one study of 20 observers should find on average; "significant pairs" above counts every pair of a block (pairs
  further apart than neighbours too) in one such study, so a count near the expectation, or above it by the
  non-neighbouring pairs, agrees with the plan. A block the plan does not resolve has one neighbouring pair too
  close to come out; its other pairs can. A pair of equal conditions comes out significant in under 5 % of studies
  (Holm's correction over the block's pairs).
TXT
echo "demo: the study report (HTML, then the PDF through headless Chromium)"
run_with_heartbeat demo "$skinlab" report "$out/study.db" -o "$out/report"

cat <<TXT

demo: done
  contact sheet:   $(pwd)/$out/stimuli/contact.html  (and contact.png)
  stimuli:         $(pwd)/$out/stimuli/manifest.json
  study database:  $(pwd)/$out/study.db  (20 simulated observers; responses in $out/responses.csv)
  JOD scale:       $(pwd)/$out/scale/report_section.html  (scale.json, scores.csv, plots)
  study report:    $(pwd)/$out/report/index.html  (and report.pdf)
  a session with a real participant:
    $skinlab study serve $out/study.db        # then open the printed participant link in a browser
TXT
