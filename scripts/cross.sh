#!/usr/bin/env bash
# Cross-builds the freestanding real-time filter core (src/embed/c/afmkit_embed.c, include/afmkit/embed/afmkit_embed.h)
# with the target check tests/cross/cross_check.c for 64-bit ARM Linux (run under qemu-aarch64) and a Cortex-M4F
# board (Arm MPS2 AN386, run bare metal under qemu-system-arm with semihosting), on headers written by the host
# exporter `afmkit control export --format c-header` (float and double, several numbers of test samples), and
# checks on the target that the closed loop reproduces the host's double reference within the exported tolerance.
#
# Usage: scripts/cross.sh [--target aarch64|cortex-m4|all] [--afmkit PATH] [--samples "1 10 50"]
#                         [--tuning "EXPORT OPTIONS"] [--work DIR] [--keep]
#   --target   which targets (default all)
#   --afmkit   the host afmkit binary (default build/bin/afmkit; also the first non-option argument)
#   --samples  numbers M of exported test samples, one header per M and precision (default "1 10 50 1000")
#   --tuning   the design options given to `afmkit control export` (default: a 50 Hz rotation sampled at 10 kHz,
#              "--rotation-frequency 314.1592653589793 --sample-rate 10000", N = 10 and the other defaults)
#   --work     scratch folder (default: a fresh one under $TMPDIR, removed on success, kept on failure)
#   --keep     keep the scratch folder
# Exit status: 0 when every check passes; 1 when one fails, a toolchain is missing (the message names the Debian
# package; scripts/bootstrap.sh installs them all) or the exporter fails; 2 for bad usage.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)

target=all
afmkit=""
samples="1 10 50 1000"
tuning="--rotation-frequency 314.1592653589793 --sample-rate 10000"
work=""
keep=0
usage() {
  echo "usage: scripts/cross.sh [--target aarch64|cortex-m4|all] [--afmkit PATH] [--samples \"1 10 50\"]" \
       "[--tuning \"EXPORT OPTIONS\"] [--work DIR] [--keep]" >&2
  exit 2
}
while [ $# -gt 0 ]; do
  case "$1" in
    --target) [ $# -ge 2 ] || usage; target="$2"; shift 2 ;;
    --afmkit) [ $# -ge 2 ] || usage; afmkit="$2"; shift 2 ;;
    --samples) [ $# -ge 2 ] || usage; samples="$2"; shift 2 ;;
    --tuning) [ $# -ge 2 ] || usage; tuning="$2"; shift 2 ;;
    --work) [ $# -ge 2 ] || usage; work="$2"; shift 2 ;;
    --keep) keep=1; shift ;;
    -h|--help) sed -n '2,20p' "$0"; exit 0 ;;
    -*) echo "cross.sh: unknown option '$1'" >&2; usage ;;
    *) [ -z "$afmkit" ] || usage; afmkit="$1"; shift ;;
  esac
done
case "$target" in
  aarch64) targets=(aarch64) ;;
  cortex-m4) targets=(cortex-m4) ;;
  all) targets=(aarch64 cortex-m4) ;;
  *) echo "cross.sh: --target must be aarch64, cortex-m4 or all (got '$target')" >&2; exit 2 ;;
esac
for m in $samples; do
  [[ "$m" =~ ^[1-9][0-9]*$ ]] || { echo "cross.sh: --samples takes positive integers (got '$m')" >&2; exit 2; }
done

# ---- what is needed ------------------------------------------------------------------------------------------
need() {  # need <command> <Debian package>
  if ! command -v "$1" >/dev/null 2>&1; then
    echo "cross.sh: '$1' not found: install the Debian package $2 (apt-get install $2, or scripts/bootstrap.sh)" >&2
    exit 1
  fi
}
m4_flags=(-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16)
for t in "${targets[@]}"; do
  if [ "$t" = aarch64 ]; then
    need aarch64-linux-gnu-gcc gcc-aarch64-linux-gnu
    need qemu-aarch64 qemu-user
    if [ ! -f "$(aarch64-linux-gnu-gcc -print-file-name=libc.a)" ]; then
      echo "cross.sh: the aarch64 C library (libc.a) is missing: install the Debian package libc6-dev-arm64-cross" >&2
      exit 1
    fi
  else
    need arm-none-eabi-gcc gcc-arm-none-eabi
    need arm-none-eabi-nm binutils-arm-none-eabi
    need arm-none-eabi-size binutils-arm-none-eabi
    need qemu-system-arm qemu-system-arm
    if [ ! -f "$(arm-none-eabi-gcc "${m4_flags[@]}" -print-file-name=librdimon.a)" ]; then
      echo "cross.sh: newlib for arm-none-eabi (librdimon.a) is missing: install the Debian package libnewlib-arm-none-eabi" >&2
      exit 1
    fi
    if ! qemu-system-arm -M help | grep -q '^mps2-an386 '; then
      echo "cross.sh: this qemu-system-arm has no mps2-an386 machine: install a newer Debian package qemu-system-arm" >&2
      exit 1
    fi
  fi
