"""Compare the outputs of compare.sh: CSV byte for byte; sidecars and --json byte for byte, else after removing
timing keys (seconds, ...) and the new "grid"; report counts."""
import json, os, sys, filecmp
OUT = sys.argv[1]
TIMING = {"seconds", "seconds_per_separation", "elapsed"}
def strip(x):
    if isinstance(x, dict):
        return {k: strip(v) for k, v in x.items() if k not in TIMING and k != "grid"}
    if isinstance(x, list):
        return [strip(v) for v in x]
    return x
files = same_bytes = same_norm = differ = 0
for case in sorted(os.listdir(f"{OUT}/base")):
    b, n = f"{OUT}/base/{case}", f"{OUT}/new/{case}"
    for f in sorted(os.listdir(b)):
        if f in ("stderr.txt",):
            continue
        pb, pn = f"{b}/{f}", f"{n}/{f}"
        files += 1
        if not os.path.exists(pn):
            print("MISSING", case, f); differ += 1; continue
        if filecmp.cmp(pb, pn, shallow=False):
            same_bytes += 1; continue
        if f.endswith(".json") or f == "json.txt":
            try:
                if strip(json.load(open(pb))) == strip(json.load(open(pn))):
                    same_norm += 1; print("same but timing/grid:", case, f); continue
            except Exception as e:
                print("json error", case, f, e)
        if f == "stdout.txt":
            # summary lines hold times (search: ... s)
            lb, ln = open(pb).read().splitlines(), open(pn).read().splitlines()
            import re
            t = lambda s: re.sub(r"[0-9.]+(e-?[0-9]+)? ?(ms|s|µs)\b", "T", s)
            if [t(x) for x in lb] == [t(x) for x in ln]:
                same_norm += 1; print("same but timing:", case, f); continue
        differ += 1
        print("DIFFER", case, f)
print(f"{files} files compared: {same_bytes} byte-identical, {same_norm} identical but for timings/grid, {differ} differ")
