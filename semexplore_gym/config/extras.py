"""Optional extras: the one error a missing one raises.

The core install runs the expert, the baselines and the env. Trained SB3 models, weight tuning
(``rl``), the multi-robot env (``multi``) and the Ray backend (``ray``) need an extra; the code
that imports one calls :func:`require_extra` first, so a missing extra is one
:class:`MissingExtraError` naming it and its ``pip install`` line (the CLI prints it as one
``error:`` line and exits 2).
"""

from __future__ import annotations

import importlib


class MissingExtraError(ImportError):
    """An optional extra is not installed; the message names it and the pip command.

    Attributes:
        extra: The extra's name (``rl``, ``multi``, ``ray`` ...).
    """

    def __init__(self, what: str, extra: str, missing: str = "") -> None:
        self.extra = extra
        detail = f" (no module named {missing!r})" if missing else ""
        super().__init__(
            f"{what} needs the {extra!r} extra{detail}: pip install 'semexplore-gym[{extra}]'",
            name=missing or None,
        )


def require_extra(extra: str, what: str, *modules: str) -> None:
    """Import ``modules`` (top-level names such as ``"torch"``), or raise
    :class:`MissingExtraError` saying that ``what`` needs ``extra``.

    Only a missing module is reported this way; a module that is there but fails on import
    raises its own error.
    """
    for module in modules:
        try:
            importlib.import_module(module)
        except ModuleNotFoundError as e:
            # A missing dependency of the module (torch's own) counts as the extra missing too.
            raise MissingExtraError(what, extra, e.name or module) from e
