#!/usr/bin/env bash
# Builds the library, the program and the test suite with AddressSanitizer + UndefinedBehaviorSanitizer in
# build-asan/ (at -O1 with line tables: what the sanitizers need, at half the compile time of -O2 -g) and runs the
# suite there: the unit tests, the readers, the documented examples and the bad-input table of docs/ (which run the
# instrumented build-asan/bin/afmkit), and a sample of the hostile campaign (its full product runs in Release).
# Not here: the install test, the ARM cross tests and the Python module (an instrumented extension needs the ASan
# runtime preloaded into the interpreter). Any memory error, leak or undefined behaviour fails the test that hit it.
# Usage: scripts/sanitize.sh [extra ctest arguments, e.g. -R cli]
#        scripts/sanitize.sh --build-only | --test-only [ctest arguments]     (CI times the two on their own)
set -euo pipefail
cd "$(dirname "$0")/.."
do_build=1
do_test=1
case "${1:-}" in
  --build-only) do_test=0; shift ;;
  --test-only) do_build=0; shift ;;
esac
if [ "$do_build" = 1 ]; then
  generator=()
  [ -f build-asan/CMakeCache.txt ] || { command -v ninja >/dev/null && generator=(-G Ninja); }
  cmake -S . -B build-asan "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DAFMKIT_SANITIZE=ON \
    -DAFMKIT_BUILD_BENCH=OFF -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" \
    -DCMAKE_C_FLAGS_RELWITHDEBINFO="-O1 -g1 -DNDEBUG" >/dev/null
  cmake --build build-asan -j"$(nproc)"
fi
if [ "$do_test" = 1 ]; then
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=0:strict_string_checks=1:detect_stack_use_after_return=1
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  ctest --test-dir build-asan --output-on-failure -j2 -LE '^(install|cross)$' "$@"
fi
