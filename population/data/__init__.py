"""Reference data the library ships: published numbers with their sources, and measured tables.

- `published`: every published number ddmm compares with (the paper's tables, human
  recordings, TouchSim), each with its source; the physiology scorecard's reference ranges;
- ``accuracy_table.json``: the measured accuracy of each step and method, which
  ``simulate(tolerance=...)`` reads (written by ``ddmm accuracy --write-table``).
"""

from ddmm.utils.lazy import lazy_exports

_WHERE = {
    "published": ("HUMAN_DIRECTION_THRESHOLD_DEG", "HUMAN_DSI", "HUMAN_TUNED_FRACTION", "PAPER_TABLE2",
                  "PAPER_TABLE3", "PAPER_TABLE4", "PHYSIOLOGY_REFERENCE"),
}
__all__, __getattr__, __dir__ = lazy_exports(__name__, _WHERE)
