#!/usr/bin/env bash
# Every C++ test makes its temporary folders with tests/common/temp_folder.h (a fresh folder per test under the build
# folder's tests-tmp/, removed afterwards): no test file outside tests/common/ names the system temp folder
# (std::filesystem::temp_directory_path) or makes one by hand (mkdtemp). Argument: the source folder.
set -euo pipefail
tests="$1/tests"
files=$(find "$tests" -type f \( -name '*.cpp' -o -name '*.h' -o -name '*.hpp' \) ! -path "$tests/common/*" \
  ! -path '*/node_modules/*' | sort)
count=$(printf '%s\n' "$files" | grep -c . || true)
if [ "$count" -eq 0 ]; then
  echo "temp_folders: no C++ test files under $tests" >&2
  exit 1
fi
bad=$(printf '%s\n' "$files" | xargs grep -nE 'temp_directory_path|mkdtemp' || true)
if [ -n "$bad" ]; then
  echo "temp_folders: $(printf '%s\n' "$bad" | wc -l) lines make a temporary folder by hand; use" \
    "skinlab::test_support::TempFolder (tests/common/temp_folder.h):" >&2
  printf "%s\n" "$bad" | sed "s|^$tests/||" >&2
  exit 1
fi
echo "temp_folders: $count C++ test files, none makes a temporary folder by hand"
