#!/usr/bin/env python3
"""`afmkit study run` as users run it (issue 28 §5): the start-up of a short study (<= 1 s serially) and the
speed-up of 2 local workers over the serial run for a study of about 15 s (>= 1.8x on an idle 2-core machine),
each against the study runner of an earlier commit (--baseline: a Dask LocalCluster for "local") in the same run.

Each run is a whole process, `python3 -m afmkit.study run FILE` (what `afmkit study run` execs), timed until it and
every process it started have ended: wall time, and CPU time of all of them (this script is a child subreaper, so
orphans such as a fork server or Dask's processes are reaped and counted here). Configurations run in interleaved
rounds; medians, ratios and the machine's load average (os.getloadavg, 1 min) during the runs are printed, and the
results of every configuration are compared with the serial run's, bit for bit.

    PYTHONPATH=build/python /usr/bin/python3 bench/study_scaling.py [--runs 3] [--seconds 15] [--baseline ec6a91b]
"""
import argparse
import os
import shutil
import statistics
import sys
import tempfile
from pathlib import Path

os.environ.setdefault("OMP_NUM_THREADS", "1")

ROOT = Path(__file__).resolve().parent.parent

from whole_process import old_tree, run, subreaper  # noqa: E402  (bench/ is the script's folder)

STUDY = """name = "bench"
computation = "tapping.orbit"
outputs = ["max(amplitude | stable)", "count(amplitude | stable)"]
[parameters]
law = "attractive"
approach_adhesion = 0.5
departure_adhesion = 1.0
frequency_ratio = 1.005
[axes]
separation = {{ start = 7.0, stop = 21.0, points = {points} }}
"""


def same_results(a: Path, b: Path) -> bool:
    import numpy as np
    import zarr

    ga, gb = zarr.open_group(str(a), mode="r"), zarr.open_group(str(b), mode="r")
    names = [n for n in ga.array_keys() if not n.startswith("chunk_")]
    return all(np.array_equal(ga[n][:], gb[n][:], equal_nan=True) for n in names)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=str(ROOT / "build"))
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--seconds", type=float, default=15.0, help="the long study's computation on one core")
    ap.add_argument("--short-points", type=int, default=4, help="points of the short study (start-up)")
    ap.add_argument("--baseline", default="ec6a91b", help="git commit of the old study runner")
    args = ap.parse_args()
    subreaper()
    build = Path(args.build).resolve()
    sys.path.insert(0, str(build / "python"))
    from afmkit.study import Study
    from afmkit.study.run import _pilot

    work = Path(tempfile.mkdtemp(prefix="afmkit-bench-study-"))
    try:
        packages = {"new": build / "python", "old": old_tree(args.baseline, build, work)}
        (work / "probe.toml").write_text(STUDY.format(points=200))
        probe = Study.from_toml(str(work / "probe.toml"))
        cost = _pilot(probe)[2]  # CPU time per point
        points = max(2, round(args.seconds / cost))
        (work / "short.toml").write_text(STUDY.format(points=args.short_points))
        (work / "long.toml").write_text(STUDY.format(points=points))
        print(f"per point {cost * 1e3:.1f} ms: long study {points} points (~{points * cost:.1f} s on one core), "
              f"short study {args.short_points} points; {os.cpu_count()} cores")
        configs = [  # (label, package, study file, scheduler)
            ("short, serial (new)", "new", "short", "serial"), ("short, serial (old)", "old", "short", "serial"),
            ("short, local (new)", "new", "short", "local"), ("short, local (old: Dask)", "old", "short", "local"),
            ("long, serial (new)", "new", "long", "serial"), ("long, local 2 (new)", "new", "long", "local"),
            ("long, local 2 (old: Dask)", "old", "long", "local"),
        ]
        samples = {c[0]: [] for c in configs}
        for k in range(args.runs):  # interleaved rounds
            for label, pkg, which, scheduler in (configs if k % 2 == 0 else configs[::-1]):
                store = work / f"{label.replace(' ', '_').replace(',', '').replace(':', '')}-{k}.zarr"
                env = dict(os.environ, PYTHONPATH=str(packages[pkg]))
                samples[label].append(run([sys.executable, "-m", "afmkit.study", "run", str(work / f"{which}.toml"),
                                           "--store", str(store), "--scheduler", scheduler, "--workers", "2",
                                           "--quiet"], env, work)[:3])
        med = {}
        print(f"{'':<28} {'wall s':>7} {'CPU s':>7} {'load':>6}   runs (wall s)")
        for label, s in samples.items():
            med[label] = (statistics.median(w for w, _, _ in s), statistics.median(c for _, c, _ in s))
            print(f"{label:<28} {med[label][0]:7.2f} {med[label][1]:7.2f} "
                  f"{statistics.median(l for *_, l in s):6.2f}   " + " ".join(f"{w:.2f}" for w, *_ in s))

        def ratio(a, b, i=0):
            return med[a][i] / med[b][i]

        print(f"short study serial, new / old: wall {ratio('short, serial (new)', 'short, serial (old)'):.2f}, "
              f"CPU {ratio('short, serial (new)', 'short, serial (old)', 1):.2f}; target <= 1 s start-up: "
              f"{'met' if med['short, serial (new)'][0] <= 1.0 else 'NOT met'} "
              f"({med['short, serial (new)'][0]:.2f} s for {args.short_points} points)")
        print(f"short study local, new / old: wall {ratio('short, local (new)', 'short, local (old: Dask)'):.2f}, "
              f"CPU {ratio('short, local (new)', 'short, local (old: Dask)', 1):.2f}")
        s_new = ratio("long, serial (new)", "long, local 2 (new)")
        print(f"long study, 2 local workers over serial: new {s_new:.2f}x, old (Dask) "
              f"{ratio('long, serial (new)', 'long, local 2 (old: Dask)'):.2f}x; target >= 1.8x on an idle 2-core "
              f"machine: {'met' if s_new >= 1.8 else 'NOT met'} (load {os.getloadavg()[0]:.2f})")
        reference = work / "long_serial_(new)-0.zarr"
        mismatched = [p.name for p in sorted(work.glob("*.zarr")) if p.name.startswith("long")
                      and not same_results(reference, p)]
        print("results bit for bit the serial run's: " + ("yes, every long run" if not mismatched
                                                            else f"NO: {', '.join(mismatched)}"))
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
