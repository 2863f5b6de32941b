#!/usr/bin/env bash
# Builds the library, the program and the whole test suite with AddressSanitizer + UndefinedBehaviorSanitizer
# in build-asan/ and runs the suite there (this includes the documented command examples and the bad-input
# table of docs/, which run the instrumented build/bin/afmkit of that folder). Any memory error, leak or
# undefined behaviour fails the test that hit it.
# Usage: scripts/sanitize.sh [extra ctest arguments, e.g. -R cli]
set -euo pipefail
cd "$(dirname "$0")/.."
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DAFMKIT_SANITIZE=ON -DAFMKIT_BUILD_BENCH=OFF >/dev/null
cmake --build build-asan -j"$(nproc)"
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=0:strict_string_checks=1:detect_stack_use_after_return=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
ctest --test-dir build-asan --output-on-failure -j2 "$@"
