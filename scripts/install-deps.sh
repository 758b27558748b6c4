#!/usr/bin/env bash
# Installs the Debian 12 packages skinlab needs (headless, no GPU required), quietly (apt's output goes to a log
# that is shown only when the installation fails). Idempotent: only missing packages are installed. Needs root
# (or sudo) and Debian's package registry.
#   scripts/install-deps.sh demo   what the main job needs: build, render, serve, analyse, report (HTML + PDF)
#   scripts/install-deps.sh all    (default) and what the tests need besides: Node.js for the browser tests,
#                                  clang-format, Blender (Cycles), Slurm and munge, nginx, curl and jq
set -euo pipefail
profile="${1:-all}"
case "$profile" in demo | all) ;; *) echo "install-deps: unknown profile '$profile' (demo or all)" >&2; exit 2 ;; esac

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
  libboost-dev   # Boost.Beast/Asio (header-only): the study server's HTTP layer
  # the test and benchmark frameworks (small; the one CMake configuration of both commands finds them)
  libgtest-dev libgmock-dev libbenchmark-dev
  chromium   # the study report's PDF (headless print), and the browser tests
  fonts-dejavu-core   # stimuli: captions of contact.png (OpenImageIO render_text needs a TrueType font)
)
if [ "$profile" = all ]; then
  PACKAGES+=(
    nodejs   # the browser tests (Playwright driving Debian's chromium); npm: see below
    curl   # tests: the server-defect checks send raw HTTP
    clang-format   # tests: style_clang_format checks every C++ file against .clang-format
    slurm-wlm munge jq   # stimuli: the single-node Slurm cluster test (slurmctld, slurmd, sbatch; munged; jq)
    blender   # the pathtraced method: Cycles runs as a child process (docs/pathtraced.md)
    nginx openssl   # online studies: the HTTPS deployment test (nginx in front of the server, self-signed cert)
  )
fi

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

# npm: Debian 12's nodejs package has none, so Debian's npm is installed then; a Node.js from elsewhere (e.g.
# nodesource) brings its own npm, which Debian's npm package conflicts with, so it is installed only when absent.
if [ "$profile" = all ] && ! command -v npm >/dev/null 2>&1; then
  missing+=(npm)
fi

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#PACKAGES[@]} packages of '$profile' present"
  exit 0
fi

SUDO=""
if [ "$(id -u)" != 0 ]; then SUDO="sudo"; fi
log="$(mktemp "${TMPDIR:-/tmp}/skinlab-install-deps.XXXXXX.log")"
echo "install-deps: installing ${#missing[@]} packages for '$profile' (${missing[*]}); apt's log: $log"
export DEBIAN_FRONTEND=noninteractive
if ! { $SUDO apt-get update -qq && $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"; } >"$log" 2>&1; then
  tail -n 40 "$log" >&2
  echo "install-deps: apt-get failed (the last lines are above; the whole log: $log)" >&2
  exit 1
fi
echo "install-deps: done"
