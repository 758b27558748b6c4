#!/usr/bin/env bash
# Every page of the documentation stays readable as reference: README.md and every page under docs/ at most 700
# lines (a longer page is split by topic, with the index page naming where each section went). Argument: the source
# folder.
set -euo pipefail
source_dir="$1"
limit=700
pages=0
long=()
for page in "$source_dir/README.md" "$source_dir"/docs/*.md; do
  [ -f "$page" ] || continue
  pages=$((pages + 1))
  lines=$(wc -l < "$page")
  [ "$lines" -le "$limit" ] || long+=("${page#"$source_dir"/}: $lines lines")
done
if [ ! -f "$source_dir/README.md" ] || [ "$pages" -lt 2 ]; then
  echo "doc_page_length: no README.md or no pages under $source_dir/docs" >&2
  exit 1
fi
if [ "${#long[@]}" -gt 0 ]; then
  echo "doc_page_length: ${#long[@]} of $pages pages exceed $limit lines: ${long[*]}" >&2
  exit 1
fi
echo "doc_page_length: $pages pages (README.md and docs/), each at most $limit lines"
