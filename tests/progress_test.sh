#!/usr/bin/env bash
# scripts/lib/progress.sh: a long step prints a count while it runs (here apt's log lines, written over ~4 s by a
# stand-in for apt-get), keeps the whole log, and passes the command's exit status on.
set -euo pipefail
source "$(dirname "$0")/../scripts/lib/progress.sh"
dir=$(mktemp -d "${TMPDIR:-/tmp}/skinlab-progress.XXXXXX")
trap 'rm -rf "$dir"' EXIT
log=$dir/apt.log
echo "Hit:1 http://deb.debian.org/debian bookworm InRelease" >"$log"
first=2
fake_apt() {
  for p in a b c; do echo "Get:1 http://deb.debian.org/debian bookworm/main amd64 $p 1.0 [10 kB]"; done
  sleep 1.2
  for p in a b; do echo "Unpacking $p (1.0) ..."; done
  sleep 1.2
  for p in a b c; do echo "Setting up $p (1.0) ..."; done
  sleep 1.2
  return 3
}
status() { apt_status "$1" "$first" 3; }
rc=0
out=$(SKINLAB_PROGRESS_POLL=0.2 SKINLAB_PROGRESS_EVERY=1 run_with_progress install-deps "$log" status fake_apt) || rc=$?
echo "$out"
fail() { echo "progress_test: $*" >&2; exit 1; }
[ "$rc" = 3 ] || fail "exit status $rc, not the command's 3"
grep -q '^install-deps: 2/3 packages unpacked ([0-9]* s)$' <<<"$out" || fail "no unpacked count"
grep -q '^install-deps: 3/3 packages set up ([0-9]* s)$' <<<"$out" || fail "no set-up count"
grep -q '^Unpacking b (1.0) ...$' "$log" || fail "the log lost apt's lines"
grep -q '^Hit:1' "$log" || fail "the log lost its earlier lines"
# A step without a status prints "still running" at least every SKINLAB_PROGRESS_QUIET seconds.
out=$(SKINLAB_PROGRESS_POLL=0.2 SKINLAB_PROGRESS_QUIET=1 run_with_progress npm "$log" - sleep 2.5)
grep -q '^npm: still running ([0-9]* s)$' <<<"$out" || fail "no heartbeat: $out"
# A command that prints its own lines keeps them on the console, with a heartbeat between them.
rc=0
out=$(SKINLAB_PROGRESS_POLL=0.2 SKINLAB_PROGRESS_QUIET=1 run_with_heartbeat plan bash -c 'echo first; sleep 2.5; echo last; exit 4') || rc=$?
[ "$rc" = 4 ] || fail "heartbeat: exit status $rc, not the command's 4"
grep -q '^first$' <<<"$out" && grep -q '^last$' <<<"$out" || fail "heartbeat: the command's lines are lost: $out"
grep -q '^plan: still running ([0-9]* s)$' <<<"$out" || fail "no heartbeat between the lines: $out"
echo "progress_test: ok"
