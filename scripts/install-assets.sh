#!/usr/bin/env bash
# Puts downloaded third-party assets where skinlab looks for them, after checking each file's SHA-256:
#   scripts/install-assets.sh DOWNLOADS [ASSETS] [REFERENCE]
# DOWNLOADS: a folder holding the downloaded files under any sub-folders (found by file name);
# ASSETS (default ../shared/assets): the scanned head and the HDR environments, as $SKINLAB_ASSETS expects them;
# REFERENCE (default ../shared/reference): the published separable kernels, as $SKINLAB_REFERENCE expects them.
# Where each file comes from, and its licence: docs/assets.md#getting-the-third-party-assets.
set -euo pipefail
if [ $# -lt 1 ] || [ ! -d "$1" ]; then
  echo "usage: scripts/install-assets.sh DOWNLOADS [ASSETS] [REFERENCE]  (DOWNLOADS: a folder of downloaded files)" >&2
  exit 2
fi
cd "$(dirname "$0")/.."
downloads=$1
assets=${2:-../shared/assets}
reference=${3:-../shared/reference}

# destination (relative to its root) | root | sha256
files=(
  "LeePerrySmith/LeePerrySmith.glb|A|402b8a8ac9f03232e6d64b5962929703a069daf99d3c49ac8eb0e48bedc9c576"
  "LeePerrySmith/Map-COL.jpg|A|e976d73b31407f8d0967412bf468019ed26a5d5a32cf5811aabff7e816458a65"
  "LeePerrySmith/Infinite-Level_02_Tangent_SmoothUV.jpg|A|36925e51ad9b324b94e8faf4692da1b4132809f2762bb8d5bd549ffd215d4ca6"
  "LeePerrySmith/Map-SPEC.jpg|A|cbb96b60e355b804d9b6c7338372d13ec8cc7adf664f50a00a3d32c66afd293a"
  "envmaps/royal_esplanade_1k.hdr|A|d72031e24581a0f13911fbcdee475db0f8cafcf48bf1771c6b971c3310db6cb2"
  "envmaps/venice_sunset_1k.hdr|A|0e72ed46b5316cb5fb67fc81ff85b024a09146fd89ef3811a8d2299647ada118"
  "separable-sss-kernels/Skin1_PreInt_DISCSEP.bn|R|0920d96f6fc1c9a3689aca651916d25817385ecd58e3e0cc5c21aec23bd661f0"
  "separable-sss-kernels/Skin2_PreInt_DISCSEP.bn|R|de010da0650c7a0f68f12f65f23a7b541966b012a2d4ff7b0fb92ce2007549db"
  "separable-sss-kernels/Marble_PreInt_DISCSEP.bn|R|3acab13a1621dc3f0b3d77514bfb580949532e906573c3cbf6a7687403f714ed"
  "separable-sss-kernels/Apple_PreInt_DISCSEP.bn|R|867f36bea297b62c01b3ee9fe9c9caa3576676f67e075ae7c2289a66f4b2400e"
  "separable-sss-kernels/Ketchup_PreInt_DISCSEP.bn|R|d7665212f767d81683c4b1f2eb8595751792c3e62742a7a99505788dbc099f09"
  "separable-sss-kernels/Wholemilk_PreInt_DISCSEP.bn|R|39e467327044c0463a76ffe7bfef1ece32829363173ad812b94b15500ed806eb"
)
installed=0 missing=0 bad=0
for entry in "${files[@]}"; do
  IFS='|' read -r destination root sum <<<"$entry"
  name=$(basename "$destination")
  found=$(find "$downloads" -type f -name "$name" | head -n 1)
  if [ -z "$found" ]; then
    echo "install-assets: $name: not in $downloads (skipped)"
    missing=$((missing + 1))
    continue
  fi
  if [ "$(sha256sum "$found" | cut -d' ' -f1)" != "$sum" ]; then
    echo "install-assets: $found: sha256 differs from the published file's ($sum); not installed" >&2
    bad=$((bad + 1))
    continue
  fi
  if [ "$root" = A ]; then target="$assets/$destination"; else target="$reference/$destination"; fi
  mkdir -p "$(dirname "$target")"
  cp "$found" "$target.tmp.$$" && mv "$target.tmp.$$" "$target"
  installed=$((installed + 1))
done
license=$(find "$downloads" -type f -name LeePerrySmith_License.txt | head -n 1)
if [ -n "$license" ]; then mkdir -p "$assets/LeePerrySmith" && cp "$license" "$assets/LeePerrySmith/"; fi
echo "install-assets: $installed installed, $missing not found, $bad refused (checksum)"
echo "  SKINLAB_ASSETS=$(cd "$assets" 2>/dev/null && pwd || echo "$assets")"
echo "  SKINLAB_REFERENCE=$(cd "$reference" 2>/dev/null && pwd || echo "$reference")"
[ "$bad" -eq 0 ]
