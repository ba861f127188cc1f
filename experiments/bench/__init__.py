"""Benchmarks behind ``ddmm bench``: each case runs in a fresh process and prints numbers; the event cases
also mark each latency within or over the bound of docs/recordings.md ("Latency from the touch").

- `cases`: the cases by name (``python -m ddmm.experiments.bench.cases --case NAME`` runs one);
- `runner`: runs the cases, each in its own process, and formats the table;
- `lsl`: the latency cases over Lab Streaming Layer;
- `events`: latency from the event (contact, release, shear step), with conditioning and without, and over LSL.
"""

from ddmm.utils.lazy import lazy_exports

_WHERE = {
    "cases": ("CASES", "EVENT_CASES", "EXTRA_CASES", "GROUPS", "LSL_CASES", "SCALING", "run_case"),
    "runner": ("format_table", "run_bench"),
    "lsl": ("run_lsl_case",),
    "events": ("event_case", "format_event_case", "run_event_case"),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _WHERE)
