#!/usr/bin/env python3
"""`afmkit scan` end to end as users run it (issue 28 §4: 10^7 samples imaged to 1024^2 with all outputs <= 1.5 s):

    afmkit scan --sample rough --sample-rate 100e3 --radial-speed 4e-5 --image-resolution 1024

(50 Hz spindle, 100 s to the 4 mm rim: 10^7 samples, 5000 turns at 2000 samples per turn, pitch 0.8 µm; the default
2048^2 rough sample generated; the controller on, so the uncontrolled comparison run too; 12 image files, the turn
table and its sidecar). Runs the program and, with --baseline OLD_PROGRAM (e.g. a build of the code before a change),
the old one interleaved with it, each in its own output folder; prints per run wall, CPU (user + system, of the
process and its threads), peak RSS, the medians, the ratios old/new, the machine load (1-minute load average before
and after), and whether every output file is byte-identical to the baseline's (the sidecar compared with its output
paths replaced, which name the folders).

    python3 bench/scan_end_to_end.py build/bin/afmkit [--baseline /tmp/afmkit_old] [--runs 5] [--profile]

On a loaded machine the wall says little: --profile also runs each program once under `perf record -e cpu-clock`
(the CPU time of every thread, whatever the load) and prints, per phase (start and sample / simulation / after the
scan / files: cut where the main thread first and last simulates and first packs a GSF file), the CPU of its threads
and a lower bound of its wall on an idle 2-core machine: at least the busiest thread's CPU and half the total
(waits — disk syncs — and the order the threads depend on each other are not counted).
"""
import argparse
import filecmp
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

ARGS = ["scan", "--sample", "rough", "--sample-rate", "100e3", "--radial-speed", "4e-5", "--image-resolution", "1024"]


def run_once(program, folder):
    argv = [program] + ARGS + ["--image-output", os.path.join(folder, "scan"),
                               "--output", os.path.join(folder, "turns.csv")]
    null = os.open(os.devnull, os.O_WRONLY)
    start = time.perf_counter()
    pid = os.posix_spawn(argv[0], argv, os.environ, file_actions=[(os.POSIX_SPAWN_DUP2, null, 1),
                                                                   (os.POSIX_SPAWN_DUP2, null, 2)])
    _, status, usage = os.wait4(pid, 0)
    wall = time.perf_counter() - start
    os.close(null)
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"{argv} exited {os.waitstatus_to_exitcode(status)}")
    return wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024.0


def phase_profile(program, folder, rate=4000):
    """Per-phase CPU of each thread from a perf cpu-clock profile; returns lines to print."""
    data = os.path.join(folder, "perf.data")
    argv = [program] + ARGS + ["--image-output", os.path.join(folder, "scan"),
                               "--output", os.path.join(folder, "turns.csv")]
    subprocess.run(["perf", "record", "-q", "-e", "cpu-clock", "-F", str(rate), "-o", data, "--"] + argv,
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    script = subprocess.run(["perf", "script", "-i", data, "-F", "tid,time,ip,sym"], check=True,
                            capture_output=True, text=True).stdout
    os.remove(data)
    rows = []
    for line in script.splitlines():
        p = line.split()
        if len(p) >= 3:
            rows.append((p[0], float(p[1].rstrip(":")), " ".join(p[3:])))
    main = rows[0][0]
    sim = [t for tid, t, sym in rows if tid == main and "simulate_scan" in sym]
    gsf = [t for tid, t, sym in rows if tid == main and "format_gsf" in sym]
    cuts = [min(sim), max(sim), min(gsf)]
    per = [{} for _ in range(4)]
    for tid, t, _ in rows:
        k = sum(t >= c for c in cuts)
        per[k][tid] = per[k].get(tid, 0) + 1
    out, bound = [], 0.0
    for name, threads in zip(["start and sample", "simulation", "after the scan", "files"], per):
        cpu, busiest = sum(threads.values()) / rate, max(threads.values(), default=0) / rate
        bound += max(busiest, cpu / 2)
        out.append(f"  {name}: CPU {cpu:.3f} s over {len(threads)} threads, busiest {busiest:.3f} s "
                   f"-> >= {max(busiest, cpu / 2):.3f} s")
    out.append(f"  idle 2-core wall >= {bound:.3f} s (CPU {len(rows) / rate:.3f} s)")
    return out


def sidecar_without_paths(path, folder):
    text = open(path).read().replace(folder, "<folder>")
    return json.loads(text)


def json_differences(old, new, path=""):
    """The key paths where two JSON values differ (added, removed or changed)."""
    if isinstance(old, dict) and isinstance(new, dict):
        out = []
        for k in sorted(set(old) | set(new)):
            p = f"{path}.{k}" if path else k
            if k not in old:
                out.append(f"+{p}")
            elif k not in new:
                out.append(f"-{p}")
            else:
                out += json_differences(old[k], new[k], p)
        return out
    return [] if old == new else [path]


def compare(new_folder, old_folder):
    differing = []
    for name in sorted(os.listdir(old_folder)):
        a, b = os.path.join(old_folder, name), os.path.join(new_folder, name)
        if name.endswith(".json"):
            keys = json_differences(sidecar_without_paths(a, old_folder), sidecar_without_paths(b, new_folder))
            if keys:
                differing.append(f"{name} ({', '.join(keys)})")
        elif not (os.path.exists(b) and filecmp.cmp(a, b, shallow=False)):
            differing.append(name)
    return len(os.listdir(old_folder)), differing


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("program")
    ap.add_argument("--baseline", help="the old program, run interleaved with the new one")
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--profile", action="store_true", help="per-phase CPU of each program from perf (see above)")
    a = ap.parse_args()
    programs = [("new", os.path.abspath(a.program))]
    if a.baseline:
        programs.append(("old", os.path.abspath(a.baseline)))
    load_before = os.getloadavg()[0]
    results = {name: [] for name, _ in programs}
    with tempfile.TemporaryDirectory() as tmp:
        folders = {name: os.path.join(tmp, name) for name, _ in programs}
        for f in folders.values():
            os.makedirs(f)
        for run in range(a.runs):
            for name, program in (programs if run % 2 == 0 else programs[::-1]):
                wall, cpu, rss = run_once(program, folders[name])
                results[name].append((wall, cpu, rss))
                print(f"run {run} {name}: wall {wall:.3f} s, CPU {cpu:.3f} s, peak RSS {rss:.1f} MB", flush=True)
        agreement = compare(folders["new"], folders["old"]) if a.baseline else None
        if a.profile:
            for name, program in programs:
                print(f"{name}, phases (perf cpu-clock):")
                for line in phase_profile(program, folders[name]):
                    print(line)
    load_after = os.getloadavg()[0]
    med = {name: [statistics.median(r[k] for r in rows) for k in range(3)] for name, rows in results.items()}
    for name, (wall, cpu, rss) in med.items():
        print(f"{name}: median wall {wall:.3f} s, CPU {cpu:.3f} s, peak RSS {rss:.1f} MB")
    if a.baseline:
        (nw, nc, nr), (ow, oc, orss) = med["new"], med["old"]
        print(f"ratio old/new: wall {ow / nw:.2f}, CPU {oc / nc:.2f}; peak RSS new/old {nr / orss:.3f}")
        files, differing = agreement
        print(f"outputs: {files - len(differing)} of {files} files byte-identical to the baseline's"
              + (f"; differing: {', '.join(differing)}" if differing else ""))
    print(f"machine load (1-minute average): {load_before:.2f} before, {load_after:.2f} after, "
          f"{os.cpu_count()} cores")


if __name__ == "__main__":
    main()