done
need timeout coreutils

if [ -z "$afmkit" ]; then
  afmkit="$root/build/bin/afmkit"
fi
if [ ! -x "$afmkit" ]; then
  echo "cross.sh: no afmkit binary at '$afmkit': build it (cmake --build build --target afmkit_cli) or pass --afmkit PATH" >&2
  exit 1
fi
core_c="$root/src/embed/c/afmkit_embed.c"
core_include="$root/include"
check_dir="$root/tests/cross"
for f in "$core_c" "$core_include/afmkit/embed/afmkit_embed.h" "$check_dir/cross_check.c" "$check_dir/mps2/startup.c" \
         "$check_dir/mps2/mps2_an386.ld"; do
  [ -f "$f" ] || { echo "cross.sh: missing source file $f" >&2; exit 1; }
done

if [ -z "$work" ]; then
  work=$(mktemp -d "${TMPDIR:-/tmp}/afmkit-cross.XXXXXX")
else  # reused between runs: only a folder this script made (marker file) or an empty one is cleared
  if [ -d "$work" ] && [ -n "$(ls -A "$work")" ] && [ ! -f "$work/.afmkit-cross" ]; then
    echo "cross.sh: --work $work is not empty and was not made by cross.sh; not clearing it" >&2
    exit 2
  fi
  rm -rf "$work"
  mkdir -p "$work"
fi
touch "$work/.afmkit-cross"
status=0
summary=()
failures=()
fail() { echo "cross.sh: FAILED: $*" >&2; status=1; failures+=("$*"); }

