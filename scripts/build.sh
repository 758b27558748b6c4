#!/usr/bin/env bash
# Installs missing Debian packages, configures (CMake preset "release") and builds everything.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
# ccache (when present) may reuse objects across clones of the repository in other folders.
export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=true
# SKINLAB_WERROR=ON (scripts/test.sh, hence CI) treats every warning as an error, so e.g. a `switch` over SssMethod
# that misses a method fails the build (-Wall includes -Wswitch).
cmake --preset release -DSKINLAB_WERROR="${SKINLAB_WERROR:-OFF}" >/dev/null
cmake --build --preset release -j "$(nproc)"
