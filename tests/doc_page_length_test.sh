#!/usr/bin/env bash
# doc_page_length.sh counts README.md as well as docs/*.md: a 701-line README.md, or docs page, in a scratch source
# folder fails it, naming the page; 700 lines pass. Argument: the tests folder.
set -euo pipefail
check="$1/doc_page_length.sh"
scratch=$(mktemp -d "${TMPDIR:-/tmp}/skinlab-doc-length.XXXXXX")
trap 'rm -rf "$scratch"' EXIT
mkdir -p "$scratch/docs"
lines() { seq "$1" | sed 's/^/line /'; }
lines 700 > "$scratch/README.md"
lines 10 > "$scratch/docs/page.md"
bash "$check" "$scratch" > /dev/null
for long in README.md docs/page.md; do
  lines 701 > "$scratch/$long"
  if output=$(bash "$check" "$scratch" 2>&1); then
    echo "doc_page_length_test: a 701-line $long passed: $output" >&2
    exit 1
  fi
  case "$output" in
    *"$long: 701 lines"*) ;;
    *) echo "doc_page_length_test: the failure does not name $long: $output" >&2; exit 1 ;;
  esac
  lines 10 > "$scratch/$long"
done
echo "doc_page_length_test: README.md and docs pages over 700 lines are refused"
