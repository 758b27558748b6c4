#!/usr/bin/env bash
# The test command: sets everything up on a fresh Debian 12 machine, builds, and runs every test with ctest.
# GL tests render through EGL (Mesa llvmpipe without a GPU); tests that need the scanned head look in
# $SKINLAB_ASSETS (default ../shared/assets) and skip with a message when it is absent.
set -euo pipefail
cd "$(dirname "$0")/.."
# Everything, with every package the tests use (warnings are errors, as in the main job's build).
SKINLAB_DEPS=all bash scripts/build.sh
if [ -f tests/browser/package.json ]; then
  (cd tests/browser && npm install --no-audit --no-fund --loglevel=error >/dev/null)
fi
# Tests that need the assets skip with a message when SKINLAB_ASSETS is unset: point it at the default folder only
# when that folder exists.
if [ -z "${SKINLAB_ASSETS:-}" ] && [ -d ../shared/assets ]; then
  SKINLAB_ASSETS="$(cd ../shared/assets && pwd)"
fi
if [ -n "${SKINLAB_ASSETS:-}" ]; then export SKINLAB_ASSETS; fi
ctest --preset release -j "$(nproc)" "$@"
