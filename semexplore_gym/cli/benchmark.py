"""``semexplore benchmark``: every (world, policy, seed) mission, resumable, with figures and stats.

Example::

    semexplore benchmark --worlds maze1,maze2 --policies semantic,frontier,nearest --runs 10 --out runs/bench
"""

from __future__ import annotations

import argparse
import json
import shlex
import sys

from semexplore_gym.cli._flags import add_renamed_flag
from semexplore_gym.core.safe_io import short_repr
from semexplore_gym.cli import describe


def _split(text: str) -> list[str]:
    return [t.strip() for t in text.split(",") if t.strip()] if text else []


def _split_worlds(text: str) -> list[str]:
    """Split on commas that start a new world: ``maze:seed=1,size_m=6,maze2`` keeps the params."""
    out: list[str] = []
    for part in _split(text):
        if out and "=" in part and ":" not in part and ":" in out[-1]:
            out[-1] += "," + part  # a key=value of the previous world's parameters
        else:
            out.append(part)
    return out


def _check_worlds(worlds: list[str], seed: int) -> None:
    """Build each world once before any mission starts, so a typo fails at once, not per mission.

    Raises:
        ValueError: an unknown or malformed world spelling (the message names it).
        FileNotFoundError: a map file that does not exist.
    """
    from semexplore_gym.core.worlds import make_world

    for world in worlds:
        try:
            make_world(world.replace("seed=*", f"seed={seed}"))
        except FileNotFoundError as e:
            raise FileNotFoundError(f"--worlds {world!r}: {e}") from None
        except ValueError as e:
            raise ValueError(f"--worlds {world!r}: {e}") from None


#: Bounds of the benchmark's counts: beyond them a typo, not a plan.
MAX_RUNS = 100_000
MAX_WORKERS = 256


def validate_args(args: argparse.Namespace) -> None:
    """Check the numbers and the output path before anything is loaded or run.

    Raises:
        ValueError: naming the argument and its value.
    """
    from pathlib import Path

    if not (1 <= args.runs <= MAX_RUNS):
        raise ValueError(f"--runs must be in 1..{MAX_RUNS}, got {args.runs}")
    if not (0 <= args.seed0 <= 2**32 - 1 - args.runs):
        raise ValueError(f"--seed0 must be in 0..2**32-1-runs, got {args.seed0}")
    if not (1 <= args.workers <= MAX_WORKERS):
        raise ValueError(f"--workers must be in 1..{MAX_WORKERS}, got {args.workers}")
    if args.max_time_s is not None and not (0 < args.max_time_s <= 1e7):
        raise ValueError(f"--max-time-s must be in (0, 1e7] s, got {args.max_time_s!r}")
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out {short_repr(args.out)} is an existing file; give a directory")


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = sub.add_parser(
        "benchmark",
        help="run exploration missions for several worlds, policies and seeds; write runs.csv, plots, summary.md",
        description=describe(__doc__),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument(
        "--worlds",
        required=True,
        help="comma-separated world spellings; 'maze:seed=*' uses each run's seed",
    )
    p.add_argument(
        "--policies",
        default="semantic,frontier,nearest",
        help="comma-separated policy specs (default: %(default)s)",
    )
    p.add_argument(
        "--runs", type=int, default=10, help="seeds per (world, policy) (default: %(default)s)"
    )
    p.add_argument("--seed0", type=int, default=0, help="first seed (default: %(default)s)")
    p.add_argument(
        "--out", required=True, help="output directory; rerunning the same command resumes"
    )
    p.add_argument(
        "--max-time-s", type=float, default=None, help="stop each mission after this simulated time"
    )
    p.add_argument("--env-config", default=None, help="env config: preset name or YAML path")
    p.add_argument(
        "--env-set",
        dest="env_overrides",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="env config override, e.g. lidar.n_beams=180 (repeatable)",
    )
    p.add_argument(
        "--random-start",
        action="store_true",
        help="sample each seed's start pose in free space (same for every policy)",
    )
    p.add_argument(
        "--workers", type=int, default=1, help="missions in parallel (default: %(default)s)"
    )
    p.add_argument(
        "--backend",
        choices=("process", "ray"),
        default="process",
        help="parallel backend (default: %(default)s)",
    )
    p.add_argument(
        "--ray-address",
        default=None,
        help="existing Ray cluster address ('auto'); default starts a local one",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--no-plots", action="store_true", help="skip figures")
    add_renamed_flag(p, "--config", "use --env-config (env config preset or YAML)")
    add_renamed_flag(p, "--set", "use --env-set SECTION.KEY=VALUE (env config override)")
    return p


def run(args: argparse.Namespace) -> int:
    from semexplore_gym.evaluation.harness import (
        expand_tasks,
        parse_seeds,
        run_benchmark,
        write_manifest,
    )
    from semexplore_gym.evaluation.report import write_plots, write_summary

    validate_args(args)
    worlds = _split_worlds(args.worlds)
    policies = _split(args.policies)
    seeds = parse_seeds(args.runs, args.seed0)
    for what, items in (("worlds", worlds), ("policies", policies)):
        if not items:
            raise ValueError(f"--{what} is empty")
        dup = next((x for i, x in enumerate(items) if x in items[:i]), None)
        if dup is not None:
            raise ValueError(
                f"--{what} lists {short_repr(dup)} twice; each must appear once "
                "(a repeat would count the same missions twice)"
            )
    _check_worlds(worlds, seeds[0])
    from policies.registry import policy_factories, strip_label

    known = policy_factories()
    for p in policies:
        if strip_label(p).partition(":")[0] not in known:
            raise ValueError(f"unknown policy {p!r}; known: {', '.join(sorted(known))}")
        if strip_label(p).partition(":")[0] in ("py", "sb3", "pretrained"):
            # user code and model files: load them once now, so a typo fails before any mission
            from policies.registry import make_policy

            try:
                make_policy(p)
            except (ValueError, FileNotFoundError) as e:
                raise ValueError(f"--policies {p!r}: {e}") from None
    from semexplore_gym.core.params import to_dict
    from semexplore_gym.envs.config import load_env_config

    overrides = list(args.env_overrides) + (
        ["episode.random_start=true"] if args.random_start else []
    )
    env_config = (
        load_env_config(args.env_config, overrides) if (args.env_config or overrides) else None
    )
    tasks = expand_tasks(worlds, policies, seeds, max_time_s=args.max_time_s, env_config=env_config)
    from pathlib import Path

    Path(args.out).mkdir(parents=True, exist_ok=True)
    write_manifest(
        args.out,
        {
            "command": " ".join(shlex.quote(a) for a in sys.argv),
            "worlds": worlds,
            "policies": policies,
            "seeds": seeds,
            "max_time_s": args.max_time_s,
            "config": args.env_config,
            "env_config": to_dict(env_config) if env_config is not None else None,
            "workers": args.workers,
            "backend": args.backend,
        },
    )
    res = run_benchmark(
        tasks,
        args.out,
        workers=args.workers,
        backend=args.backend,
        ray_address=args.ray_address,
        progress=not args.no_progress,
    )
    summary = write_summary(args.out)
    plots = [] if args.no_plots else write_plots(args.out)
    print(
        json.dumps(
            {
                "ran": res["ran"],
                "skipped": res["skipped"],
                "failed": len(res["failed"]),
                "summary": str(summary),
                "plots": [str(p) for p in plots],
            }
        )
    )
    print(Path(summary).read_text())
    return 1 if res["failed"] else 0
