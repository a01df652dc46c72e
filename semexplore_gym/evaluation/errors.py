"""An error about one value the caller passed, worded so that a front end can rename it.

Library code names the value by its Python parameter (``runs must be >= 1, got 0``); the
command line catches :class:`ParameterError` and puts its own flag in its place
(``--runs must be >= 1, got 0``), so each layer speaks of what its user typed.
"""

from __future__ import annotations

from collections.abc import Mapping

#: Placeholder for the parameter's name in a :class:`ParameterError` message.
PARAM = "{param}"


class ParameterError(ValueError):
    """A bad value of the parameter ``param``.

    Args:
        param: The parameter's Python name (``runs``, ``out_dir``, ``algo``).
        template: The message, with :data:`PARAM` where the parameter is named.
    """

    def __init__(self, param: str, template: str) -> None:
        self.param = param
        self.template = template
        super().__init__(self.named(param))

    def named(self, name: str) -> str:
        """The message with the parameter called ``name`` (a flag, say)."""
        return self.template.replace(PARAM, name)

    def for_flags(self, flags: Mapping[str, str]) -> ValueError:
        """A plain ValueError naming the flag ``flags[param]`` (the parameter if unmapped)."""
        return ValueError(self.named(flags.get(self.param, self.param)))
