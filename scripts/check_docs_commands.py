"""Check the docs' long reproduce commands without running them.

A ```bash block with a ``<!-- long -->`` line right above its fence holds commands that
produced a published figure or table and take too long for the docs test to run (hours on two
cores). Each command must be the project's own (``semexplore ...`` or ``python scripts/NAME.py
...``, after ``VAR=value`` prefixes), its arguments must parse with that command's own argument
parser, and the values that name things must resolve as the command would resolve them before
starting any mission: policy specs (registry, versions, parameter overrides), world specs,
suite and split names, env / train / policy config files. Nothing is run: no mission, no
training, no model loaded.

A block may set a shell variable from a short Python expression on a line of its own,
``NAME=$(python -c 'CODE')``, and use it later as ``"$NAME"`` (a long list of worlds); the
checker runs that one line. Comment lines (``# about 2 h on 2 cores``) are allowed anywhere.

Usage::

    python scripts/check_docs_commands.py                 # README.md and docs/*.md
    python scripts/check_docs_commands.py docs/results.md
"""

from __future__ import annotations

import argparse
import contextlib
import io
import os
import re
import runpy
import shlex
import subprocess
import sys
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

REPO = Path(__file__).resolve().parents[1]
#: The line right above a long block's fence.
LONG_MARK = "<!-- long -->"
LONG_FENCE = re.compile(
    r"^<!-- long -->\n```(?P<info>[^\n]*)\n(?P<body>.*?)^```[ \t]*$", re.S | re.M
)
ASSIGN = re.compile(r"([A-Z_][A-Z0-9_]*)=\$\(python -c '([^']*)'\)")
ENV_PREFIX = re.compile(r"[A-Z_][A-Z0-9_]*=\S*")
SCRIPT = re.compile(r"scripts/[\w-]+\.py")
#: Output folders of the docs' earlier commands: a model a reader trains first lives there.
READER_OUTPUTS = ("runs/",)


class CommandError(ValueError):
    """A documented command that would not start; the message says why."""


# ------------------------------------------------------------------------------- blocks
def long_blocks(markdown: str) -> list[tuple[int, str, str]]:
    """``(line of the body's first line, info string, body)`` of every long block."""
    return [
        (markdown.count("\n", 0, m.start("body")) + 1, m.group("info").strip(), m.group("body"))
        for m in LONG_FENCE.finditer(markdown)
    ]


def _logical_lines(body: str, first_line: int) -> Iterator[tuple[int, str]]:
    """Continuation lines joined, each with the page line it starts on."""
    start, parts = first_line, list[str]()
    for i, line in enumerate(body.splitlines(), first_line):
        if not parts:
            start = i
        if line.rstrip().endswith("\\"):
            parts.append(line.rstrip()[:-1])
            continue
        parts.append(line)
        yield start, " ".join(parts)
        parts = []
    if parts:
        yield start, " ".join(parts)


def _expand(line: str, variables: dict[str, str]) -> str:
    for name, value in variables.items():
        line = line.replace(f"${{{name}}}", value).replace(f"${name}", value)
    return line


def _evaluate(code: str) -> str:
    """The output of one ``python -c`` line of a block (a list the command reads)."""
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join([str(REPO), os.environ.get("PYTHONPATH", "")]),
    }
    proc = subprocess.run(
        [sys.executable, "-c", code], cwd=REPO, env=env, capture_output=True, text=True, timeout=60
    )
    if proc.returncode != 0:
        raise CommandError(f"python -c failed: {proc.stderr.strip().splitlines()[-1:]}")
    return proc.stdout.strip()


