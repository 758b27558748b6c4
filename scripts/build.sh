#!/usr/bin/env bash
# Installs missing Debian packages, configures (CMake preset "release") and builds:
#   scripts/build.sh              everything (libraries, the CLI, tests, benchmarks)
#   scripts/build.sh TARGET ...   only those targets (the main job builds `skinlab`)
# SKINLAB_DEPS picks the package profile (scripts/install-deps.sh: demo or all, default all).
# Both README commands configure with the same flags, so the second one reuses what the first one built.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh "${SKINLAB_DEPS:-all}"
# ccache (when present) may reuse objects across clones of the repository in other folders.
export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=true
# Warnings are errors (set SKINLAB_WERROR=OFF to build past them while developing), so e.g. a `switch` over
# SssMethod that misses a method fails the build (-Wall includes -Wswitch).
echo "build: configuring (CMake preset release, build/release)"
cmake --preset release -DSKINLAB_WERROR="${SKINLAB_WERROR:-ON}" >/dev/null
targets=()
for t in "$@"; do targets+=(--target "$t"); done
# ninja prints one "[done/total] Building …" line per step (its counter); nothing is left to build: "no work to do".
echo "build: building ${*:-everything} with $(nproc) jobs"
cmake --build --preset release -j "$(nproc)" "${targets[@]}"
