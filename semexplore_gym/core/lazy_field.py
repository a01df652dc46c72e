"""A dataclass field whose value may be stored as a recipe and built when first read."""

from __future__ import annotations

from collections.abc import Callable
from typing import Any


class LazyField:
    """Data descriptor of a dataclass field: stores a value or a ``recipe_type`` instance, and
    returns the value, building a stored recipe with ``build(recipe)`` on first read (the result
    replaces it). The value lives in the instance's ``__dict__`` under ``_NAME``.

    Used where most results are never read: a replan scores tens of frontier paths and drives
    along one; most topometric maps are never rastered in full.
    """

    def __init__(self, recipe_type: type, build: Callable[[Any], Any]) -> None:
        self._recipe_type = recipe_type
        self._build = build
        self._name = ""
        self._slot = ""

    def __set_name__(self, owner: type, name: str) -> None:
        self._name = name
        self._slot = f"_{name}"

    def __get__(self, obj: Any, objtype: Any = None) -> Any:
        if obj is None:
            raise AttributeError(self._name)  # no default value for the dataclass field
        v = obj.__dict__[self._slot]
        if isinstance(v, self._recipe_type):
            v = self._build(v)
            obj.__dict__[self._slot] = v
        return v

    def __set__(self, obj: Any, value: Any) -> None:
        obj.__dict__[self._slot] = value
