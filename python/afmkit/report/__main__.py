"""python3 -m afmkit.report [--output-dir out/report] [--jobs 2] [--figures all]: what `afmkit report` runs."""
import signal
import sys

from .._commands import argument_parser
from .build import ReportError, ReportFailure, build


def make_parser():
    """The options as `afmkit report` declares them (its C++ ParamSet): the same keys, defaults and help."""
    return argument_parser("report", prog="afmkit report")


def main(argv=None) -> int:
    args = make_parser().parse_args(argv)

    def terminated(signum, frame):  # SIGTERM cleans up as Ctrl-C does
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, terminated)
    try:
        path = build(args.output_dir, jobs=args.jobs, figures=args.figures, _own_process=True)
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
