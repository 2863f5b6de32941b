"""Cost of the command layer (issue 26: "the command layer adds <= 5 % to a 1 ms command"), `tapping orbit` at a
setting where the orbit search takes about a millisecond, end to end:

    PYTHONPATH=build/python /usr/bin/python3 bench/command_layer.py [--repeat 400] [--rounds 3] [--bench build/bin/bench_command_layer]

In one run it times
  * Python: afmkit.tapping.orbit(...) in-process (keywords -> ParamSet -> the command's run -> NumPy columns ->
    afmkit.Result), against the search's own time of the same calls (r.results.search.seconds: the library's
    find_orbits, measured inside it), interleaved;
  * C++ (when the benchmark program bench/bench_command_layer.cpp is built, -DAFMKIT_BUILD_BENCH=ON): the library
    call alone, the command's run on a ParamSet (as the Python module builds it; no process start) and the same
    writing the CSV and sidecar;
and prints each path's time and its ratio to the library call, in wall time and in CPU time (the CPU time a call
takes is far less disturbed by other processes on a shared machine than its wall time), with the machine's load
average before and after; `--rounds` repeats the whole measurement and prints the medians over the rounds. The
target: <= 1.05 (judged on the medians of the CPU-time ratios). Exit status 1 when the Python
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
    """Wall time and CPU time of afmkit.tapping.orbit and the search time it reports, per call (seconds)."""
    wall, cpu, search = [], [], []
    afmkit.tapping.orbit(**CASE)  # warm: module, registry, first allocations
    for _ in range(repeat):
        c0, t0 = time.process_time(), time.perf_counter()
        r = afmkit.tapping.orbit(**CASE)
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
        search.append(r.results.search.seconds)
    return wall, cpu, search, len(r)


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
            times[b["run_name"]] = (b["real_time"] * scale, b["cpu_time"] * scale)
    return times


def load() -> str:
    return "load average {:.2f} {:.2f} {:.2f} on {} cores".format(*os.getloadavg(), os.cpu_count())


def one_round(args) -> dict:
    """One measurement of every path; the ratios to the library call (wall and CPU)."""
    print(f"round: {load()}")
    wall, cpu, search, rows = python_path(args.repeat)
    out = {"python wall": statistics.median([w / s for w, s in zip(wall, search)])}
    print(f"  tapping orbit {CASE}: {rows} orbit(s)")
    print(f"  Python afmkit.tapping.orbit: {statistics.median(wall) * 1e3:.3f} ms median wall, "
          f"{statistics.median(cpu) * 1e3:.3f} ms CPU; search inside it {statistics.median(search) * 1e3:.3f} ms wall; "
          f"wall ratio {out['python wall']:.3f} (median per call)")
    cpp = cpp_path(args.bench)
    if cpp is None:
        print(f"  C++: {args.bench} not built (-DAFMKIT_BUILD_BENCH=ON, target bench_command_layer): skipped")
    else:
        lib_wall, lib_cpu = cpp["Library"]
        print(f"  C++ library call alone:             {lib_wall * 1e3:.3f} ms wall, {lib_cpu * 1e3:.3f} ms CPU")
        for name, what in (("Command", "command on a ParamSet (captured)"),
                           ("CommandFiles", "command writing CSV + sidecar")):
            w, c = cpp[name]
            out[name + " wall"], out[name + " cpu"] = w / lib_wall, c / lib_cpu
            print(f"  C++ {what + ':':34s} {w * 1e3:.3f} ms wall, {c * 1e3:.3f} ms CPU; ratio {w / lib_wall:.3f} "
                  f"wall, {c / lib_cpu:.3f} CPU")
        out["python cpu"] = statistics.median(cpu) / lib_cpu
        print(f"  Python over the C++ library call:   ratio {statistics.median(cpu) / lib_cpu:.3f} CPU")
    print(f"  after: {load()}")
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=400)
    ap.add_argument("--rounds", type=int, default=3, help="repeat the whole measurement; medians over the rounds")
    here = os.path.dirname(os.path.abspath(__file__))
    ap.add_argument("--bench", default=os.path.join(here, "..", "build", "bin", "bench_command_layer"),
                    help="the C++ benchmark program (skipped when missing)")
    args = ap.parse_args()

    rounds = [one_round(args) for _ in range(args.rounds)]
    print(f"medians over {len(rounds)} round(s) (target <= {TARGET}):")
    medians = {k: statistics.median(r[k] for r in rounds) for k in rounds[0]}
    for k, v in medians.items():
        print(f"  {k:20s} {v:.3f}   (rounds: {', '.join(f'{r[k]:.3f}' for r in rounds)})")
    ok = medians.get("python cpu", medians["python wall"]) <= TARGET
    ok &= medians.get("Command cpu", 0.0) <= TARGET
    return 0 if ok else 1
if __name__ == "__main__":
    sys.exit(main())