def block_commands(body: str, first_line: int) -> list[tuple[int, list[str]]]:
    """The commands of a long block as ``(page line, argv)``: comments dropped, ``VAR=$(python
    -c '...')`` lines evaluated into ``$VAR``, ``VAR=value`` prefixes removed.

    Raises:
        CommandError: a line that is not a command shlex can split (the message names it).
    """
    variables: dict[str, str] = {}
    out: list[tuple[int, list[str]]] = []
    for line_no, line in _logical_lines(body, first_line):
        assign = ASSIGN.fullmatch(line.strip())
        if assign:
            variables[assign.group(1)] = _evaluate(assign.group(2))
            continue
        try:
            tokens = shlex.split(_expand(line, variables), comments=True)
        except ValueError as e:
            raise CommandError(f"line {line_no}: {e}") from None
        while tokens and ENV_PREFIX.fullmatch(tokens[0]):
            tokens = tokens[1:]
        if tokens:
            out.append((line_no, tokens))
    return out


# --------------------------------------------------------------------------------- parsing
class _Parsed(BaseException):
    """Raised by the patched ``parse_args`` to leave a script's ``main`` before its work."""

    def __init__(self, namespace: argparse.Namespace) -> None:
        super().__init__()
        self.namespace = namespace


@contextlib.contextmanager
def _argparse_errors(what: str) -> Iterator[None]:
    """An argparse failure (usage error, exit 2) as a CommandError with argparse's message."""
    err = io.StringIO()
    try:
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            yield
    except SystemExit as e:
        lines = [ln for ln in err.getvalue().splitlines() if ln.strip()]
        last = lines[-1] if lines else f"exit code {e.code}"
        raise CommandError(last if "error:" in last else f"{what}: {last}") from None


def parse_script(argv: list[str]) -> tuple[argparse.Namespace, dict[str, Any]]:
    """A ``python scripts/NAME.py ...`` command's arguments, parsed by the script's own parser.

    The script's ``main`` runs until its parser returns (argparse's own checks, and a script's
    ``parse_args(argv)`` function when it has one, which holds its further checks), then stops.

    Returns:
        The parsed namespace and the script's module globals.
    """
    script = REPO / argv[1]
    if not SCRIPT.fullmatch(argv[1]) or not script.is_file():
        raise CommandError(f"no such script {argv[1]!r}")
    module = runpy.run_path(str(script), run_name="docs_check")
    saved_argv, sys.argv = sys.argv, argv[1:]  # argparse names the script in its errors
    try:
        return _parse_with(module, argv)
    finally:
        sys.argv = saved_argv


def _parse_with(module: dict[str, Any], argv: list[str]) -> tuple[argparse.Namespace, dict]:
    with _argparse_errors(argv[1]):
        if callable(module.get("parse_args")):
            return module["parse_args"](argv[2:]), module
        original = argparse.ArgumentParser.parse_args

        def stop_after_parsing(self: argparse.ArgumentParser, *a: Any, **k: Any) -> Any:
            raise _Parsed(original(self, *a, **k))

        argparse.ArgumentParser.parse_args = stop_after_parsing  # type: ignore[assignment]
        try:
            module["main"](argv[2:])
        except _Parsed as parsed:
            return parsed.namespace, module
        finally:
            argparse.ArgumentParser.parse_args = original  # type: ignore[method-assign]
    raise CommandError(f"{argv[1]}: main() returned without parsing its arguments")


def parse_semexplore(argv: list[str]) -> argparse.Namespace:
    """A ``semexplore ...`` command's arguments, parsed by the CLI's own parser."""
    from semexplore_gym.cli import build_parser

    with _argparse_errors(shlex.join(argv[:2])):
        args = build_parser().parse_args(argv[1:])
    if not getattr(args, "command", None):
        raise CommandError("semexplore without a subcommand")
    return args


