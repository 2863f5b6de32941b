"""python3 -m afmkit.study run FILE [--store S] [--scheduler serial|local|tcp://host:8786] [--workers N]
[--chunk-seconds 1] [--chunk-points N] [--netcdf F] [--quiet]: runs the study described in the TOML file FILE
(docs/study.md)."""
import argparse
import os
import signal
import sys
import tomllib
from pathlib import Path

from .definition import StudyError, Study
from .run import run


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="python3 -m afmkit.study", description=__doc__)
    sub = parser.add_subparsers(dest="action", required=True)
    p = sub.add_parser("run", help="run (or resume) a study")
    p.add_argument("file", help="the study's TOML file")
    p.add_argument("--store", help="Zarr store of the results (default: the file's [run] store, or "
                                   "out/<name>.zarr)")
    p.add_argument("--scheduler", help="serial, local (a LocalCluster, the default) or a Dask scheduler address "
                                       "tcp://host:8786")
    p.add_argument("--workers", type=int, help="worker processes of the local cluster (default: one per core)")
    p.add_argument("--chunk-seconds", type=float, help="computation per chunk in seconds (default 1)")
    p.add_argument("--chunk-points", type=int, help="points per chunk (instead of --chunk-seconds)")
    p.add_argument("--netcdf", help="also write the results to this NetCDF file")
    p.add_argument("--quiet", action="store_true", help="no progress lines")
    args = parser.parse_args(argv)

    def terminated(signum, frame):  # SIGTERM stops as Ctrl-C does: finished chunks stay
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, terminated)
    try:
        study = Study.from_toml(args.file)
        settings = tomllib.loads(Path(args.file).read_text(encoding="utf-8")).get("run", {})
        allowed = {"store", "scheduler", "workers", "chunk_seconds", "chunk_points", "netcdf"}
        unknown = sorted(set(settings) - allowed)
        if unknown:
            raise StudyError(f"run.{unknown[0]}", f"{args.file}: unknown field 'run.{unknown[0]}' (allowed: "
                                                  f"{', '.join(sorted(allowed))})")
        def pick(name, default=None):
            value = getattr(args, name)
            return value if value is not None else settings.get(name, default)

        store = Path(pick("store", f"out/{study.name}.zarr"))
        store.parent.mkdir(parents=True, exist_ok=True)
        ds = run(study, store, scheduler=pick("scheduler"), workers=pick("workers"),
                 chunk_seconds=pick("chunk_seconds", 1.0), chunk_points=pick("chunk_points"),
                 progress=not args.quiet, netcdf=pick("netcdf"))
    except (StudyError, ValueError, TypeError) as e:
        field = getattr(e, "field", None) or getattr(e, "parameter", None)
        print(f"afmkit study: {e}" + (f" [field: {field}]" if field and field not in str(e) else ""),
              file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("afmkit study: interrupted; finished chunks are kept, run again to resume", file=sys.stderr)
        return 130
    print(f"afmkit study: {study.size} points in {store} ({ds.attrs['failed_points']} failed numerically)")
    return 0


if __name__ == "__main__":
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    sys.exit(main())
