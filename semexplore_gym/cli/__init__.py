"""The ``semexplore`` command: one entry point, one module per subcommand.

Each subcommand module defines ``add_parser(subparsers)`` (registering its parser with
``set_defaults(func=run)``-style dispatch handled here) and ``run(args) -> int``.
"""

from __future__ import annotations

import argparse
import importlib
import os
import re
import sys
from collections.abc import Sequence

from semexplore_gym.config.extras import MissingExtraError

#: Subcommand name -> module under ``semexplore_gym.cli``.
SUBCOMMANDS: dict[str, str] = {
    "show-world": "show_world",
    "segment": "segment",
    "explore": "explore",
    "benchmark": "benchmark",
    "train": "train",
    "compare-weights": "compare_weights",
    "maps": "maps",
    "pretrained": "pretrained",
    "oracle": "oracle",
    "report": "report",
}


def describe(doc: str | None) -> str:
    """A subcommand's ``--help`` description from its module docstring: reST markup made plain
    (no double backticks, ``Example::`` as ``Example:``), paragraphs and indentation kept (use
    with ``argparse.RawDescriptionHelpFormatter``)."""
    text = (doc or "").strip()
    text = re.sub(r"``(.+?)``", r"\1", text, flags=re.DOTALL)
    text = re.sub(r":(?:func|class|meth|mod|data):`~?([^`]+)`", r"\1", text)
    return text.replace("::\n", ":\n")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="semexplore",
        description="SemanticExplore: semantic topometric exploration with a simulated TurtleBot3.",
    )
    from semexplore_gym import __version__

    parser.add_argument("--version", action="version", version=f"semexplore {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for module_name in SUBCOMMANDS.values():
        try:
            module = importlib.import_module(f"semexplore_gym.cli.{module_name}")
        except ModuleNotFoundError as e:
            if e.name == f"semexplore_gym.cli.{module_name}":
                continue  # subcommand not part of this build
            raise
        p = module.add_parser(sub)
        # _prog names the command in error lines; a subcommand's own sub-parsers (maps get)
        # set theirs the same way, and theirs win.
        p.set_defaults(_run=module.run, _prog=p.prog)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; returns the process exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if not getattr(args, "_run", None):
        parser.print_help()
        return 2
    from semexplore_gym.cli._output import json_stdout

    try:
        with json_stdout(args):
            return int(args._run(args) or 0)
    except BrokenPipeError:
        # The reader went away (``semexplore segment ... --json | head``): stop quietly; point
        # stdout at /dev/null so the interpreter's final flush does not raise again.
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
        return 0
    except ImportError as e:
        if not isinstance(e, MissingExtraError) and "pip install" not in str(e):
            raise
        # An optional extra is not installed: its name and the pip line, no traceback.
        print(f"{error_prefix(args)} {e}", file=sys.stderr)
        return 2
    except (ValueError, OSError, KeyError, RecursionError, MemoryError) as e:
        # Bad input ends here as one short line; never a traceback or a flood of output.
        from semexplore_gym.core.validation import one_line

        text = one_line(str(e), 600) or type(e).__name__
        if isinstance(e, (RecursionError, MemoryError)):
            text = f"{type(e).__name__}: input too large or too deeply nested ({text})"
        print(f"{error_prefix(args)} {text}", file=sys.stderr)
        return 2


def error_prefix(args: argparse.Namespace) -> str:
    """``semexplore maps get: error:``: the one style of every error line of the command."""
    return f"{getattr(args, '_prog', None) or f'semexplore {args.command}'}: error:"


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
