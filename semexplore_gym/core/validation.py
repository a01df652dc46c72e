"""Checks of parameter values, and the bounded reprs their error messages quote.

:func:`require_finite` is the ``__post_init__`` check of the frozen parameter sets;
:func:`short_repr` and :func:`one_line` keep any value or text quoted in an error message short,
so a huge or deeply nested input never floods stderr.
"""

from __future__ import annotations

import math
import reprlib
from collections.abc import Iterable
from typing import Any

_REPR = reprlib.Repr()
_REPR.maxlevel = 3
_REPR.maxlist = _REPR.maxtuple = _REPR.maxset = _REPR.maxdict = 6
_REPR.maxstring = 80
_REPR.maxother = 80
_REPR.maxlong = 40


def short_repr(value: Any, limit: int = 80) -> str:
    """``repr(value)`` cut to at most ``limit`` characters (``...`` marks the cut).

    Cheap on huge or deeply nested values: only the first few items of each container are
    looked at, so printing an alias-expanded document costs no more than printing a small one.
    """
    try:
        text = _REPR.repr(value)
    except Exception:  # noqa: BLE001 - a broken __repr__ must not hide the real error
        text = f"<{type(value).__name__}>"
    if len(text) > limit:
        text = text[: max(0, limit - 3)] + "..."
    return text


def one_line(text: str, limit: int = 200) -> str:
    """``text`` on one line (whitespace runs collapsed), cut to ``limit`` characters."""
    flat = " ".join(str(text).split())
    return flat if len(flat) <= limit else flat[: max(0, limit - 3)] + "..."


def require_finite(obj: Any, names: Iterable[str], *, positive: bool, prefix: str = "") -> None:
    """Raise a ValueError naming the first of ``obj``'s fields ``names`` that is not a finite
    number ``> 0`` (``positive``) or ``>= 0``: the ``__post_init__`` check of parameter sets."""
    for name in names:
        v = getattr(obj, name)
        if (
            isinstance(v, bool)
            or not isinstance(v, (int, float))
            or not (math.isfinite(v) and (v > 0.0 if positive else v >= 0.0))
        ):
            what = "a positive finite number" if positive else "a finite number >= 0"
            raise ValueError(f"{prefix}{name} must be {what}, got {short_repr(v)}")
