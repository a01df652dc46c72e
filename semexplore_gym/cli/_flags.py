"""Flag vocabulary shared by the subcommands.

Every config flag names what it configures: ``--env-config``/``--env-set`` (the env config),
``--policy-config``/``--policy-set`` (policy parameters), ``--train-config``/``--train-set``
(a training run). The bare ``--config``/``--set`` used to mean a different thing in each
command; they are kept as hidden flags that stop with a message naming the new spelling.
"""

from __future__ import annotations

import argparse
from collections.abc import Sequence
from typing import Any


class _RenamedFlag(argparse.Action):
    """An argparse action that fails (exit code 2, usage on stderr) naming the new flag."""

    def __init__(self, option_strings: Sequence[str], dest: str, *, hint: str, **kwargs: Any):
        super().__init__(option_strings, dest, nargs="?", help=argparse.SUPPRESS, **kwargs)
        self.hint = hint

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: Any,
        option_string: str | None = None,
    ) -> None:
        parser.error(f"{option_string} was renamed: {self.hint}")


def add_renamed_flag(parser: argparse.ArgumentParser, old: str, hint: str) -> None:
    """Register ``old`` as a removed flag whose use exits with ``"OLD was renamed: HINT"``."""
    parser.add_argument(old, dest=f"_renamed_{old.lstrip('-')}", action=_RenamedFlag, hint=hint)


def check_output_flag(
    flag: str, path: str, suffixes: tuple[str, ...] = (), *, parent_must_exist: bool = True
) -> None:
    """:func:`~semexplore_gym.config.output_paths.check_output_file`, its error naming ``flag``.

    Raises:
        ValueError: ``"--gif 'x.txt' must end in .gif"``: the flag, then what is wrong.
    """
    from semexplore_gym.config.output_paths import check_output_file

    try:
        check_output_file(path, suffixes, parent_must_exist=parent_must_exist)
    except ValueError as e:
        raise ValueError(f"{flag} {e}") from None
