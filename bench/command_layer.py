"""Cost of the command layer (issue 26: "the command layer adds <= 5 % to a 1 ms command"), `tapping orbit` at a
setting where the orbit search takes about a millisecond, end to end:

    PYTHONPATH=build/python /usr/bin/python3 bench/command_layer.py [--repeat 400] [--bench build/bin/bench_command_layer]

In one run it times
  * Python: afmkit.tapping.orbit(...) in-process (keywords -> ParamSet -> the command's run -> NumPy columns ->
    afmkit.Result), against the search's own time of the same calls (r.results.search.seconds: the library's
    find_orbits, measured inside it), interleaved;
  * C++ (when the benchmark program bench/bench_command_layer.cpp is built, -DAFMKIT_BUILD_BENCH=ON): the library
    call alone, the command's run on a ParamSet (as the Python module builds it; no process start) and the same
    writing the CSV and sidecar;
and prints each path's time and its ratio to the library call. The target: <= 1.05. Exit status 1 when the Python
or the C++ command layer exceeds it. Run it on an otherwise idle machine. The orbit search runs on one thread
(OMP_NUM_THREADS=1 unless set): on a busy machine its OpenMP threads wait on each other for far longer than the
search takes, which would hide the layer's cost.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")  # before the module (and its OpenMP runtime) loads

import afmkit  # noqa: E402

CASE = dict(quality_factor=2.0, separation=5.0, max_period_multiple=1)  # as bench/bench_command_layer.cpp
TARGET = 1.05


def python_path(repeat: int):
    """Wall time of afmkit.tapping.orbit and the search time it reports, per call (seconds)."""
    wall, search = [], []
    afmkit.tapping.orbit(**CASE)  # warm: module, registry, first allocations
    for _ in range(repeat):
        t0 = time.perf_counter()
        r = afmkit.tapping.orbit(**CASE)
        wall.append(time.perf_counter() - t0)
        search.append(r.results.search.seconds)
    return wall, search, len(r)


def cpp_path(binary: str):
    """Library, Command, CommandFiles times (seconds) from the C++ benchmark program, or None."""
    if not binary or not os.path.exists(binary):
        return None
    out = subprocess.run([binary, "--benchmark_format=json", "--benchmark_min_time=1",
                          "--benchmark_repetitions=3", "--benchmark_report_aggregates_only=true"],
                         check=True, capture_output=True, text=True).stdout
    times = {}
    for b in json.loads(out)["benchmarks"]:
        if b.get("aggregate_name") == "median":
            scale = {"us": 1e-6, "ms": 1e-3, "ns": 1e-9, "s": 1.0}[b["time_unit"]]
            times[b["run_name"]] = b["real_time"] * scale
    return times


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=400)
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument("--bench", default=os.path.join(here, "..", "build", "bin", "bench_command_layer"),
                    help="the C++ benchmark program (skipped when missing)")
    args = ap.parse_args()

    wall, search, rows = python_path(args.repeat)
    ok = True
    med_wall, med_search = statistics.median(wall), statistics.median(search)
    per_call = [w / s for w, s in zip(wall, search)]
    python_ratio = statistics.median(per_call)
    print(f"tapping orbit {CASE}: {rows} orbit(s)")
    print(f"  Python afmkit.tapping.orbit: {med_wall * 1e3:.3f} ms median wall; search inside it "
          f"{med_search * 1e3:.3f} ms; ratio {python_ratio:.3f} (median per call; target <= {TARGET})")
    ok &= python_ratio <= TARGET
    cpp = cpp_path(args.bench)
    if cpp is None:
        print(f"  C++: {args.bench} not built (-DAFMKIT_BUILD_BENCH=ON, target bench_command_layer): skipped")
    else:
        lib = cpp["Library"]
        print(f"  C++ library call alone:             {lib * 1e3:.3f} ms")
        for name, what in (("Command", "command on a ParamSet (captured)"),
                           ("CommandFiles", "command writing CSV + sidecar")):
            print(f"  C++ {what + ':':34s} {cpp[name] * 1e3:.3f} ms; ratio {cpp[name] / lib:.3f}")
        print(f"  Python over the C++ library call:   ratio {med_wall / lib:.3f}")
        ok &= cpp["Command"] / lib <= TARGET
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
