#!/usr/bin/env bash
# Every page under docs/ stays readable as reference: at most 700 lines (a longer page is split by topic, with the
# index page naming where each section went). Argument: the source folder.
set -euo pipefail
docs="$1/docs"
limit=700
pages=0
long=()
for page in "$docs"/*.md; do
  pages=$((pages + 1))
  lines=$(wc -l < "$page")
  [ "$lines" -le "$limit" ] || long+=("$(basename "$page"): $lines lines")
done
if [ "$pages" -eq 0 ]; then
  echo "doc_page_length: no pages in $docs" >&2
  exit 1
fi
if [ "${#long[@]}" -gt 0 ]; then
  echo "doc_page_length: ${#long[@]} of $pages pages exceed $limit lines: ${long[*]}" >&2
  exit 1
fi
echo "doc_page_length: $pages pages, each at most $limit lines"
