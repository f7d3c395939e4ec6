"""The ``hmatddm`` command line.

    hmatddm validate [--json]     closed-form checks as a table of error and time
"""
import argparse
import json
import sys

EXIT_OK, EXIT_FAILED, EXIT_BAD_INPUT, EXIT_NOT_CONVERGED = 0, 1, 2, 3


def _validate(args):
    from .validate import format_table, run_checks

    rows = run_checks()
    if args.json:
        print(json.dumps(rows, indent=2))
    else:
        print(format_table(rows))
    return EXIT_OK if all(r["passed"] for r in rows) else EXIT_FAILED


def build_parser():
    parser = argparse.ArgumentParser(prog="hmatddm", description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    validate = sub.add_parser("validate", help="closed-form checks (Griffith, Sneddon) as a table")
    validate.add_argument("--json", action="store_true", help="print JSON instead of a table")
    validate.set_defaults(handler=_validate)
    return parser


def main(argv=None):
    from .errors import ConvergenceError, InputError

    args = build_parser().parse_args(argv)
    try:
        return args.handler(args)
    except InputError as exc:
        print(f"hmatddm: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except ConvergenceError as exc:
        print(f"hmatddm: did not converge: {exc}", file=sys.stderr)
        return EXIT_NOT_CONVERGED


if __name__ == "__main__":
    sys.exit(main())
