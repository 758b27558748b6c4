#!/usr/bin/env bash
# A stimulus set built through a real Slurm: brings up a single-node cluster on this machine (munged, slurmctld
# and slurmd on free loopback ports, every file in a temporary folder; tests/stimuli/slurm_cluster.sh), then
#  1. `skinlab stimuli slurm SPEC -o A --shards 4` (after one refused by sbatch for an unknown partition): a
#     4-task array and a merge job (afterok); the merged set must
#     equal a local build (ids, order, manifest entries, every image's sha256) and `stimuli status` must say done;
#  2. the same into B, where one running task is requeued midway (`scontrol requeue`, as on preemption) and
#     another one's renderer is killed midway (SIGKILL, as on a crash): the requeued task resumes its shard, the killed one
#     is reported failed with its log, is resubmitted alone (`--only-shard`), and the merged set again equals the
#     local build, with no temporary file left anywhere.
# Usage: slurm_cluster_test.sh SKINLAB_CLI SOURCE_DIR. Exits 77 (skipped) when Slurm, munge or jq is missing, no
# cgroup filesystem is mounted, or no EGL renderer works; it needs to run as root (CI) or as a user allowed to start the daemons.
set -euo pipefail

SKINLAB="$1"
SOURCE_DIR="$2"
SPEC="$SOURCE_DIR/tests/data/stimuli/cluster-small.toml"

skip() {
  echo "SKIPPED: $*"
  exit 77
}
source "$SOURCE_DIR/tests/stimuli/slurm_cluster.sh"
slurm_cluster_require

