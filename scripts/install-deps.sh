#!/usr/bin/env bash
# Installs the Debian 12 packages skinlab needs (headless, no GPU required). apt's output goes to a log (its last
# lines are shown when the installation fails); meanwhile a count is printed every few seconds ("install-deps: 12/85
# packages unpacked"). Idempotent: only missing packages are installed. Needs root (or sudo) and Debian's package
# registry (network access to a Debian mirror).
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
source "$(dirname "$0")/lib/progress.sh"
log="$(mktemp "${TMPDIR:-/tmp}/skinlab-install-deps.XXXXXX.log")"
echo "install-deps: installing ${#missing[@]} packages for '$profile' (${missing[*]}); apt's log: $log"
export DEBIAN_FRONTEND=noninteractive
fail() {
  tail -n 40 "$log" >&2
  echo "install-deps: apt-get failed (the last lines are above; the whole log: $log)" >&2
  exit 1
}
echo "install-deps: reading the package lists from Debian's package registry (apt-get update)"
run_with_progress install-deps "$log" - $SUDO apt-get update -q || fail
# How many packages the installation brings, dependencies included (a dry run), for the counts.
total=$($SUDO apt-get install -s --no-install-recommends "${missing[@]}" 2>>"$log" | grep -c '^Inst ' || true)
first=$(($(wc -l <"$log") + 1))
install_status() { apt_status "$1" "$first" "$total"; }
echo "install-deps: downloading and installing $total packages (dependencies included)"
run_with_progress install-deps "$log" install_status \
  $SUDO apt-get install -y -q --no-install-recommends -o Dpkg::Progress-Fancy=0 "${missing[@]}" || fail
echo "install-deps: done ($total packages)"
