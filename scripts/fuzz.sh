#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/fuzz_*.cpp) with clang-14 + ASan + UBSan in build-fuzz/ and runs each on its
# corpus fuzz/corpus/<target>/ (read only; new inputs go to a scratch folder). Prints executions per target.
# Usage: scripts/fuzz.sh                 # 5 seconds per target (what CI runs)
#        scripts/fuzz.sh --seconds 600   # longer
#        scripts/fuzz.sh --runs 1000000  # at least a million inputs per target
#        scripts/fuzz.sh --keep          # add the new interesting inputs to fuzz/corpus/ (then commit them)
set -euo pipefail
cd "$(dirname "$0")/.."
limit=(-max_total_time=5)
keep=0
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) limit=(-max_total_time="$2"); shift 2 ;;
    --runs) limit=(-runs="$2"); shift 2 ;;
    --keep) keep=1; shift ;;
    *) echo "fuzz.sh: unknown option '$1' (use --seconds N, --runs N, --keep)" >&2; exit 2 ;;
  esac
done
if ! command -v clang++-14 >/dev/null; then echo "fuzz.sh: clang++-14 missing: run scripts/bootstrap.sh" >&2; exit 2; fi

generator=()
[ -f build-fuzz/CMakeCache.txt ] || { command -v ninja >/dev/null && generator=(-G Ninja); }
CC=clang-14 CXX=clang++-14 cmake -S . -B build-fuzz "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
  -DAFMKIT_BUILD_FUZZ=ON -DAFMKIT_BUILD_TESTS=OFF -DAFMKIT_BUILD_BENCH=OFF >/dev/null
cmake --build build-fuzz -j"$(nproc)" --target fuzz_all

status=0
for src in fuzz/fuzz_*.cpp; do
  name=$(basename "$src" .cpp)
  corpus="fuzz/corpus/$name"
  scratch=$(mktemp -d)
  mkdir -p "$corpus"
  log="$scratch/log"
  if ! ASAN_OPTIONS=detect_leaks=1 "build-fuzz/bin/$name" "${limit[@]}" -print_final_stats=1 -rss_limit_mb=2048 \
      -timeout=10 -artifact_prefix="$scratch/" "$scratch" "$corpus" >"$log" 2>&1; then
    echo "fuzz: $name FAILED; the input that failed and the log are in $scratch:" >&2
    tail -40 "$log" >&2
    status=1
    continue
  fi
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$')
  cov=$(grep -o 'cov: [0-9]*' "$log" | tail -1 || true)
  echo "fuzz: $name ok: $runs inputs executed ($cov), corpus $(ls "$corpus" | wc -l) files"
  if [ "$keep" = 1 ]; then
    build-fuzz/bin/"$name" -merge=1 "$corpus" "$scratch" >/dev/null 2>&1 || true
  fi
  rm -rf "$scratch"
done
exit $status
