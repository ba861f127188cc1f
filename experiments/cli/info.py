"""``ddmm info``: a summary of a dataset file."""

from __future__ import annotations

__all__ = ["register", "run_info"]


def register(sub) -> None:
    """Add ``ddmm info``."""
    p = sub.add_parser("info", help="summarise a dataset file")
    p.add_argument("file")
    p.set_defaults(func=run_info)


def run_info(args) -> int:
    from ddmm.population import describe_dataset, load_dataset
    print(describe_dataset(load_dataset(args.file)))
    return 0
