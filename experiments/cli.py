"""The ``ddmm`` command line.  Bad input ends with a one-line error and exit status 2."""

from __future__ import annotations

import argparse
import sys

__all__ = ["build_parser", "main"]


class _Parser(argparse.ArgumentParser):
    """An ArgumentParser whose usage errors are one line and exit status 2."""

    def error(self, message):
        self.exit(2, f"ddmm: error: {message} (see '{self.prog} --help')\n")


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every subcommand registered."""
    from ddmm import __version__
    from ddmm.experiments import (
        bench,
        cmd_accuracy,
        cmd_biology,
        cmd_export,
        cmd_physiology,
        cmd_population,
        cmd_reproduce,
        cmd_stream,
    )

    parser = _Parser(
        prog="ddmm",
        description="Population-coding simulator of tactile afferents (DDMM).",
    )
    parser.add_argument("--version", action="version", version=f"ddmm {__version__}")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND",
                                parser_class=_Parser)
    for module in (cmd_reproduce, cmd_population, cmd_biology, cmd_physiology, cmd_accuracy, cmd_stream, cmd_export,
                   bench):
        module.register(sub)
    return parser


def main(argv=None) -> int:
    """Entry point of the ``ddmm`` console script."""
    from ddmm.population._extras import MissingExtraError

    args = build_parser().parse_args(argv)
    try:
        return int(args.func(args) or 0)
    except (ValueError, TypeError, MissingExtraError) as exc:  # a missing extra says which to install
        print(f"ddmm: error: {exc}", file=sys.stderr)
        return 2
    except OSError as exc:
        print(f"ddmm: error: {exc.strerror or exc}: {exc.filename or ''}".rstrip(": "), file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("ddmm: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