# ------------------------------------------------------------------------------ resolving
def check_policies(text: str) -> None:
    """Every spec of a comma-separated policy list resolves: the benchmark's own check (names,
    versions, overrides, files), except that a ``pretrained:NAME`` is looked up without loading
    its model and a model zip under ``runs/`` is one the reader trains first."""
    from semexplore_gym.policies.pretrained import get_pretrained
    from semexplore_gym.policies.specs import parse_spec, split_specs

    from semexplore_gym.cli.benchmark import check_policies as check_specs
    from semexplore_gym.cli.world_lists import refuse_repeats

    specs = split_specs(text)
    if not specs:
        raise CommandError("--policies is empty")
    refuse_repeats("--policies", specs)
    built = []
    for spec in specs:
        base = parse_spec(spec)[0]
        name, _, arg = base.partition(":")
        if name == "pretrained":
            get_pretrained(arg)
        elif name in ("sb3", "option-ppo") and arg.startswith(READER_OUTPUTS):
            if not arg.endswith(".zip"):
                raise CommandError(f"--policies {spec!r}: a model file ends in .zip")
        else:
            built.append(spec)
    check_specs(built)


def check_world(spec: str, extra_names: tuple[str, ...] = ()) -> None:
    """A world spec resolves: a catalogue name for ``map:NAME`` (the file need not be fetched),
    an existing file, or a fixed or procedural world (built once, as the benchmark does)."""
    from semexplore_gym.cli.world_lists import check_worlds
    from semexplore_gym.maps.catalogue import get_catalogue_map

    if spec in extra_names:
        return
    if spec.startswith("map:"):
        get_catalogue_map(spec[4:].split(",")[0].strip())
    elif spec.lower().endswith((".yaml", ".yml", ".json", ".png")):
        if not (REPO / spec).is_file() and not Path(spec).is_file():
            raise CommandError(f"world file {spec!r} not found")
    else:
        check_worlds([spec], 0)


def _worlds(value: Any) -> list[str]:
    from semexplore_gym.cli.world_lists import split_worlds

    if isinstance(value, (list, tuple)):
        return [w for v in value for w in split_worlds(str(v))]
    return split_worlds(str(value))


def _check_config(flag: str, load: Callable[..., Any], path: Any, overrides: Any) -> None:
    try:
        load(path, list(overrides or []))
    except (ValueError, FileNotFoundError) as e:
        raise CommandError(f"{flag} {path!r}: {e}") from None


def check_team(args: argparse.Namespace) -> None:
    """``semexplore benchmark --robots``: the team sizes parse and every team policy builds."""
    from semexplore_gym.policies.team import make_team_policy

    from semexplore_gym.cli.benchmark import team_study_request

    for spec in team_study_request(args).policies:
        make_team_policy(spec)


def check_train(args: argparse.Namespace) -> None:
    """``semexplore train``: the train config and its ``--train-set`` overrides load for
    ``--algo`` (the loader the command itself uses)."""
    import importlib

    from semexplore_gym.training.train_config import check_train_config, load_train_config

    loaders = {
        "frontier_value": ("frontier_value_search", "load_frontier_value_config"),
        "oracle_student": ("oracle_student", "load_oracle_student_config"),
        "option_ppo": ("option_ppo", "load_option_ppo_config"),
    }
    if args.algo in loaders:
        module, name = loaders[args.algo]
        load = getattr(importlib.import_module(f"semexplore_gym.training.{module}"), name)
        _check_config("--train-config", load, args.train_config, args.overrides)
        return
    _check_config("--train-config", load_train_config, args.train_config, args.overrides)
    check_train_config(load_train_config(args.train_config, args.overrides), args.algo)