# Short paths: the munge socket path must fit a sockaddr_un (108 bytes).
WORK=$(mktemp -d "${TMPDIR:-/tmp}/skinlab-slurm.XXXXXX")
passed=0
finish() {
  slurm_cluster_stop
  if [ "$passed" = 1 ]; then
    rm -rf "$WORK"
  else
    echo "slurm_cluster_test: FAILED; files kept in $WORK"
    [ -n "${SLURM_CLUSTER_DIR:-}" ] && slurm_cluster_logs
    for f in "$WORK"/*/slurm/logs/*.log; do [ -f "$f" ] && { echo "----- $f"; tail -n 20 "$f"; }; done
  fi
}
trap finish EXIT

fail() {
  echo "slurm_cluster_test: FAIL: $*"
  exit 1
}

# The reference: a local build of the same spec.
if ! "$SKINLAB" stimuli build "$SPEC" -o "$WORK/local" --no-contact-sheet --progress lines >"$WORK/local.log" 2>&1; then
  if grep -q "no usable EGL" "$WORK/local.log"; then skip "no EGL renderer: $(tail -n 1 "$WORK/local.log")"; fi
  cat "$WORK/local.log"
  fail "the local build failed"
fi

slurm_cluster_start "$WORK/cluster" || fail "the single-node cluster did not start"

# A manifest without the fields that differ between runs (timings) and the shard field.
normalised() { jq -S 'del(.shard) | .stimuli |= map(del(.timings_ms))' "$1/manifest.json"; }

# Checks that DIR holds the same set as the local build: manifest (minus timings), every file's sha256.
same_as_local() {
  local dir="$1"
  [ -f "$dir/manifest.json" ] || fail "$dir: no manifest.json"
  [ "$(jq -r .complete "$dir/manifest.json")" = true ] || fail "$dir: manifest not complete"
  diff <(normalised "$WORK/local") <(normalised "$dir") >"$WORK/diff.txt" || { cat "$WORK/diff.txt"; fail "$dir: manifest differs from the local build"; }
  local n=0 id file
  while IFS=$'\t' read -r id file sum; do
    [ "$(sha256sum "$dir/$file" | cut -d' ' -f1)" = "$sum" ] || fail "$dir/$file: sha256 differs from its manifest"
    [ "$(sha256sum "$WORK/local/$file" | cut -d' ' -f1)" = "$sum" ] || fail "$file differs from the local build"
    n=$((n + 1))
  done < <(jq -r '.stimuli[] | (.id + "\t" + .files.exr + "\t" + .sha256.exr), (.id + "\t" + .files.png + "\t" + .sha256.png)' "$dir/manifest.json")
  [ "$n" = 24 ] || fail "$dir: $n image files, expected 24"
  if find "$dir/.." -name '.*.tmp-*' | grep -q .; then fail "temporary files left: $(find "$dir/.." -name '.*.tmp-*')"; fi
  echo "slurm_cluster_test: $dir equals the local build (12 stimuli, 24 files, manifest)"
}

# Waits (at most $2 s) until none of the given jobs is pending or running, except jobs waiting on a dependency
# that can never be satisfied.
wait_jobs() {
  local jobs="$1" limit="$2" start=$SECONDS active
  while true; do
    active=$(squeue -h -j "$jobs" -o '%T %r' 2>/dev/null | grep -v 'DependencyNeverSatisfied' | grep -c -E 'PENDING|RUNNING|CONFIGURING|COMPLETING|REQUEUE' || true)
    [ "$active" = 0 ] && return 0
    [ $((SECONDS - start)) -gt "$limit" ] && { squeue; fail "jobs $jobs still active after ${limit}s"; }
    sleep 0.5
  done
}

# "array job 12 (...), merge job 13" → "12 13"
job_ids() { sed -n "s/^stimuli: set '[^']*': array job \([0-9]*\) .*merge job \([0-9]*\) .*/\1 \2/p" "$1"; }

# ---- 1. a clean run ----------------------------------------------------------------------------------------------
# sbatch's own refusal is one line naming the script; the corrected command may then use the same folder.
if "$SKINLAB" stimuli slurm "$SPEC" -o "$WORK/A" --shards 4 --partition nope >"$WORK/A.refused" 2>&1; then
  fail "a submission to an unknown partition succeeded"
fi
grep -q "^skinlab: failure: sbatch $WORK/A/slurm/build.sbatch failed (exit 1): sbatch: error: .*partition" "$WORK/A.refused" &&
  [ "$(wc -l <"$WORK/A.refused")" = 1 ] || { cat "$WORK/A.refused"; fail "sbatch's refusal is not one clear line"; }
t0=$SECONDS
"$SKINLAB" stimuli slurm "$SPEC" -o "$WORK/A" --shards 4 --time 10:00 >"$WORK/A.submit" 2>&1 || { cat "$WORK/A.submit"; fail "submission A failed"; }
cat "$WORK/A.submit"
read -r arrayA mergeA < <(job_ids "$WORK/A.submit")
[ -n "$mergeA" ] || fail "no job ids in the submission's output"
wait_jobs "$arrayA,$mergeA" 120
echo "slurm_cluster_test: run A (4 tasks + merge) took $((SECONDS - t0)) s"
"$SKINLAB" stimuli status "$WORK/A" | tee "$WORK/A.status"
[ "$(grep -c '^shard [1-4]/4  done ' "$WORK/A.status")" = 4 ] || fail "status of A: not every shard done"
grep -q "^merge  done  job $mergeA" "$WORK/A.status" || fail "status of A: merge not done"
same_as_local "$WORK/A/set"

# ---- 2. a requeued task and a killed task ----------------------------------------------------------------------
t0=$SECONDS
"$SKINLAB" stimuli slurm "$SPEC" -o "$WORK/B" --shards 4 --time 10:00 >"$WORK/B.submit" 2>&1 || { cat "$WORK/B.submit"; fail "submission B failed"; }
read -r arrayB mergeB < <(job_ids "$WORK/B.submit")
[ -n "$mergeB" ] || fail "no job ids in the submission's output"

# The watch loop below forks nothing (bash builtins only), so that it sees every task between its stimuli even on
# a loaded machine.
# Stimuli of shard I listed in its manifest so far (one "stimulus_wall" timing per entry).
done_count() {
  local text="" rest
  [ -f "$WORK/B/shards/$1/manifest.json" ] && text=$(<"$WORK/B/shards/$1/manifest.json")
  rest=${text//\"stimulus_wall\"/}
  echo $(((${#text} - ${#rest}) / 15))
}
# The pid of the skinlab process building shard I (recorded in its folder's build lock: "pid P on HOST").
renderer_pid() {
  local word p comm=""
  read -r word p _ <"$WORK/B/shards/$1/.skinlab-build.lock" 2>/dev/null || return 1
  read -r comm <"/proc/$p/comm" 2>/dev/null || return 1
  [ "$comm" = skinlab ] || return 1
  echo "$p"
}
# Midway = the shard's manifest lists 1 or 2 of its 3 stimuli. Two tasks are frozen (SIGSTOP to their renderer)
# as soon as each is seen midway, so that neither can move on; then the first is requeued (`scontrol requeue`, as
# on preemption; Slurm kills the frozen task and starts it again) and the second one's renderer is killed
# (SIGKILL, as on a crash or the kernel's OOM killer): that task fails.
frozen=() frozen_pid=() frozen_n=() start=$SECONDS
while [ "${#frozen[@]}" -lt 2 ]; do
  for i in 1 2 3 4; do
    [ "${#frozen[@]}" -lt 2 ] || break
    case " ${frozen[*]} " in *" $i "*) continue ;; esac
    n=$(done_count "$i")
    if [ "$n" -lt 1 ] || [ "$n" -ge 3 ]; then continue; fi
    pid=$(renderer_pid "$i") || continue
    kill -STOP "$pid" 2>/dev/null || continue
    n=$(done_count "$i")
    if [ "$n" -ge 3 ]; then kill -CONT "$pid" 2>/dev/null || true; continue; fi  # it finished meanwhile
    frozen+=("$i") frozen_pid+=("$pid") frozen_n+=("$n")
  done
  if [ $((SECONDS - start)) -gt 90 ]; then
    for pid in "${frozen_pid[@]}"; do kill -CONT "$pid" 2>/dev/null || true; done
    fail "could not catch two tasks midway (caught: ${frozen[*]})"
  fi
  sleep 0.01
done
requeued=${frozen[0]} killed=${frozen[1]}
scontrol requeue "${arrayB}_$((requeued - 1))"
echo "slurm_cluster_test: requeued shard $requeued midway (${frozen_n[0]}/3 done)"
kill -KILL "${frozen_pid[1]}"
echo "slurm_cluster_test: killed shard $killed's renderer midway (${frozen_n[1]}/3 done)"
wait_jobs "$arrayB" 120
"$SKINLAB" stimuli status "$WORK/B" | tee "$WORK/B.status"
grep -q "^shard $killed/4  failed " "$WORK/B.status" || fail "status of B: the killed shard $killed is not reported failed"
grep -q "^    log: $WORK/B/slurm/logs/build-${arrayB}_$((killed - 1)).log\$" "$WORK/B.status" || fail "status of B: no log of the failed shard"
grep -q "^resubmit shard $killed: skinlab stimuli slurm .* --only-shard $killed\$" "$WORK/B.status" || fail "status of B: no resubmit line"
grep -q "^    skinlab: shard $killed/4 failed: exit status 137 (signal 9)$" "$WORK/B.status" || fail "status of B: no error line of the killed shard"
grep -q "^shard $requeued/4  done " "$WORK/B.status" || fail "status of B: the requeued shard $requeued is not done"
[ "$(grep -c '^skinlab: shard [0-9]*/4 of set' "$WORK/B/slurm/logs/build-${arrayB}_$((requeued - 1)).log")" = 2 ] ||
  fail "the requeued task's log does not show two starts"
grep -q -E "stimuli: set 'cluster-small': 3 stimuli, [12] unchanged, [12] to render" \
  "$WORK/B/slurm/logs/build-${arrayB}_$((requeued - 1)).log" || fail "the requeued task did not resume its shard"
grep -q "^merge  pending .*job $mergeB" "$WORK/B.status" || fail "status of B: the merge is not reported pending"
[ -f "$WORK/B/set/manifest.json" ] && fail "the merge ran although a shard failed"

"$SKINLAB" stimuli slurm "$SPEC" -o "$WORK/B" --shards 4 --time 10:00 --only-shard "$killed" >"$WORK/B.resubmit" 2>&1 ||
  { cat "$WORK/B.resubmit"; fail "resubmission of shard $killed failed"; }
cat "$WORK/B.resubmit"
grep -q "cancelled the earlier merge job $mergeB" "$WORK/B.resubmit" || fail "the earlier merge job was not cancelled"
read -r arrayC mergeC < <(job_ids "$WORK/B.resubmit")
wait_jobs "$arrayC,$mergeC" 120
grep -q -E "stimuli: set 'cluster-small': 3 stimuli, [12] unchanged, [12] to render" \
  "$WORK/B/slurm/logs/build-${arrayC}_$((killed - 1)).log" || fail "the resubmitted shard did not resume"
echo "slurm_cluster_test: run B (requeue, kill, resubmit, merge) took $((SECONDS - t0)) s"
"$SKINLAB" stimuli status "$WORK/B" | tee "$WORK/B.status2"
[ "$(grep -c '^shard [1-4]/4  done ' "$WORK/B.status2")" = 4 ] || fail "status of B after the resubmission: not every shard done"
grep -q "^merge  done  job $mergeC" "$WORK/B.status2" || fail "status of B: the new merge is not done"
same_as_local "$WORK/B/set"

passed=1
echo "slurm_cluster_test: PASS"
