"""Benchmark of parameter studies (docs/study.md): scheduling overhead of Dask against the serial run at the default
chunk size (about 1 s of computation per chunk), and the speed-up of 2 workers over 1, all in this process.

    PYTHONPATH=build/python /usr/bin/python3 bench/study_scaling.py [--chunks 16]

Prints the per-point cost, the wall times (the fastest of --repeat interleaved runs of the whole study) and the ratios the issue sets targets for (overhead <= 5 %, 2 workers
>= 1.8x one worker on 2 cores). Run it on an otherwise idle machine.
"""
import argparse
import os
import shutil
import tempfile
import time

os.environ.setdefault("OMP_NUM_THREADS", "1")

import distributed  # noqa: E402

from afmkit.study import Study, run  # noqa: E402
from afmkit.study.run import _pilot  # noqa: E402


def study(points: int) -> Study:
    return Study.make("tapping.orbit",
                      axes={"separation": {"start": 7.0, "stop": 21.0, "points": points}},
                      outputs=["max(amplitude | stable)", "count(amplitude | stable)"],
                      parameters={"law": "attractive", "approach_adhesion": 0.5, "departure_adhesion": 1.0,
                                  "frequency_ratio": 1.005})


def timed(fn) -> float:
    start = time.perf_counter()
    fn()
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--chunks", type=int, default=32, help="chunks of about 1 s each")
    parser.add_argument("--repeat", type=int, default=3, help="runs of each configuration; the fastest counts")
    args = parser.parse_args()
    cost, _ = _pilot(study(200))
    per_chunk = max(1, round(1.0 / cost))
    s = study(per_chunk * args.chunks)
    print(f"per point: {cost * 1e3:.1f} ms; {per_chunk} points per chunk (about 1 s); {args.chunks} chunks, "
          f"{s.size} points")
    work = tempfile.mkdtemp(prefix="afmkit-bench-study-")
    try:
        def cluster(n):
            return distributed.LocalCluster(n_workers=n, threads_per_worker=1, processes=True,
                                            dashboard_address=None, host="127.0.0.1", env={"OMP_NUM_THREADS": "1"})

        def timed_run(name, scheduler, k):
            run(study(8), f"{work}/warm-up-{name}-{k}.zarr", scheduler=scheduler, chunk_points=2, progress=False)
            return timed(lambda: run(s, f"{work}/{name}-{k}.zarr", scheduler=scheduler, chunk_points=per_chunk,
                                     progress=False))

        # rounds interleave the configurations so that drifts of the machine's speed hit all three alike; each
        # configuration runs alone (a new cluster per round), after a small warm-up study (imports, worker start-up:
        # not its time); the fastest whole run (pilot, store, chunks, opening the results) of each counts
        times = {"serial": [], 1: [], 2: []}
        for k in range(args.repeat):
            times["serial"].append(timed_run("serial", "serial", k))
            for n in (1, 2):
                with cluster(n) as c, distributed.Client(c) as client:
                    times[n].append(timed_run(f"dask{n}", client, k))
        t_serial, results = min(times["serial"]), {1: min(times[1]), 2: min(times[2])}
        print("runs (s): " + "; ".join(f"{name}: " + " ".join(f"{t:.2f}" for t in ts) for name, ts in times.items()))
        print(f"serial (this process)     {t_serial:7.2f} s")
        print(f"Dask, 1 worker            {results[1]:7.2f} s   overhead {100 * (results[1] / t_serial - 1):+.1f} % "
              f"(target <= 5 %)")
        print(f"Dask, 2 workers           {results[2]:7.2f} s   speed-up over 1 worker {results[1] / results[2]:.2f}x "
              f"(target >= 1.8x on 2 cores)")
    finally:
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
