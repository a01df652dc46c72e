"""How ``SemanticExplore-v0`` hands out its observation and ``info``: one typed options object.

None of these options change what the env simulates; they trade copies for speed (see the
env's docstring, *Arguments* and *Speed*).
"""

from __future__ import annotations

import difflib
import inspect
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

#: ``map_observation`` options: a fresh copy of the whole map, a fresh window around the robot,
#: or a read-only live view of the env's map.
MAP_OBSERVATIONS = ("copy", "window", "shared")
#: ``static_info`` options: the static ``info`` entries in every step's ``info``, or at reset only.
STATIC_INFO_MODES = ("every_step", "reset")


@dataclass(frozen=True)
class ObservationOptions:
    """The env's speed options (defaults: the canonical observation and ``info``).

    Attributes:
        map_observation: ``"copy"`` (a fresh copy of the whole map each step), ``"window"``
            (a fresh ``map_window_cells`` square around the robot, plus
            ``obs["map_offset_cells"]``) or ``"shared"`` (a read-only live view of the env's
            map).
        static_info: ``"every_step"`` (the static entries in every ``info``) or ``"reset"``
            (only in the ``info`` of ``reset``).
        map_window_cells: Side of the ``"window"`` map in cells (8 to 4096).

    Raises:
        ValueError: a value outside the choices above.
    """

    map_observation: str = "copy"
    static_info: str = "every_step"
    map_window_cells: int = 160

    def __post_init__(self) -> None:
        if self.map_observation not in MAP_OBSERVATIONS:
            raise ValueError(
                f"map_observation must be one of {MAP_OBSERVATIONS}, got {self.map_observation!r}"
            )
        if self.static_info not in STATIC_INFO_MODES:
            raise ValueError(
                f"static_info must be one of {STATIC_INFO_MODES}, got {self.static_info!r}"
            )
        cells: Any = self.map_window_cells
        if isinstance(cells, bool) or not isinstance(cells, int | np.integer):
            raise ValueError(f"map_window_cells must be an integer, got {cells!r}")
        if not 8 <= cells <= 4096:
            raise ValueError(f"map_window_cells must be in [8, 4096], got {cells!r}")
        object.__setattr__(self, "map_window_cells", int(cells))

    @classmethod
    def from_flags(
        cls,
        base: ObservationOptions | None,
        flags: Mapping[str, Any],
        constructor: Callable[..., Any] | None = None,
    ) -> ObservationOptions:
        """``base`` (or the defaults) with the fields named in ``flags`` replaced: the
        ``gym.make("SemanticExplore-v0", map_observation=...)`` spelling.

        Args:
            base: The options to start from (None: the defaults).
            flags: Option fields by name: the env's keyword arguments that it does not name.
            constructor: The env's ``__init__``, whose named parameters the error lists.

        Raises:
            TypeError: a name that is neither a field nor a keyword of ``constructor``; the
                message names it, a close match, and every valid keyword.
        """
        from dataclasses import fields, replace

        options = [f.name for f in fields(cls)]
        unknown = [name for name in flags if name not in options]
        if unknown:
            named = inspect.signature(constructor).parameters.values() if constructor else ()
            valid = [
                p.name
                for p in named
                if p.name != "self" and p.kind not in (p.VAR_KEYWORD, p.VAR_POSITIONAL)
            ] + options
            close = difflib.get_close_matches(unknown[0], valid, n=1)
            guess = f" (did you mean {close[0]!r}?)" if close else ""
            raise TypeError(
                f"unexpected keyword argument {unknown[0]!r}{guess}; the keywords are "
                f"{', '.join(valid)}"
            )
        return replace(base or cls(), **flags) if flags else (base or cls())
