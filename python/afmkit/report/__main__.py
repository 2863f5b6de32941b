"""python3 -m afmkit.report [--output-dir out/report] [--jobs 2] [--figures all]: what `afmkit report` runs."""
import argparse
import os
import signal
import sys

from .build import ReportError, ReportFailure, build


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="afmkit report", description=__doc__)
    parser.add_argument("--output-dir", default="out/report", help="folder for index.html and the figures")
    parser.add_argument("--jobs", type=int, default=min(2, os.cpu_count() or 1),
                        help="figures computed at the same time (processes)")
    parser.add_argument("--figures", default="all", help="'all' or a comma-separated list of figure ids")
    args = parser.parse_args(argv)

    def terminated(signum, frame):  # SIGTERM cleans up as Ctrl-C does
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, terminated)
    try:
        path = build(args.output_dir, jobs=args.jobs, figures=args.figures)
    except (ReportError, ReportFailure) as e:
        print(f"afmkit report: {e}", file=sys.stderr)
        return e.status
    except KeyboardInterrupt:
        print("afmkit report: interrupted; index.html was not changed", file=sys.stderr)
        return 130
    print(f"afmkit report: wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
