"""Benchmarks behind ``ddmm bench``: each case runs in a fresh process and prints numbers, never a verdict.

- `cases`: the cases by name (``python -m ddmm.experiments.bench.cases --case NAME`` runs one);
- `runner`: runs the cases, each in its own process, and formats the table;
- `lsl`: the latency cases over Lab Streaming Layer.
"""

from ddmm.utils.lazy import lazy_exports

_WHERE = {
    "cases": ("CASES", "EXTRA_CASES", "LSL_CASES", "SCALING", "run_case"),
    "runner": ("format_table", "run_bench"),
    "lsl": ("run_lsl_case",),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _WHERE)
