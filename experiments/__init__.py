"""What is run on the library: the ``ddmm`` command line, the paper's reproduction, fits, validation,
benchmarks and figures.  Nothing in `ddmm.models` or `ddmm.population` imports from here.

- `cli`: the ``ddmm`` command line, one module per command;
- `paper`: the paper's Tables II-IV and Figs 6-8, cell by cell;
- `calibration`: the fits of the presets and of the paper calibration;
- `validation`: the protocols behind the claims the scorecard does not hold (accuracy, decoding, recordings);
- `bench`: speed and memory, each case in a fresh process;
- `plots`: figures from data (they return figures; the CLI saves them);
- `io`: the CLI's atomic output files;
- `docs_reference`: generates ``docs/cli.md``, ``docs/api.md`` and the module map of ``docs/development.md``.
"""
