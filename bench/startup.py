#!/usr/bin/env python3
"""Start-up of the afmkit program as users run it (issue 28 §2: <= 5 ms for `afmkit --version` and a trivial
command). Runs each case N times, interleaved with /bin/true (the baseline measured in the same run: what any
process start costs here), each process started directly (os.posix_spawn) and waited with os.wait4 for its own
CPU time (user + system); prints the medians of wall and CPU time and their ratios to /bin/true, and with
--baseline OLD_PROGRAM the same cases of another build beside them (e.g. the program before a change).

    python3 bench/startup.py build/bin/afmkit [--runs 200] [--baseline /tmp/afmkit_old]
"""
import argparse
import os
import statistics
import sys
import tempfile
import time

CASES = [
    ("--version", ["--version"]),
    ("--help", ["--help"]),
    ("tapping hb --help", ["tapping", "hb", "--help"]),
    ("tapping hb --points 2 --output ''", ["tapping", "hb", "--points", "2", "--output", ""]),
]


def run_once(argv, cwd):
    null = os.open(os.devnull, os.O_WRONLY)
    start = time.perf_counter_ns()
    pid = os.posix_spawn(argv[0], argv, os.environ, file_actions=[(os.POSIX_SPAWN_DUP2, null, 1),
                                                                   (os.POSIX_SPAWN_DUP2, null, 2)])
    _, status, usage = os.wait4(pid, 0)
    wall = (time.perf_counter_ns() - start) * 1e-6
    os.close(null)
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"{argv} exited {os.waitstatus_to_exitcode(status)}")
    return wall, (usage.ru_utime + usage.ru_stime) * 1e3


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("program")
    ap.add_argument("--runs", type=int, default=200)
    ap.add_argument("--baseline", help="another build of the program, timed in the same runs")
    args = ap.parse_args()
    programs = {"afmkit": os.path.abspath(args.program)}
    if args.baseline:
        programs["baseline"] = os.path.abspath(args.baseline)
    true = "/bin/true"
    samples = {}  # (program, case) -> [(wall, cpu)]
    os.chdir(tempfile.mkdtemp(prefix="afmkit_startup_"))
    for _ in range(args.runs):  # interleaved: the machine's load affects every case alike
        samples.setdefault(("/bin/true", ""), []).append(run_once([true], "."))
        for name, path in programs.items():
            for label, case in CASES:
                samples.setdefault((name, label), []).append(run_once([path] + case, "."))
    med = {k: (statistics.median(w for w, _ in v), statistics.median(c for _, c in v)) for k, v in samples.items()}
    t_wall, t_cpu = med[("/bin/true", "")]
    load = os.getloadavg()[0]
    print(f"{args.runs} runs each, interleaved; load average {load:.2f} on {os.cpu_count()} cores")
    print(f"{'program':<10} {'case':<36} {'wall ms':>8} {'CPU ms':>8} {'wall/true':>10} {'CPU/true':>9}"
          + ("  new/baseline (wall, CPU)" if args.baseline else ""))
    print(f"{'/bin/true':<10} {'':<36} {t_wall:8.2f} {t_cpu:8.2f} {1:10.2f} {1:9.2f}")
    for name in programs:
        for label, _ in CASES:
            w, c = med[(name, label)]
            extra = ""
            if args.baseline and name == "afmkit":
                bw, bc = med[("baseline", label)]
                extra = f"  {w / bw:.2f}, {c / bc:.2f}"
            print(f"{name:<10} {label:<36} {w:8.2f} {c:8.2f} {w / t_wall:10.2f} {c / max(t_cpu, 1e-3):9.2f}{extra}")
    worst = max(med[("afmkit", label)][0] for label, _ in CASES[:1] + CASES[3:])
    print(f"target: `--version` and a trivial command <= 5 ms wall: {'met' if worst <= 5.0 else 'NOT met'} "
          f"(worst {worst:.2f} ms)")


if __name__ == "__main__":
    main()
