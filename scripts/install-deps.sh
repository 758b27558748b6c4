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
  libsqlite3-dev sqlite3 libssl-dev
  libboost-dev   # Boost.Beast/Asio (header-only): the study server's event-driven HTTP layer
  # tests and benchmarks
  libgtest-dev libgmock-dev libbenchmark-dev
  # browser test of the participant page
  chromium nodejs   # npm: see below
  fonts-dejavu-core   # stimuli: captions of contact.png (OpenImageIO render_text needs a TrueType font)
  curl   # tests: the server-defect checks send raw HTTP
  clang-format   # tests: style_clang_format checks every C++ file against .clang-format
  slurm-wlm munge jq   # stimuli: the single-node Slurm cluster test (slurmctld, slurmd, sbatch; munged; jq reads manifests)
  blender   # the pathtraced method: Cycles runs as a child process (docs/pathtraced.md)
  nginx openssl   # online studies: the HTTPS deployment test (nginx in front of the server, a self-signed certificate)
)

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

# npm: Debian 12's nodejs package has none, so Debian's npm is installed then; a Node.js from elsewhere (e.g.
# nodesource) brings its own npm, which Debian's npm package conflicts with, so it is installed only when absent.
if ! command -v npm >/dev/null 2>&1; then
  missing+=(npm)
fi

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
