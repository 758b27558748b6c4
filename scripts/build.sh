#!/usr/bin/env bash
# Installs missing Debian packages, configures (CMake preset "release") and builds everything.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
cmake --preset release >/dev/null
cmake --build --preset release -j "$(nproc)"
