"""The ``ddmm`` command line: one module per command, named after it.

Each command module defines ``register(sub)``, which adds its parser to the
``ddmm`` subcommands and sets the function that runs it.  A new command is a
new module here and one entry in `COMMANDS` (the order ``ddmm --help`` lists
them in).  Options that several commands share live in `options` (engines,
runs, scenes, output files) and `recording_options` (recorded forces); the
parser, the dispatch and the one-line errors in `app`.
"""

from ddmm.experiments.cli.app import build_parser, main

__all__ = ["COMMANDS", "build_parser", "main"]

#: The commands, in the order ``ddmm --help`` lists them; each is the module ``ddmm.experiments.cli.<name>``.
COMMANDS = ("reproduce", "simulate", "plan", "info", "plot", "demo", "tuning", "calibrate", "decode", "physiology",
            "accuracy", "stream", "play", "stimulate", "export", "bench")