# The core must build warning-free and freestanding (firmware copies it with its own warning flags).
warn_flags=(-std=c99 -Wall -Wextra -Wpedantic -Wshadow -Wdouble-promotion -Werror)
# set_defines <precision> [<header>]: core_defines = the core's precision macro; check_defines = the same for the
# check program, unless the exported header defines it itself
set_defines() {
  core_defines=()
  if [ "$1" = double ]; then core_defines=(-DAFMKIT_EMBED_DOUBLE); fi
  check_defines=("${core_defines[@]}")
  if [ $# -ge 2 ] && grep -Eq '^[[:space:]]*#[[:space:]]*define[[:space:]]+AFMKIT_EMBED_DOUBLE([[:space:]]|$)' "$2"; then
    check_defines=()
  fi
}

# export_header <precision> <M> <dir>: writes <dir>/afmkit_export.h with the host exporter.
export_header() {
  mkdir -p "$3"
  # shellcheck disable=SC2086 # $tuning: several options
  if ! "$afmkit" control export --format c-header --output "$3/afmkit_export.h" --precision "$1" \
      --test-vectors "$2" $tuning >"$3/export.log" 2>&1; then
    fail "afmkit control export --precision $1 --test-vectors $2 $tuning (log: $3/export.log)"
    sed 's/^/  | /' "$3/export.log" >&2
    return 1
  fi
}

# run_check <label> <log> <command...>: runs the target program with a time limit; records its verdict.
run_check() {
  local label="$1" log="$2"
  shift 2
  local rc=0
  timeout --kill-after=5 60 "$@" >"$log" 2>&1 || rc=$?
  sed 's/^/  | /' "$log"
  local worst tol
  worst=$(sed -n 's/^worst |m - m_ref| = \([^ ]*\) .*tolerance \([^ ]*\)$/\1/p' "$log")
  tol=$(sed -n 's/^worst |m - m_ref| = \([^ ]*\) .*tolerance \([^ ]*\)$/\2/p' "$log")
  local verdict=PASS
  if [ "$rc" -eq 124 ] || [ "$rc" -eq 137 ]; then
    verdict="FAIL (timed out after 60 s)"
  elif ! grep -q "^afmkit cross check: .* $precision precision" "$log"; then
    verdict="FAIL (the program did not run in $precision precision)"
  elif [ "$rc" -ne 0 ] || ! grep -qx PASS "$log"; then
    verdict="FAIL (exit $rc)"
  fi
  [ "$verdict" = PASS ] || fail "$label: $verdict"
  # speed: samples/s on Linux; on the MPS2 SysTick ticks per step, 25 MHz of QEMU virtual time at 1 ns per
  # instruction (-icount shift=0), so 40 instructions per tick
  local speed
  speed=$(sed -n 's/^samples\/s: \([^ ]*\) .*/\1 samples\/s (emulated)/p' "$log")
  if [ -z "$speed" ]; then
    speed=$(sed -n 's/^SysTick ticks per step: \([^ ]*\) .*/\1/p' "$log" |
              awk '{if ($1 != "") printf "%.0f instructions/step (QEMU icount)", 40 * $1}')
  fi
  summary+=("$(printf '%-34s worst %-10s tolerance %-10s %-5s %s' "$label" "${worst:-?}" "${tol:-?}" "$verdict" "$speed")")
}

# check_freestanding <object> <label>: the core object may only need math.h functions, the compiler's runtime
# helpers (libgcc __aeabi_*) and the four functions GCC requires of any freestanding environment.
check_freestanding() {
  local undefined
  undefined=$(arm-none-eabi-nm -u "$1" | awk '{print $2}' | sort -u | tr '\n' ' ')
  local bad=""
  for s in $undefined; do
    case "$s" in
      __aeabi_*|__gnu_*) ;;
      memcpy|memmove|memset|memcmp) ;;
      sqrt|sqrtf|fabs|fabsf|sin|sinf|cos|cosf|sincos|sincosf|tan|tanf|atan2|atan2f|exp|expf|log|logf|pow|powf| \
      floor|floorf|ceil|ceilf|fmod|fmodf|hypot|hypotf|isfinite|__fpclassifyf|__fpclassifyd|__isinff|__isnanf|__isinfd|__isnand) ;;
      *) bad="$bad $s" ;;
    esac
  done
  echo "  core $2 needs from outside: ${undefined:-nothing}"
  summary+=("$(printf '%-34s needs: %s' "core $2 (Cortex-M4) symbols" "${undefined:-nothing}")")
  [ -z "$bad" ] || fail "core $2 needs symbols outside math.h and libgcc:$bad"
}

# ---- aarch64 Linux (qemu-aarch64, static) ----------------------------------------------------------------------
run_aarch64() {
  echo "== aarch64: aarch64-linux-gnu-gcc -O2 -std=c99 -static, run under qemu-aarch64"
  for precision in float double; do
    for m in $samples; do
      local dir="$work/aarch64-$precision-$m"
      export_header "$precision" "$m" "$dir" || continue
      set_defines "$precision" "$dir/afmkit_export.h"
      if ! aarch64-linux-gnu-gcc -O2 "${warn_flags[@]}" "${core_defines[@]}" -ffreestanding -I"$core_include" -c "$core_c" \
             -o "$dir/afmkit_embed.o" >"$dir/build.log" 2>&1 ||
         ! aarch64-linux-gnu-gcc -O2 -std=c99 -Wall -Wextra -Werror "${check_defines[@]}" -I"$core_include" -I"$dir" \
             -c "$check_dir/cross_check.c" -o "$dir/cross_check.o" >>"$dir/build.log" 2>&1 ||
         ! aarch64-linux-gnu-gcc -static "$dir/cross_check.o" "$dir/afmkit_embed.o" -lm -o "$dir/cross_check" \
             >>"$dir/build.log" 2>&1; then
        fail "aarch64 $precision M=$m: build (log: $dir/build.log)"
        sed 's/^/  | /' "$dir/build.log" >&2
        continue
      fi
      echo "-- aarch64 $precision M=$m: qemu-aarch64 $dir/cross_check"
      run_check "aarch64 $precision M=$m" "$dir/run.log" qemu-aarch64 "$dir/cross_check"
    done
  done
}

