#!/usr/bin/env bash
# Stimulus sets on Slurm: how long a stimulus takes, and what the Slurm path adds, on this machine.
# Builds SPEC locally (one renderer), then through a single-node Slurm cluster brought up in a temporary folder
# (tests/stimuli/slurm_cluster.sh) with `skinlab stimuli slurm SPEC --shards N`, and prints:
#  - the local build's wall time and the per-stimulus wall times from its manifest (timings_ms.stimulus_wall:
#    render + EXR/PNG write + hash), so a reader can size shards: stimuli × seconds per stimulus;
#  - the Slurm build's wall time from submission to the merged set, each task's own build time (from its log) and
#    the start cost of a task (its build time minus the sum of its stimuli);
#  - whether the merged set equals the local build, hash for hash.
# Usage: bench/stimuli/bench_slurm.sh SKINLAB SPEC [SHARDS=4] [--set key=value ...]  (as root; needs slurm-wlm,
# munge, jq; SKINLAB_ASSETS for specs that use the scanned head). Exits 77 where the cluster cannot run here.
set -euo pipefail
SKINLAB=$(readlink -f "$1")
SPEC=$(readlink -f "$2")
SHARDS=${3:-4}
shift $(($# < 3 ? $# : 3))
EXTRA=("$@")
HERE=$(cd "$(dirname "$0")/../.." && pwd)
source "$HERE/tests/stimuli/slurm_cluster.sh"
slurm_cluster_require # exits 77 (skipped) without Slurm, munge, jq, root or cgroups

WORK=$(mktemp -d "${TMPDIR:-/tmp}/skinlab-bench-slurm.XXXXXX")
# The cluster's sockets need short paths (a sockaddr_un holds 108 bytes): always under /tmp.
CLUSTER=$(mktemp -d /tmp/skinlab-slurm.XXXXXX)
trap 'slurm_cluster_stop; rm -rf "$WORK" "$CLUSTER"' EXIT
trap 'exit 143' TERM INT

echo "machine: $(nproc) cores, load average $(cut -d' ' -f1-3 /proc/loadavg) at the start, $(date -u +%Y-%m-%dT%H:%M:%SZ)"
t0=$(date +%s.%N)
TIMEFORMAT='%U %S'
cpu=$({ time "$SKINLAB" stimuli build "$SPEC" -o "$WORK/local" --no-contact-sheet --progress lines "${EXTRA[@]}" \
  >"$WORK/local.log" 2>&1; } 2>&1)
t1=$(date +%s.%N)
echo "local build CPU time (user + system, all threads): $(echo "$cpu" | awk '{printf "%.1f", $1 + $2}') s"
jq -r '.renderer.gl_renderer' "$WORK/local/manifest.json" | sed 's/^/renderer: /'
jq -r --arg wall "$(awk -v a="$t0" -v b="$t1" 'BEGIN {print b - a}')" '
  [.stimuli[].timings_ms.stimulus_wall / 1000] as $t | ($t | sort) as $s |
  "local build: \(.stimuli | length) stimuli at \(.stimuli[0].width)x\(.stimuli[0].height) in \($wall | tonumber * 10 | round / 10) s; " +
  "per stimulus: mean \(($t | add / length) * 100 | round / 100) s, median \($s[(($s | length) / 2 | floor)] * 100 | round / 100) s, " +
  "min \($s[0] * 100 | round / 100) s, max \($s[-1] * 100 | round / 100) s; start (wall - sum) \((($wall | tonumber) - ($t | add)) * 10 | round / 10) s"' \
  "$WORK/local/manifest.json"
jq -r '.stimuli[] | select(.reference) | "  reference \(.id): \(.timings_ms.stimulus_wall / 1000 * 10 | round / 10) s"' "$WORK/local/manifest.json"

slurm_cluster_start "$CLUSTER" >/dev/null
t0=$(date +%s.%N)
out=$("$SKINLAB" stimuli slurm "$SPEC" -o "$WORK/slurm" --shards "$SHARDS" "${EXTRA[@]}")
array=$(echo "$out" | sed -n "s/.*array job \([0-9]*\) .*merge job \([0-9]*\) .*/\1/p")
merge=$(echo "$out" | sed -n "s/.*array job \([0-9]*\) .*merge job \([0-9]*\) .*/\2/p")
while [ -n "$(squeue -h -j "$array,$merge" -o %A 2>/dev/null)" ]; do sleep 0.2; done
t1=$(date +%s.%N)
echo "slurm build: $SHARDS tasks + merge, submission to merged set: $(awk -v a="$t0" -v b="$t1" 'BEGIN {printf "%.1f", b - a}') s"
for i in $(seq 1 "$SHARDS"); do
  log="$WORK/slurm/slurm/logs/build-${array}_$((i - 1)).log"
  task=$(sed -n 's/^stimuli: \([0-9]*\) stimuli (.*) in \([0-9.]*\) s;.*/\1 \2/p' "$log")
  sum=$(jq '[.stimuli[].timings_ms.stimulus_wall] | add / 1000' "$WORK/slurm/shards/$i/manifest.json")
  echo "  task $i: ${task% *} stimuli, build ${task#* } s, of it stimuli $(printf '%.1f' "$sum") s"
done
cmp <(jq -S '[.stimuli[] | {id, sha256}]' "$WORK/local/manifest.json") \
    <(jq -S '[.stimuli[] | {id, sha256}]' "$WORK/slurm/set/manifest.json") >/dev/null &&
  echo "merged set equals the local build (every sha256)" || echo "MERGED SET DIFFERS FROM THE LOCAL BUILD"
