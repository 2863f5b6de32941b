"""python3 -m afmkit.study run FILE [--store S] [--scheduler serial|local|tcp://host:8786] [--workers N]
[--chunk-seconds 1] [--chunk-points N] [--netcdf F] [--quiet]: runs the study described in the TOML file FILE
(docs/study.md)."""
import argparse
import importlib.util
import math
import os
import signal
import sys

from .._commands import argument_parser, commands, declared_defaults
from .definition import StudyError, Study, read_toml
from .run import StudyFailure, compute, results

_KIND_TYPES = {"file": (str,), "text": (str,), "integer": (int,), "real": (int, float)}
#: The [run] table's fields — the options of `afmkit study run` as it declares them, but the study file itself and
#: quiet — and the Python types each takes (a wrong type is refused naming the file and field).
RUN_FIELDS = {p["key"]: _KIND_TYPES[p["kind"]] for p in next(s for s in commands() if s["path"] == "study run")["params"]
              if p["key"] not in ("file", "quiet")}


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


def make_parser():
    """`run` with the options as `afmkit study run` declares them (its C++ ParamSet): each one given overrides the
    file's [run] table, which overrides the declared default (declared_defaults; main)."""
    parser = argparse.ArgumentParser(prog="python3 -m afmkit.study", description=__doc__)
    sub = parser.add_subparsers(dest="action", required=True)
    sub.add_parser("run", help="run (or resume) a study",
                   parents=[argument_parser("study run", given_only=True, add_help=False)])
    return parser


def main(argv=None) -> int:
    parser = make_parser()
    args = parser.parse_args(argv)

    def terminated(signum, frame):  # SIGTERM stops as Ctrl-C does: finished chunks stay
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, terminated)

    def where(e) -> str:  # every message names the study file
        return "" if args.file in str(e) else f"{args.file}: "

    def missing(needed) -> int:  # the machine's set-up, not the study file: exit 1 (0: nothing missing)
        absent = [pkg for module, pkg in needed if importlib.util.find_spec(module) is None]
        if absent:
            print(f"afmkit study: needs the Debian packages {' '.join(absent)} (scripts/bootstrap.sh --all installs "
                  "them; docs/study.md)", file=sys.stderr)
        return 1 if absent else 0

    if missing([("zarr", "python3-zarr")]):
        return 1
    try:
        study = Study.from_toml(args.file)
        settings = _run_settings(args.file)

        declared = declared_defaults("study run")

        def pick(name, default=None):  # given, else the file's [run] table, else the declared default
            value = getattr(args, name)
            if value is None:
                value = settings.get(name)
            return value if value is not None else declared[name] if declared[name] is not None else default

        store = pick("store", f"out/{study.name}.zarr")
        netcdf = pick("netcdf")
        scheduler = pick("scheduler")
        # Dask only for a scheduler's address, xarray and netCDF4 only for the NetCDF file
        needed = ([("distributed", "python3-distributed")] if "://" in str(scheduler or "") else []) + (
            [("xarray", "python3-xarray"), ("netCDF4", "python3-netcdf4")] if netcdf is not None else [])
        if missing(needed):
            return 1
        path, failed = compute(study, store, scheduler=scheduler, workers=pick("workers"),
                               chunk_seconds=pick("chunk_seconds"), chunk_points=pick("chunk_points"),
                               progress=not args.quiet, netcdf=netcdf)
        if netcdf is not None:  # xarray only for the NetCDF file (its import is half of a short study's start-up)
            results(path, failed, netcdf)
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
    print(f"afmkit study: {study.size} points in {store} ({failed} failed numerically)")
    return 0


if __name__ == "__main__":
    os.environ.setdefault("OMP_NUM_THREADS", "1")
    sys.exit(main())