# ---- Cortex-M4F bare metal (MPS2 AN386 under qemu-system-arm, semihosting) --------------------------------------
run_cortex_m4() {
  echo "== cortex-m4: arm-none-eabi-gcc ${m4_flags[*]} -O2, MPS2 AN386 under qemu-system-arm (semihosting)"
  local base="$work/cortex-m4"
  mkdir -p "$base"
  if ! arm-none-eabi-gcc "${m4_flags[@]}" -O2 -std=c99 -Wall -Wextra -Werror -c "$check_dir/mps2/startup.c" \
      -o "$base/startup.o" >"$base/build.log" 2>&1; then
    fail "cortex-m4: startup build (log: $base/build.log)"
    sed 's/^/  | /' "$base/build.log" >&2
    return
  fi
  for precision in float double; do
    local core="$base/afmkit_embed_$precision.o"
    set_defines "$precision"
    # the core alone, freestanding, with its stack use per function
    if ! (cd "$base" && arm-none-eabi-gcc "${m4_flags[@]}" -O2 "${warn_flags[@]}" -ffreestanding -fstack-usage \
            "${core_defines[@]}" -I"$core_include" -c "$core_c" -o "$core") >"$base/core-$precision.log" 2>&1; then
      fail "cortex-m4 core ($precision): build (log: $base/core-$precision.log)"
      sed 's/^/  | /' "$base/core-$precision.log" >&2
      continue
    fi
    check_freestanding "$core" "$precision"
    # and it links with no C library at all (-nostdlib; only libm and libgcc offered)
    if ! arm-none-eabi-gcc "${m4_flags[@]}" -nostdlib -Wl,-e,0 "$core" -lm -lgcc -o "$base/core-only-$precision.elf" \
        >"$base/core-link-$precision.log" 2>&1; then
      fail "cortex-m4 core ($precision): does not link with -nostdlib (log: $base/core-link-$precision.log)"
      sed 's/^/  | /' "$base/core-link-$precision.log" >&2
    fi
    local text stack
    text=$(arm-none-eabi-size "$core" | awk 'NR == 2 {print $1 " B text, " $2 " B data, " $3 " B bss"}')
    stack=$(awk -F'\t' '{split($1, a, ":"); printf "%s%s %s B", sep, a[length(a)], $2; sep = ", "}' \
              "$base/afmkit_embed_$precision.su" 2>/dev/null || true)
    echo "  core $precision: $text; stack per function: ${stack:-?}"
    summary+=("$(printf '%-34s %s' "core $precision (Cortex-M4 -O2) size" "$text")")
    summary+=("$(printf '%-34s %s' "core $precision (Cortex-M4) stack" "${stack:-?}")")
    for m in $samples; do
      local dir="$base/$precision-$m"
      export_header "$precision" "$m" "$dir" || continue
      set_defines "$precision" "$dir/afmkit_export.h"
      if ! arm-none-eabi-gcc "${m4_flags[@]}" -O2 -std=c99 -Wall -Wextra -Werror \
             "${check_defines[@]}" -I"$core_include" -I"$dir" -c "$check_dir/cross_check.c" -o "$dir/cross_check.o" >"$dir/build.log" 2>&1 ||
         ! arm-none-eabi-gcc "${m4_flags[@]}" --specs=rdimon.specs -nostartfiles -T "$check_dir/mps2/mps2_an386.ld" \
             -Wl,--gc-sections "$base/startup.o" "$dir/cross_check.o" "$core" -lm -o "$dir/cross_check.elf" \
             >>"$dir/build.log" 2>&1; then
        fail "cortex-m4 $precision M=$m: build (log: $dir/build.log)"
        sed 's/^/  | /' "$dir/build.log" >&2
        continue
      fi
      echo "-- cortex-m4 $precision M=$m: qemu-system-arm -M mps2-an386 -icount shift=0 ... -kernel $dir/cross_check.elf"
      run_check "cortex-m4 $precision M=$m" "$dir/run.log" qemu-system-arm -M mps2-an386 -icount shift=0 -nographic \
        -monitor none -serial none -semihosting-config enable=on,target=native -kernel "$dir/cross_check.elf"
    done
  done
}

for t in "${targets[@]}"; do
  if [ "$t" = aarch64 ]; then run_aarch64; else run_cortex_m4; fi
done

echo "== cross summary (afmkit: $afmkit; export options: $tuning)"
for line in "${summary[@]}"; do echo "  $line"; done
for line in "${failures[@]}"; do echo "  FAILED: $line"; done
if [ "$status" -eq 0 ]; then
  echo "cross: all checks PASS"
  if [ "$keep" = 1 ]; then echo "cross: files in $work"; else rm -rf "$work"; fi
else
  echo "cross: FAIL (files kept in $work)"
fi
exit $status
