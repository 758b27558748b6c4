#!/usr/bin/env bash
# Every ctest name is stable and readable: none carries a printed parameter value ("# GetParam() = 72-byte object
# <BA-B0 …>", memory bytes that change between builds and break `ctest -R` selections). Arguments: the ctest
# command and the build folder.
set -euo pipefail
ctest="$1" build="$2"
names=$("$ctest" --test-dir "$build" -N | sed -n 's/^ *Test *#[0-9]*: //p')
count=$(printf '%s\n' "$names" | grep -c . || true)
if [ "$count" -eq 0 ]; then
  echo "test_names: ctest -N listed no tests in $build" >&2
  exit 1
fi
bad=$(printf '%s\n' "$names" | grep -E 'GetParam|TypeParam|byte object| #|[^A-Za-z0-9_./:-]' || true)
if [ -n "$bad" ]; then
  echo "test_names: $(printf '%s\n' "$bad" | wc -l) of $count test names carry a printed value or odd characters:" >&2
  printf '%s\n' "$bad" | head -n 10 >&2
  exit 1
fi
echo "test_names: $count names, all plain"
