"""python3 -m afmkit.study run FILE [--store S] [--scheduler serial|local|tcp://host:8786] [--workers N]
[--chunk-seconds 1] [--chunk-points N] [--netcdf F] [--quiet]: runs the study described in the TOML file FILE
(docs/study.md)."""
import argparse
import importlib.util
import math
import os
import signal
import sys

from .definition import StudyError, Study, read_toml
from .run import StudyFailure, run

#: The [run] table's fields and the Python types each takes (a wrong type is refused naming the file and field).
RUN_FIELDS = {"store": (str,), "scheduler": (str,), "workers": (int,), "chunk_seconds": (int, float),
              "chunk_points": (int,), "netcdf": (str,)}


def _run_settings(file: str) -> dict:
    """The [run] table of the study file, each field of its type (else StudyError naming the file and field)."""
    settings = read_toml(file).get("run", {})
    if not isinstance(settings, dict):
        raise StudyError("run", f"{file}: 'run' must be a table ([run])")
    unknown = sorted(set(settings) - set(RUN_FIELDS))
    if unknown:
        raise StudyError(f"run.{unknown[0]}", f"{file}: unknown field 'run.{unknown[0]}' (allowed: "
                                              f"{', '.join(sorted(RUN_FIELDS))})")
    for key, value in settings.items():
        types = RUN_FIELDS[key]
        if isinstance(value, bool) or not isinstance(value, types) or (
                isinstance(value, float) and not math.isfinite(value)):
            want = "a string" if types == (str,) else "an integer" if types == (int,) else "a finite number"
            raise StudyError(f"run.{key}", f"{file}: run.{key} = {value!r} is not allowed: must be {want}")
    return settings


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

    def where(e) -> str:  # every message names the study file
        return "" if args.file in str(e) else f"{args.file}: "

    missing = [pkg for module, pkg in (("xarray", "python3-xarray"), ("zarr", "python3-zarr"),
                                       ("distributed", "python3-distributed"), ("netCDF4", "python3-netcdf4"))
               if importlib.util.find_spec(module) is None]
    if missing:  # the machine's set-up, not the study file: exit 1
        print(f"afmkit study: needs the Debian packages {' '.join(missing)} (scripts/bootstrap.sh --all installs "
              "them; docs/study.md)", file=sys.stderr)
        return 1
    try:
        study = Study.from_toml(args.file)
        settings = _run_settings(args.file)

        def pick(name, default=None):
            value = getattr(args, name)
            return value if value is not None else settings.get(name, default)

        store = pick("store", f"out/{study.name}.zarr")
        ds = run(study, store, scheduler=pick("scheduler"), workers=pick("workers"),
                 chunk_seconds=pick("chunk_seconds", 1.0), chunk_points=pick("chunk_points"),
                 progress=not args.quiet, netcdf=pick("netcdf"))
    except (StudyError, ValueError, TypeError) as e:
        field = getattr(e, "field", None) or getattr(e, "parameter", None)
        print(f"afmkit study: {where(e)}{e}" + (f" [field: {field}]" if field and field not in str(e) else ""),
              file=sys.stderr)
        return 2
    except StudyFailure as e:
        print(f"afmkit study: {where(e)}{e} [field: {e.field}]", file=sys.stderr)
        return 1
    except OSError as e:  # not where the study writes (those are StudyError / StudyFailure): the machine's failure
        print(f"afmkit study: {where(e)}input/output failure" + (f" on '{e.filename}'" if e.filename else "")
              + f": {e.strerror or e}", file=sys.stderr)
        return 1
    except RuntimeError as e:  # afmkit.NumericalFailure of the pilot point, a lost Dask worker, …
        print(f"afmkit study: {where(e)}failed: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        print("afmkit study: interrupted; finished chunks are kept, run again to resume", file=sys.stderr)
        return 130
    print(f"afmkit study: {study.size} points in {store} ({ds.attrs['failed_points']} failed numerically)")
    return 0


if __name__ == "__main__":
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    sys.exit(main())
