#!/usr/bin/env bash
# Every benchmark has a smoke run in ctest (bench/CMakeLists.txt, skinlab_bench_smoke): each program that a
# bench/ CMakeLists.txt adds (add_executable), each program named bench_* that a CMakeLists.txt elsewhere adds (the
# metrics' benchmark beside its tests) and each shell benchmark (bench/**/*.sh but the smoke runner) is named as the
# command of a smoke run, so that a benchmark cannot rot unnoticed. Argument: the source folder.
set -euo pipefail
bench="$1/bench"
smokes=$(sed -n '/skinlab_bench_smoke(/,/)/p' "$bench/CMakeLists.txt" | grep -o 'COMMAND [^ )]*' | awk '{print $2}')
missing=()
benchmarks=0
programs=$( (grep -rhoE 'add_executable\([A-Za-z0-9_]+' "$bench" --include=CMakeLists.txt
             grep -rhoE 'add_executable\(bench_[A-Za-z0-9_]+' "$1" --include=CMakeLists.txt --exclude-dir=bench \
               --exclude-dir=build --exclude-dir=node_modules --exclude-dir=.git) | sed 's/add_executable(//' | sort -u)
for program in $programs; do
  benchmarks=$((benchmarks + 1))
  grep -qx "$program" <<< "$smokes" || missing+=("$program")
done
while IFS= read -r script; do
  relative=${script#"$bench"/}
  [ "$relative" = smoke_run.sh ] && continue
  benchmarks=$((benchmarks + 1))
  grep -qx "$relative" <<< "$smokes" || missing+=("bench/$relative")
done < <(find "$bench" -name '*.sh' | sort)
if [ "${#missing[@]}" -gt 0 ]; then
  echo "bench_smoke_coverage: ${#missing[@]} of $benchmarks benchmarks have no smoke run in bench/CMakeLists.txt: ${missing[*]}" >&2
  exit 1
fi
echo "bench_smoke_coverage: all $benchmarks benchmarks have a smoke run"