def check_names(args: argparse.Namespace, module: dict[str, Any] | None = None) -> None:
    """Resolve every value of ``args`` that names something, by the attribute it lands in."""
    from semexplore_gym.policies.specs import load_policy_config

    from semexplore_gym.envs.env_config import load_env_config
    from semexplore_gym.evaluation.splits import split_suite
    from semexplore_gym.evaluation.suites import load_suite

    ns = vars(args)
    if ns.get("policies") and not ns.get("robots"):
        check_policies(str(ns["policies"]))
    if ns.get("policy"):
        check_policies(str(ns["policy"]))
    extra = tuple((module or {}).get("REAL_MAPS", {}))  # a script's own short names for maps
    for key in ("world", "worlds"):
        for world in _worlds(ns[key]) if ns.get(key) else []:
            try:
                check_world(world.replace("seed=*", "seed=0"), extra)
            except (ValueError, FileNotFoundError) as e:  # the flag as this command spells it
                raise CommandError(re.sub(r"^--worlds\b", f"--{key}", str(e))) from None
    for suite in str(ns.get("suite") or "").split(","):
        if suite.strip():
            _check_config("--suite", lambda p, _o: load_suite(p), suite.strip(), None)
    for part in str(ns.get("split") or "").split(","):
        if part.strip():
            _check_config("--split", lambda p, _o: split_suite(p), part.strip(), None)
    if ns.get("env_config") is not None or ns.get("env_overrides"):
        _check_config(
            "--env-config", load_env_config, ns.get("env_config"), ns.get("env_overrides")
        )
    if ns.get("policy_config") is not None:
        _check_config(
            "--policy-config", lambda p, _o: load_policy_config(p), ns["policy_config"], None
        )


def check_command(argv: list[str]) -> None:
    """Check one documented command without running it.

    Raises:
        CommandError: not the project's command, an argument its parser refuses, or a value
            that does not resolve (the message names it).
    """
    if argv[0] == "python" and len(argv) > 1 and argv[1].startswith("scripts/"):
        args, module = parse_script(argv)
        check = module.get("check_args")
        try:
            check_names(args, module)
            if callable(check):
                check(args)
        except (ValueError, FileNotFoundError) as e:
            raise CommandError(f"{argv[1]}: {e}") from None
        return
    if argv[0] != "semexplore":
        raise CommandError(f"{argv[0]!r} is not the project's command (semexplore, scripts/)")
    args = parse_semexplore(argv)
    try:
        if args.command == "benchmark":
            from semexplore_gym.cli.benchmark import validate_args

            with contextlib.redirect_stderr(io.StringIO()):  # "writing to runs/..." notice
                validate_args(args)
            if args.robots:
                check_team(args)
        if args.command == "train":
            check_train(args)
        check_names(args)
    except (ValueError, FileNotFoundError) as e:
        raise CommandError(f"semexplore {args.command}: {e}") from None


# --------------------------------------------------------------------------------- pages
def check_page(path: Path) -> tuple[int, list[str]]:
    """``(commands checked, problems)`` of one page's long blocks; each problem names the page
    and the line of the command."""
    rel = str(path)
    if path.resolve().is_relative_to(REPO):
        rel = path.resolve().relative_to(REPO).as_posix()
    checked, problems = 0, []
    for first, info, body in long_blocks(path.read_text(encoding="utf-8")):
        if info != "bash":
            problems.append(f"{rel}:{first - 1}: a long block is a ```bash block, not {info!r}")
            continue
        try:
            commands = block_commands(body, first)
        except CommandError as e:
            problems.append(f"{rel}:{first}: {e}")
            continue
        if not commands:
            problems.append(f"{rel}:{first}: a long block without a command")
        for line, argv in commands:
            checked += 1
            try:
                check_command(argv)
            except CommandError as e:
                problems.append(f"{rel}:{line}: {e}")
    return checked, problems


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("pages", nargs="*", help="Markdown pages (default: README.md and docs/*.md)")
    args = ap.parse_args(argv)
    pages = [Path(p) for p in args.pages] or [
        REPO / "README.md",
        *sorted((REPO / "docs").glob("*.md")),
    ]
    total, problems = 0, []
    for page in pages:
        if not page.is_file():
            ap.error(f"no such page: {page}")
        checked, found = check_page(page)
        total += checked
        problems += found
    for problem in problems:
        print(problem, file=sys.stderr)
    print(f"{total} long commands checked, {len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
