#!/usr/bin/env bash
# Checks that every C++ file of the repository is formatted as .clang-format says (clang-format 14, Debian 12's
# `clang-format`). Prints the files that differ and exits 1; `scripts/check-format.sh --fix` rewrites them.
# Run by ctest as `style_clang_format`.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! command -v clang-format >/dev/null; then
  echo "SKIPPED: clang-format not found (scripts/install-deps.sh installs it)"
  exit 77
fi
mapfile -t files < <(git ls-files '*.cpp' '*.h' 2>/dev/null || find . -path ./build -prune -o \( -name '*.cpp' -o -name '*.h' \) -print)
if [ "${1:-}" = "--fix" ]; then
  clang-format -i --style=file "${files[@]}"
  exit 0
fi
# One clang-format run over every file; it names each line that differs ("FILE:LINE:COL: error: code should be
# clang-formatted").
if report=$(clang-format --style=file --dry-run --Werror "${files[@]}" 2>&1); then
  echo "check-format: ${#files[@]} files as .clang-format says"
  exit 0
fi
mapfile -t differ < <(printf '%s\n' "$report" | grep -o '^[^:]*:[0-9]*:[0-9]*: error' | cut -d: -f1 | sort -u)
printf '%s\n' "${differ[@]}"
echo "check-format: ${#differ[@]} of ${#files[@]} files differ from .clang-format; run scripts/check-format.sh --fix"
exit 1
