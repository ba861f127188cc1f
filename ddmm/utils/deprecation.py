"""Renamed keywords: the old name keeps working for one release, with a `DeprecationWarning`."""

from __future__ import annotations

import functools
import warnings

__all__ = ["renamed_keyword"]


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
                warnings.warn(f"{func.__qualname__}(): the keyword {old}= is deprecated and will be removed in the "
                              f"next release; use {new}=", DeprecationWarning, stacklevel=2)
                kwargs[new] = kwargs.pop(old)
            return func(*args, **kwargs)
        return wrapper
    return decorate
