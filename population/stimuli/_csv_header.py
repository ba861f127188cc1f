"""A recording's header: column names matched with their units, and the ``--columns`` line that fixes a miss."""

from __future__ import annotations

import difflib
import re
import shlex

__all__ = ["split_unit", "match_columns"]

_UNIT = re.compile(r"^(?P<name>.*?)\s*[(\[]\s*(?P<unit>[^)\]]*?)\s*[)\]]\s*$")
#: Other spellings of our column names, tried after the exact name.
_ALIASES = {"time": ("t", "timestamp", "times", "time_s", "t_s"),
            "fx": ("force_x", "forcex", "f_x", "x"), "fy": ("force_y", "forcey", "f_y", "y"),
            "fz": ("force_z", "forcez", "f_z", "z")}


def split_unit(cell: str) -> tuple:
    """``(name, unit or None)`` of a header cell: ``"Fx (mN)"`` and ``"Fx [mN]"`` give ``("Fx", "mN")``.

    Examples
    --------
    >>> split_unit("Time (s)"), split_unit("Fz [N]"), split_unit("fz")
    (('Time', 's'), ('Fz', 'N'), ('fz', None))
    """
    found = _UNIT.match(cell.strip())
    if found and found["name"] and found["unit"]:
        return found["name"].strip(), found["unit"]
    return cell.strip(), None


def match_columns(path, header, wanted: dict) -> dict:
    """Our name -> index into ``header``: each wanted name matched case-insensitively, with or without its unit.

    Raises ValueError for a name that no column carries, with the ``columns=`` mapping (and the
    ``--columns`` line) that reads the file, guessed from the header.
    """
    full = [h.strip().lower() for h in header]
    bare = [split_unit(h)[0].lower() for h in header]
    index, missing = {}, []
    for ours, theirs in wanted.items():
        key = theirs.strip().lower()
        hit = full.index(key) if key in full else (bare.index(key) if key in bare else None)
        if hit is None:
            missing.append(ours)
        else:
            index[ours] = hit
    if missing:
        raise ValueError(_missing_message(path, header, wanted, index, missing))
    return index


def _missing_message(path, header, wanted, index, missing) -> str:
    guess = _guess(header, index, missing)
    names = ", ".join(f"{wanted[m]!r} (for {m})" for m in missing)
    text = (f"scene file {str(path)!r} has no column {names}, matched case-insensitively with or without a unit; "
            f"header: {','.join(header)}")
    if len(guess) == len(missing):
        pairs = ",".join(f"{k}={v}" for k, v in guess.items())
        text += f"; read it with columns={guess!r} ({shlex.join(['--columns', pairs])})"
    return text


def _guess(header, index, missing) -> dict:
    """A column for each missing name: an alias, then the closest name, then (as many columns as names) the
    column in its place."""
    free = [i for i in range(len(header)) if i not in index.values()]
    guess = {}
    for ours in missing:
        bare = {split_unit(header[i])[0].lower(): i for i in free}
        hit = next((bare[a] for a in _ALIASES.get(ours, ()) if a in bare), None)
        if hit is None:
            close = difflib.get_close_matches(ours, list(bare), n=1, cutoff=0.6)
            hit = bare[close[0]] if close else None
        if hit is None and len(header) == len(index) + len(missing):
            hit = free[0] if free else None
        if hit is not None:
            guess[ours] = header[hit].strip()
            free.remove(hit)
    return guess
