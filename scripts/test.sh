#!/usr/bin/env bash
# The test command: sets everything up on a fresh Debian 12 machine, builds, and runs every test with ctest.
# GL tests render through EGL (Mesa llvmpipe without a GPU); tests that need the scanned head look in
# $SKINLAB_ASSETS (default ../shared/assets) and skip with a message when it is absent.
# Network: Debian's package registry (missing packages) and the npm registry (the browser tests' playwright-core),
# both before the build, so that a blocked network fails within the first minutes, with the cause and the fix.
set -euo pipefail
cd "$(dirname "$0")/.."
# Every package the tests use, then what the tests download, then the build (warnings are errors, as in the main
# job's build; build.sh finds every package present).
bash scripts/install-deps.sh all
bash scripts/fetch-test-deps.sh
SKINLAB_DEPS=all bash scripts/build.sh
# Tests that need the assets skip with a message when SKINLAB_ASSETS is unset: point it at the default folder only
# when that folder exists.
if [ -z "${SKINLAB_ASSETS:-}" ] && [ -d ../shared/assets ]; then
  SKINLAB_ASSETS="$(cd ../shared/assets && pwd)"
fi
if [ -n "${SKINLAB_ASSETS:-}" ]; then export SKINLAB_ASSETS; fi
echo "test: running the tests (ctest -j $(nproc); each test's result as it ends)"
ctest --preset release -j "$(nproc)" "$@"
