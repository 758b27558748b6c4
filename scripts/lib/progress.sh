# Progress for long, otherwise silent steps of the shell scripts (sourced, not run).
#
# run_with_progress LABEL LOG STATUS CMD...
#   Runs CMD with its output appended to LOG (the whole log is kept) and, while it runs, prints "LABEL: STATUS-LINE
#   (N s)" when the status line changes (at most every SKINLAB_PROGRESS_EVERY seconds, default 5) and at least every
#   SKINLAB_PROGRESS_QUIET seconds (default 20) even when it does not. STATUS is a function called with LOG that
#   prints the status line (e.g. apt_status); "-" prints "still running". Returns CMD's exit status.
run_with_progress() {
  local label=$1 log=$2 status=$3
  shift 3
  "$@" >>"$log" 2>&1 &
  local pid=$! start=$SECONDS last=$SECONDS line previous="" rc=0
  while kill -0 "$pid" 2>/dev/null; do
    sleep "${SKINLAB_PROGRESS_POLL:-1}"
    kill -0 "$pid" 2>/dev/null || break
    if [ "$status" = - ]; then line="still running"; else line=$("$status" "$log" || true); fi
    [ -n "$line" ] || line="still running"
    if { [ "$line" != "$previous" ] && [ $((SECONDS - last)) -ge "${SKINLAB_PROGRESS_EVERY:-5}" ]; } ||
      [ $((SECONDS - last)) -ge "${SKINLAB_PROGRESS_QUIET:-20}" ]; then
      echo "$label: $line ($((SECONDS - start)) s)"
      previous=$line
      last=$SECONDS
    fi
  done
  wait "$pid" || rc=$?
  return "$rc"
}

# apt_status LOG FIRST TOTAL: apt-get install's progress from its log, counted from line FIRST on: "12/85 packages
# downloaded", then "unpacked", then "set up" (dpkg's "Unpacking …" and "Setting up …" lines).
apt_status() {
  local log=$1 first=$2 total=$3 got unpacked setup
  got=$(tail -n "+$first" "$log" | grep -c '^Get:' || true)
  unpacked=$(tail -n "+$first" "$log" | grep -c '^Unpacking ' || true)
  setup=$(tail -n "+$first" "$log" | grep -c '^Setting up ' || true)
  if [ "$setup" -gt 0 ]; then echo "$setup/$total packages set up"
  elif [ "$unpacked" -gt 0 ]; then echo "$unpacked/$total packages unpacked"
  elif [ "$got" -gt 0 ]; then echo "$got/$total packages downloaded"
  else echo "resolving $total packages"
  fi
}

# run_with_heartbeat LABEL CMD...
#   Runs CMD with its output on the console as usual and prints "LABEL: still running (N s)" every
#   SKINLAB_PROGRESS_QUIET seconds (default 20) while it runs, for commands that may compute for a while without a
#   line. Returns CMD's exit status.
run_with_heartbeat() {
  local label=$1
  shift
  "$@" &
  local pid=$! start=$SECONDS last=$SECONDS rc=0
  while kill -0 "$pid" 2>/dev/null; do
    sleep "${SKINLAB_PROGRESS_POLL:-1}"
    if kill -0 "$pid" 2>/dev/null && [ $((SECONDS - last)) -ge "${SKINLAB_PROGRESS_QUIET:-20}" ]; then
      echo "$label: still running ($((SECONDS - start)) s)"
      last=$SECONDS
    fi
  done
  wait "$pid" || rc=$?
  return "$rc"
}
