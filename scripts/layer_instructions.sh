#!/bin/bash
# The command layer's instructions (docs/development.md#benchmarks, issue 26's "the command layer adds <= 5 % to a
# 1 ms command"): deterministic, unlike timings on a shared machine. Needs valgrind and the Python module built.
# Usage: scripts/layer_instructions.sh <build dir> [top N]      (KEEP=<dir>: keep callgrind's files there)
# Instructions per afmkit.tapping.orbit(quality_factor=2, separation=5, max_period_multiple=1) call OUTSIDE
# afmkit::tapping::find_orbits (the command layer), deterministic (callgrind): runs 200 and 400 calls, diffs.
# Prints the instructions per call and the top functions (inclusive, then exclusive).
set -e
B=$(cd "$1" && pwd); TOP=${2:-40}; T=${KEEP:-$(mktemp -d)}; mkdir -p $T
cat > $T/loop.py <<'PY'
import os, sys
os.environ.setdefault("OMP_NUM_THREADS", "1")
import afmkit
CASE = dict(quality_factor=2.0, separation=5.0, max_period_multiple=1)
for _ in range(int(sys.argv[1]) + 1):
    r = afmkit.tapping.orbit(**CASE)
PY
for n in 200 400; do
  PYTHONHASHSEED=0 PYTHONPATH=$B/python OMP_NUM_THREADS=1 valgrind --tool=callgrind --toggle-collect='afmkit::tapping::find_orbits(*' \
    --collect-atstart=yes --callgrind-out-file=$T/cg$n.out /usr/bin/python3 $T/loop.py $n >/dev/null 2>&1
  for kind in yes no; do
    callgrind_annotate --inclusive=$kind --threshold=100 $T/cg$n.out 2>/dev/null | sed -n '/file:function/,$p' |
      grep -E "^ *[0-9,]+ " | sed -E 's/^ *([0-9,]+) \([^)]*\) +/\1\t/' | tr -d ',' > $T/$kind$n.tsv
  done
  grep -E "^ *[0-9,]+ \(100.0%\) +PROGRAM TOTALS" <(callgrind_annotate $T/cg$n.out 2>/dev/null) | awk '{gsub(",","",$1); print $1}' > $T/total$n
done
/usr/bin/python3 - "$T" "$TOP" <<'PY'
import sys
T, top = sys.argv[1], int(sys.argv[2])
tot = (int(open(f"{T}/total400").read()) - int(open(f"{T}/total200").read())) / 200
print(f"layer instructions per call (outside find_orbits): {tot:,.0f}")
for kind, title in (("yes", "inclusive"), ("no", "exclusive")):
    a, b = {}, {}
    for n, d in ((200, a), (400, b)):
        for line in open(f"{T}/{kind}{n}.tsv"):
            c, _, name = line.rstrip("\n").partition("\t")
            d[name] = max(d.get(name, 0), int(c))
    rows = sorted((((b.get(k, 0) - a.get(k, 0)) / 200, k) for k in set(a) | set(b)), reverse=True)
    print(f"--- top {title} per call")
    shown = 0
    for v, k in rows:
        if title == "inclusive" and ("python3.11]" in k or "below main" in k or "ld-linux" in k or "libc-start" in k):
            continue
        print(f"{v:9.0f} {k[:160]}")
        shown += 1
        if shown >= top: break
PY
[ -n "$KEEP" ] || rm -rf $T
