#!/usr/bin/env bash
# One benchmark smoke run (bench/CMakeLists.txt, ctest label bench-smoke): runs COMMAND in a fresh folder DIR with
# TMPDIR=DIR, so that runs in parallel (and the benchmarks' fixed scratch names under the temporary folder) never
# share files, and removes DIR when COMMAND succeeds.
#   bench/smoke_run.sh DIR COMMAND [ARGS...]
set -euo pipefail
dir=$1
shift
rm -rf "$dir"
mkdir -p "$dir"
cd "$dir"
export TMPDIR=$dir
"$@"
cd /
rm -rf "$dir"
