#!/usr/bin/env python3
"""`afmkit report` as users run it (issue 28 §5: <= 3 s), against the report of an earlier commit in the same run.

Each run is a whole process, `python3 -m afmkit.report` (what `afmkit report` execs), timed from its start until it
and every process it started have ended: wall time, and CPU time of all of them (this script is made a child
subreaper, so the orphans a pool leaves, such as a fork server, are reaped here and counted). The new and the old
package run in interleaved rounds; the medians, their ratio and the machine's load average during the runs are
printed. The old package is the tree of --baseline (a git commit) with this build's compiled module. The PNG files of
the last round are compared pixel by pixel (decoded RGBA), figure by figure.

    PYTHONPATH=build/python /usr/bin/python3 bench/report_speed.py [--build build] [--runs 5] [--baseline ec6a91b]
        [--jobs 2] [--figures all] [--imports]

--imports also prints the CPU time of the imports each process pays (an interpreter alone, `import afmkit`, and
the figure modules with Matplotlib), and the figures' times on one core (the costs in REPORT_FIGURES).
"""
import argparse
import os
import re
import shutil
import statistics
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

from whole_process import old_tree, run, subreaper  # noqa: E402  (bench/ is the script's folder)


def pixels_equal(a: Path, b: Path) -> bool:
    import matplotlib.image as mpimg
    import numpy as np

    x, y = mpimg.imread(a), mpimg.imread(b)
    return x.shape == y.shape and bool(np.array_equal(x, y))


def import_costs(packages: dict, runs: int) -> None:
    cases = [("python3 -c pass", "pass"), ("import afmkit", "import afmkit"),
             ("figure modules (Matplotlib)", "import afmkit.figures.seed000, afmkit.figures.seed003, "
                                             "afmkit.figures.scan")]
    print("imports (CPU s of the whole process, median of %d):" % runs)
    for label, code in cases:
        cpu = []
        for _ in range(runs):
            env = dict(os.environ, PYTHONPATH=str(packages["new"]), OMP_NUM_THREADS="1")
            cpu.append(run([sys.executable, "-c", code], env, ".")[1])
        print(f"  {label:<30} {statistics.median(cpu):6.2f} s")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default=str(ROOT / "build"))
    ap.add_argument("--runs", type=int, default=5)
    ap.add_argument("--baseline", default="ec6a91b", help="git commit of the old report (default: before issue 28)")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--figures", default="all")
    ap.add_argument("--imports", action="store_true")
    args = ap.parse_args()
    subreaper()
    build = Path(args.build).resolve()
    work = Path(tempfile.mkdtemp(prefix="afmkit-bench-report-"))
    try:
        packages = {"new": build / "python", "old": old_tree(args.baseline, build, work)}
        if args.imports:
            import_costs(packages, args.runs)
        load_start = os.getloadavg()[0]
        samples = {k: [] for k in packages}
        for k in range(args.runs):  # interleaved: the machine's load hits both alike
            for name, pkg in (packages.items() if k % 2 == 0 else reversed(packages.items())):
                env = dict(os.environ, PYTHONPATH=str(pkg))
                out = work / f"out-{name}"
                samples[name].append(run([sys.executable, "-m", "afmkit.report", "--output-dir", str(out),
                                          "--jobs", str(args.jobs), "--figures", args.figures], env, work))
        print(f"afmkit report --jobs {args.jobs} --figures {args.figures}: {args.runs} runs each, interleaved; "
              f"{os.cpu_count()} cores; load average (1 min) {load_start:.2f} before the runs, "
              f"{os.getloadavg()[0]:.2f} after; baseline {args.baseline}")
        print(f"{'':<12} {'wall s':>7} {'CPU s':>7} {'load':>6}   runs (wall s)")
        med = {}
        for name, s in samples.items():
            med[name] = (statistics.median(w for w, _, _, _ in s), statistics.median(c for _, c, _, _ in s))
            print(f"{name:<12} {med[name][0]:7.2f} {med[name][1]:7.2f} {statistics.median(l for *_, l, _ in s):6.2f}"
                  f"   " + " ".join(f"{w:.2f}" for w, *_ in s))
        print(f"new / old: wall {med['new'][0] / med['old'][0]:.2f}, CPU {med['new'][1] / med['old'][1]:.2f}; "
              f"target <= 3 s wall: {'met' if med['new'][0] <= 3.0 else 'NOT met'} (median {med['new'][0]:.2f} s)")
        new_pngs = sorted((work / "out-new" / "figures").glob("*.png"))
        same = [p.name for p in new_pngs if pixels_equal(p, work / "out-old" / "figures" / p.name)]
        differ = sorted({p.name for p in new_pngs} - set(same))
        print(f"pixel-identical to the old report: {len(same)} of {len(new_pngs)} figures"
              + (f"; differ: {', '.join(differ)}" if differ else ""))
        if args.imports:
            env = dict(os.environ, PYTHONPATH=str(packages["new"]))
            err = run([sys.executable, "-m", "afmkit.report", "--output-dir", str(work / "one"), "--jobs", "1",
                       "--figures", args.figures], env, work)[3]
            print("figures on one core (s): " + ", ".join(
                f"{m.group(1)} {m.group(2)}" for m in re.finditer(r"\] (\S+):\s+([\d.]+) s", err)))
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
