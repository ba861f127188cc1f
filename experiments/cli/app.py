"""The ``ddmm`` application: the parser with every command registered, and one-line errors (exit status 2)."""

from __future__ import annotations

import argparse
import difflib
import functools
import os
import re
import sys
import warnings

__all__ = ["build_parser", "main"]


def _did_you_mean(word: str, candidates) -> str:
    match = difflib.get_close_matches(word, list(candidates), n=1, cutoff=0.6)
    return f" (did you mean {match[0]}?)" if match else ""


class _Parser(argparse.ArgumentParser):
    """An ArgumentParser whose usage errors are one line and exit status 2, with a "did you mean" for typos."""

    def parse_args(self, args=None, namespace=None):
        args, extras = self.parse_known_args(args, namespace)
        if extras:
            parser = self._subcommand(args)
            options = [o for action in parser._actions for o in action.option_strings]
            unknown = next((e for e in extras if e.startswith("-")), "")
            hint = _did_you_mean(unknown.split("=")[0], options) if unknown else ""
            parser.error(f"unrecognized arguments: {' '.join(extras)}{hint}")
        return args

    def _subcommand(self, args) -> argparse.ArgumentParser:
        """The parser of the subcommand ``args`` names (self if none)."""
        for action in self._actions:
            if isinstance(action, argparse._SubParsersAction) and getattr(args, action.dest, None) in action.choices:
                return action.choices[getattr(args, action.dest)]
        return self

    def error(self, message):
        choice = re.search(r"invalid choice: '([^']*)' \(choose from (.*)\)", message)
        if choice:  # a mistyped subcommand or option value
            message += _did_you_mean(choice.group(1), re.findall(r"'([^']*)'", choice.group(2)))
        self.exit(2, f"ddmm: error: {message} (see '{self.prog} --help')\n")


def build_parser() -> argparse.ArgumentParser:
    """The argument parser with every subcommand registered."""
    from importlib import import_module

    from ddmm import __version__
    from ddmm.experiments.cli import COMMANDS

    parser = _Parser(
        prog="ddmm",
        description="Population-coding simulator of tactile afferents (DDMM).",
    )
    parser.add_argument("--version", action="version", version=f"ddmm {__version__}")
    parser.add_argument("--debug", action="store_true",
                        help="show the full traceback of an unexpected error (also DDMM_DEBUG=1)")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND",
                                parser_class=_Parser)
    for command in COMMANDS:
        import_module(f"ddmm.experiments.cli.{command}").register(sub)
    return parser


def main(argv=None) -> int:
    """Entry point of the ``ddmm`` console script."""
    args = build_parser().parse_args(argv)
    debug = args.debug or os.environ.get("DDMM_DEBUG", "") not in ("", "0")
    try:
        with warnings.catch_warnings():
            # The package's own warnings, once per place; another library's (pyparsing's deprecations inside
            # Brian2, say) are not the user's to act on: only --debug shows them.
            warnings.simplefilter("default" if debug else "ignore")
            warnings.filterwarnings("default", module=r"(ddmm|__main__)(\.|$)")
            warnings.showwarning = functools.partial(_show_warning, getattr(args, "types", None))
            return int(args.func(args) or 0)
    except KeyboardInterrupt:
        print("ddmm: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # the reader went away (``ddmm ... | head``): stop quietly, as shell tools do
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 141
    except Exception as exc:  # noqa: BLE001 - the CLI never shows a traceback unless asked
        if debug:
            raise
        print(f"ddmm: error: {_one_line(exc)}", file=sys.stderr)
        return 2


def _show_warning(types, message, category, filename, lineno, file=None, line=None) -> None:
    """A warning as one ``ddmm: warning: ...`` line naming options, none once ``--types`` left out what it
    concerns (never Python's ``file:line: Category: ...`` and a line of source)."""
    from ddmm.utils.notices import cli_text, only_for_types

    concerns = only_for_types(message)
    if concerns and types is not None:
        from ddmm.models.afferent_types import normalize_type

        chosen = {normalize_type(t.strip(), "--types") for t in types.split(",") if t.strip()}
        if not chosen & set(concerns):
            return
    print(f"ddmm: warning: {cli_text(message)}", file=sys.stderr)


def _one_line(exc: BaseException) -> str:
    """The message of an error, on one line; an unexpected kind says so and how to see the traceback."""
    from ddmm.utils.extras import MissingExtraError

    if isinstance(exc, (ValueError, TypeError, MissingExtraError)):  # a missing extra says which to install
        text = str(exc)
    elif isinstance(exc, OSError):
        text = f"{exc.strerror or exc}: {exc.filename or ''}".rstrip(": ")
    else:
        text = (f"unexpected {type(exc).__name__}: {exc} (a bug or a broken environment; rerun as "
                f"'ddmm --debug ...' for the traceback)")
    return " ".join(text.split())


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
