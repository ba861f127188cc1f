"""Renamed keywords: the old name keeps working for one release, with a `DeprecationWarning`."""

from __future__ import annotations

import functools
import warnings

__all__ = ["renamed_keyword", "warn_renamed"]


def warn_renamed(old: str, new: str, stacklevel: int = 3) -> None:
    """Warn that ``old`` (a name as its user wrote it) is now ``new``, with one message for every rename.

    ``stacklevel`` 3 points at the caller of the function that warns.

    Examples
    --------
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     warn_renamed("f(types=)", "afferent_types=")
    >>> str(caught[0].message)
    'f(types=) is deprecated and will be removed in the next release; use afferent_types='
    """
    warnings.warn(f"{old} is deprecated and will be removed in the next release; use {new}", DeprecationWarning,
                  stacklevel=stacklevel)


def renamed_keyword(old: str, new: str):
    """Decorate a function whose keyword ``old`` is now ``new``: ``old=`` still works, with a warning.

    Giving both is a `TypeError` naming them.

    Examples
    --------
    >>> @renamed_keyword("types", "afferent_types")
    ... def count(*, afferent_types=()):
    ...     return len(afferent_types)
    >>> import warnings
    >>> with warnings.catch_warnings(record=True) as caught:
    ...     warnings.simplefilter("always")
    ...     count(types=("SAI", "RAI")), caught[0].category.__name__
    (2, 'DeprecationWarning')
    """
    def decorate(func):
        @functools.wraps(func)
        def wrapper(*args, **kwargs):
            if old in kwargs:
                if new in kwargs:
                    raise TypeError(f"{func.__qualname__}() got {old}= (deprecated) and {new}=: give {new}= only")
                warn_renamed(f"{func.__qualname__}({old}=)", f"{new}=")
                kwargs[new] = kwargs.pop(old)
            return func(*args, **kwargs)
        return wrapper
    return decorate
