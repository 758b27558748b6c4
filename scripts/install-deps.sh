#!/usr/bin/env bash
# Installs every Debian 12 package skinlab needs to build, test and run (headless, no GPU required).
# Idempotent: only missing packages are installed. Needs root (or sudo) and Debian's package registry.
set -euo pipefail

PACKAGES=(
  # toolchain
  build-essential cmake ninja-build pkg-config git ca-certificates ccache
  # renderer: headless OpenGL through EGL, Mesa llvmpipe on the CPU
  libegl-dev libegl1 libegl-mesa0 libgl1-mesa-dri libgbm1 libepoxy-dev libglm-dev glslang-tools
  # images, colour, meshes
  libopenimageio-dev openimageio-tools libopencolorio-dev libassimp-dev
  # analysis
  libopencv-dev libopencv-contrib-dev libeigen3-dev
  # specs, CLI, logging
  libtomlplusplus-dev nlohmann-json3-dev libcli11-dev libspdlog-dev libfmt-dev
  # experiments: SQLite store, HTTP server, hashing
  libsqlite3-dev sqlite3 libcpp-httplib-dev libssl-dev
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev
  # browser test of the participant page
  chromium nodejs   # npm ships with the machine's Node.js (nodesource); Debian's npm conflicts with it
  fonts-dejavu-core   # stimuli: captions of contact.png (OpenImageIO render_text needs a TrueType font)
  blender   # the pathtraced method: Cycles runs as a child process (docs/pathtraced.md)
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" != 0 ]; then SUDO="sudo"; fi
echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
