"""The one output rule of every ``semexplore`` command.

Progress bars, tables and other human text go to stderr, or to stdout when ``--json`` is off.
With ``--json`` a command writes exactly one JSON document to stdout and nothing else:
:func:`~semexplore_gym.cli.main` sends everything else written to stdout meanwhile (SB3's
progress bar, a library's chatter, a log line) to stderr, and the command prints its result
through :func:`print_json`, which writes to the real stdout.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import sys
from collections.abc import Iterator
from typing import Any, TextIO

#: Where :func:`print_json` writes while :func:`json_stdout` holds stdout for the result.
_RESULT_STREAM = "_json_stdout"


def add_json_flag(parser: argparse.ArgumentParser, what: str) -> None:
    """``--json``: print ``what`` as one JSON object on stdout, and nothing else there."""
    parser.add_argument(
        "--json",
        action="store_true",
        help=f"print {what} as one JSON object on stdout (progress and messages on stderr)",
    )


@contextlib.contextmanager
def json_stdout(args: argparse.Namespace) -> Iterator[None]:
    """While the command runs with ``--json``, stdout is stderr except for :func:`print_json`."""
    if not getattr(args, "json", False):
        yield
        return
    setattr(args, _RESULT_STREAM, sys.stdout)
    try:
        with contextlib.redirect_stdout(sys.stderr):
            yield
    finally:
        delattr(args, _RESULT_STREAM)


def print_json(args: argparse.Namespace, result: Any, **dumps_kwargs: Any) -> None:
    """The command's result as one JSON document on the real stdout."""
    stream: TextIO = getattr(args, _RESULT_STREAM, None) or sys.stdout
    print(json.dumps(result, **dumps_kwargs), file=stream, flush=True)


def print_result(args: argparse.Namespace, result: dict[str, Any], text: str = "") -> None:
    """A command's result: with ``--json`` one JSON object; without, ``key  value`` lines
    followed by ``text`` (a table, a summary) for a person to read."""
    if getattr(args, "json", False):
        print_json(args, result, default=float)
        return
    width = max(map(len, result), default=0)
    for key, value in result.items():
        shown = ", ".join(map(str, value)) if isinstance(value, list | tuple) else value
        print(f"{key:<{width}}  {shown}")
    if text:
        print(f"\n{text}")
