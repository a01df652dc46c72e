"""``semexplore benchmark``: every (world, policy, seed) mission, resumable, with figures and stats.

Each seed starts every policy from the same random free pose (``--fixed-start`` keeps the
world's start pose; then seeds vary a mission only through ``seed=*`` worlds). A policy spec
may carry a label, ``semantic[tuned]``, or parameter overrides, ``semantic[cost.w_v=0]``
(items separated by ``;`` or ``,``); tables show the whole spec. Examples::

    semexplore benchmark --worlds maze1,maze2 --policies semantic,frontier,nearest --runs 10 --out runs/bench
    semexplore benchmark --suite mazes,caves --policies 'semantic,semantic[cost.w_p=0],nearest' --out runs/suites
    semexplore benchmark --split mazes:test --policies semantic,nearest,frontier,sb3:agent.zip --out runs/learn

A suite (``configs/suites/NAME.yaml`` or a path to your own YAML) gives the worlds, the runs,
the start poses and each world's time limit; its summary adds a table per world family and
one over all worlds. A learning split's part (``configs/splits/NAME.yaml``: ``--split mazes:test``)
runs like a suite and adds the learning table (per family: oracle, expert, each policy,
baselines; medians, ratios to the expert and the oracle, Wilcoxon p).

Model zips (``sb3:``) and ``py:`` specs run code from the file they name, in this process and
in every worker: use only files from sources you trust.
"""

from __future__ import annotations

import argparse
import shlex
import sys
from typing import Any

from semexplore_gym.cli import describe
from semexplore_gym.cli._flags import add_renamed_flag
from semexplore_gym.cli._output import add_json_flag, print_result
from semexplore_gym.cli.world_lists import check_worlds, refuse_repeats, split_list, split_worlds
from semexplore_gym.core.validation import short_repr
from semexplore_gym.evaluation.errors import ParameterError


def _split_policies(text: str) -> list[str]:
    """Comma-separated policy specs; commas inside ``[...]`` stay with their spec."""
    from semexplore_gym.policies.specs import split_specs

    return split_specs(text)


def check_policies(policies: list[str]) -> None:
    """Build every spec with a bracket or a file once, so a typo fails before any mission.

    Raises:
        ValueError: an unknown policy, a malformed bracket, an unknown parameter, a bad file.
    """
    from semexplore_gym.policies.registry import make_policy, policy_factories
    from semexplore_gym.policies.specs import parse_spec

    known = policy_factories()
    for p in policies:
        base, _, overrides = parse_spec(p)
        name = base.partition(":")[0]
        if name not in known:
            raise ValueError(f"unknown policy {p!r}; known: {', '.join(sorted(known))}")
        if overrides or name in ("py", "sb3", "pretrained"):
            try:
                make_policy(p)
            except (ValueError, FileNotFoundError) as e:
                msg = str(e)
                raise ValueError(
                    f"--policies: {msg}" if p in msg else f"--policies {p!r}: {msg}"
                ) from None


#: Seeds per (world, policy) when neither --runs nor a suite says.
DEFAULT_RUNS = 10
#: Bounds of the benchmark's counts: beyond them a typo, not a plan.
MAX_RUNS = 100_000
MAX_WORKERS = 256


def default_out(args: argparse.Namespace, now: float | None = None) -> str:
    """``runs/<suite, split or worlds>-<YYYYmmdd-HHMMSS>``: where a run without ``--out``
    writes (a new directory each time; the name says what ran)."""
    import re
    import time

    what = args.suite or getattr(args, "split", None) or args.worlds or "bench"
    slug = re.sub(r"[^A-Za-z0-9.]+", "_", str(what)).strip("_.")[:40] or "bench"
    stamp = time.strftime("%Y%m%d-%H%M%S", time.localtime(now))
    return f"runs/{slug}-{stamp}"


def validate_args(args: argparse.Namespace) -> None:
    """Check the numbers and the output path before anything is loaded or run.

    Raises:
        ValueError: naming the argument and its value.
    """
    from pathlib import Path

    if args.runs is not None and not (1 <= args.runs <= MAX_RUNS):
        raise ValueError(f"--runs must be in 1..{MAX_RUNS}, got {args.runs}")
    if not (0 <= args.seed0 <= 2**32 - 1 - (args.runs or 1000)):
        raise ValueError(f"--seed0 must be in 0..2**32-1-runs, got {args.seed0}")
    if not (1 <= args.workers <= MAX_WORKERS):
        raise ValueError(f"--workers must be in 1..{MAX_WORKERS}, got {args.workers}")
    if args.out is None:
        args.out = default_out(args)
        print(f"semexplore benchmark: writing to {args.out} (--out to choose)", file=sys.stderr)
    if args.max_time_s is not None and not (0 < args.max_time_s <= 1e7):
        raise ValueError(f"--max-time-s must be in (0, 1e7] s, got {args.max_time_s!r}")
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"--out {short_repr(args.out)} is an existing file; give a directory")
    table = getattr(args, "best_known", None)
    if table is not None:
        from semexplore_gym.evaluation.best_known import read_table

        if not Path(table).is_file():
            raise ValueError(f"--best-known {short_repr(table)}: no such file")
        read_table(table)  # a malformed table fails now, naming its line


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = sub.add_parser(
        "benchmark",
        help="run exploration missions for several worlds, policies and seeds; write runs.csv, plots, summary.md",
        description=describe(__doc__),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    which = p.add_mutually_exclusive_group(required=True)
    which.add_argument(
        "--worlds",
        help="comma-separated world spellings; 'maze:seed=*' uses each run's seed",
    )
    which.add_argument(
        "--suite",
        help="comma-separated suite names (configs/suites: paper, mazes, offices, caves, open, real) "
        "or suite YAML paths; each world gets the suite's time limit, runs and start poses",
    )
    which.add_argument(
        "--split",
        help="comma-separated learning split parts NAME:PART (configs/splits: mazes, offices, caves, "
        "open, dungeon; parts train, validation, test), e.g. mazes:test; run like suites, plus "
        "the learning table. No test world is ever used for training or model selection",
    )
    p.add_argument(
        "--policies",
        default="semantic,frontier,nearest",
        help="comma-separated policy specs; 'semantic[cost.w_v=0;cost.w_p=0]' sets parameters, "
        "'semantic[my label]' only names a variant. sb3:MODEL.zip and py: specs run code from "
        "the named file: use only files from trusted sources (default: %(default)s)",
    )
    p.add_argument(
        "--runs",
        type=int,
        default=None,
        help="seeds per (world, policy) (default: 10, or the suite's runs)",
    )
    p.add_argument("--seed0", type=int, default=0, help="first seed (default: %(default)s)")
    p.add_argument(
        "--out",
        default=None,
        help="output directory; rerunning a command with the same --out resumes (default: "
        "runs/<suite, split or worlds>-<date>-<time>, said on stderr)",
    )
    p.add_argument(
        "--max-time-s",
        type=float,
        default=None,
        help="stop each mission after this simulated time (with --suite: replaces the suite's "
        "per-world limits)",
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
    start = p.add_mutually_exclusive_group()
    start.add_argument(
        "--random-start",
        action="store_true",
        help="sample each seed's start pose in free space, the same for every policy (the default)",
    )
    start.add_argument(
        "--fixed-start",
        action="store_true",
        help="start every mission at the world's own start pose; seeds then repeat the same "
        "mission unless the world spelling has seed=*",
    )
    _add_run_arguments(p)
    add_renamed_flag(p, "--config", "use --env-config (env config preset or YAML)")
    add_renamed_flag(p, "--set", "use --env-set SECTION.KEY=VALUE (env config override)")
    return p


def _add_run_arguments(p: argparse.ArgumentParser) -> None:
    """Where and how the missions run: workers, backend, progress and figures."""
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
    p.add_argument(
        "--robots",
        default=None,
        help="team sizes, e.g. 1,2,3: run team missions in SemanticExploreMulti-v0 with team "
        "policies (semantic, semantic_nosem, coordinated, coordinated_nobranch, greedy, "
        "independent) instead",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--no-plots", action="store_true", help="skip figures")
    add_json_flag(p, "the counts of missions run, skipped and failed and the report paths")
    p.add_argument(
        "--oracle",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="also run the privileged oracle (full-knowledge tour) on every (world, seed) and "
        "write each mission's regret against it (regret.csv, summary.md, regret_ladder.png); "
        "default: on with --suite or --split, off otherwise; with --robots, the team oracle "
        "(the tour split into routes of least makespan), off unless asked for",
    )
    p.add_argument(
        "--best-known",
        default=None,
        metavar="TABLE",
        help="best-known table (CSV) to compare each mission with: T99 and distance to 99 %% "
        "against the best any policy reached from the same start and the certified lower bound "
        "(summary.md 'Against the best known'; OUT/best_known.csv is the table updated with the "
        "run); default: the shipped configs/best_known/best_known.csv",
    )


def _suite_tasks(
    args: argparse.Namespace, seeds_for: Any, policies: list[str] | None = None
) -> tuple[list[Any], list[dict[str, Any]], list[str]]:
    """Tasks of every ``--suite`` (see :func:`~semexplore_gym.evaluation.suites.suite_tasks`)
    for ``policies`` (default: ``--policies``)."""
    from semexplore_gym.evaluation.suites import suite_tasks

    names: list[Any] = split_list(args.suite) if args.suite is not None else _split_parts(args)
    return suite_tasks(
        names,
        _split_policies(args.policies) if policies is None else policies,
        seeds_for,
        max_time_s=args.max_time_s,
        fixed_start=args.fixed_start,
        env_config=args.env_config,
        env_overrides=args.env_overrides,
    )


def _split_parts(args: argparse.Namespace) -> list[Any]:
    """The suites of ``--split NAME:PART[,...]``."""
    from semexplore_gym.evaluation.splits import split_suite

    out = []
    for spec in split_list(args.split or ""):
        try:
            out.append(split_suite(spec))
        except (ValueError, FileNotFoundError) as e:
            raise ValueError(f"--split {short_repr(spec)}: {e}") from None
    if not out:
        raise ValueError("--split is empty")
    return out


#: Python parameters named in the harness's errors, and the flags that set them.
FLAGS = {
    "names": "--suite",
    "out_dir": "--out",
    "runs": "--runs",
    "seeds": "--runs",
    "workers": "--workers",
    "backend": "--backend",
    "worlds": "--worlds",
    "policies": "--policies",
}


def _world_tasks(
    args: argparse.Namespace, policies: list[str]
) -> tuple[list[Any], list[str], list[int], Any]:
    """Tasks of ``--worlds``: ``(tasks, worlds, seeds, env config record)``."""
    from semexplore_gym.config import to_dict
    from semexplore_gym.envs.env_config import load_env_config
    from semexplore_gym.evaluation.harness import expand_tasks, parse_seeds

    worlds = split_worlds(args.worlds)
    seeds = parse_seeds(args.runs or DEFAULT_RUNS, args.seed0)
    if not worlds:
        raise ValueError("--worlds is empty")
    refuse_repeats("--worlds", worlds)
    check_worlds(worlds, seeds[0])
    if args.fixed_start and len(seeds) > 1:
        same = [w for w in worlds if "seed=*" not in w]
        if same:
            print(
                f"warning: --fixed-start: every seed repeats the same mission on "
                f"{', '.join(same)} (no seed=* in the spelling); the summary will say "
                "'no variation'",
                file=sys.stderr,
            )
    # The env's own limit must not cut the mission short; the user's --env-set wins.
    overrides = [f"episode.random_start={'false' if args.fixed_start else 'true'}"]
    if args.max_time_s is not None:
        overrides.append(f"episode.max_time_s={args.max_time_s!r}")
    overrides += args.env_overrides
    env_config = load_env_config(args.env_config, overrides)
    tasks = expand_tasks(worlds, policies, seeds, max_time_s=args.max_time_s, env_config=env_config)
    return tasks, worlds, seeds, to_dict(env_config)


def run(args: argparse.Namespace) -> int:
    try:
        return _run(args)
    except ParameterError as e:
        # The harness names its parameters; the user typed flags.
        flags = {**FLAGS, "names": "--split"} if getattr(args, "split", None) else FLAGS
        raise e.for_flags(flags) from None


def _add_oracle(args: argparse.Namespace, policies: list[str]) -> bool:
    """Whether the run includes the oracle (``--oracle``; by default with ``--suite``); appends
    its spec to ``policies`` when asked for and not listed."""
    from semexplore_gym.evaluation.regret import ORACLE_SPEC

    suites = args.suite is not None or getattr(args, "split", None) is not None
    with_oracle = args.oracle if args.oracle is not None else suites
    if with_oracle and ORACLE_SPEC not in policies:
        from semexplore_gym.core.coverage_tour.tour import require_solver

        try:
            require_solver()
        except ImportError as e:
            if args.oracle:  # asked for by name: an error
                raise ValueError(f"{e}; or leave the oracle out: --no-oracle") from None
            # on by default with --suite: run without it and say why
            print(f"semexplore benchmark: no oracle (regret) in this run: {e}", file=sys.stderr)
            return False
        policies.append(ORACLE_SPEC)
    return bool(with_oracle)


def _run(args: argparse.Namespace) -> int:
    from pathlib import Path

    from semexplore_gym.evaluation.harness import parse_seeds, run_benchmark, write_manifest

    validate_args(args)
    if getattr(args, "robots", None):
        from semexplore_gym.evaluation.team_benchmark import run_team_study

        if getattr(args, "split", None):
            raise ValueError("--robots runs --worlds or --suite; --split is for single robots")
        report = run_team_study(team_study_request(args))
        print_result(args, report, Path(report["summary"]).read_text())
        return 1 if report["failed"] else 0
    policies = _split_policies(args.policies)
    if not policies:
        raise ValueError("--policies is empty")
    refuse_repeats("--policies", policies)
    with_oracle = _add_oracle(args, policies)
    check_policies(policies)
    suites: list[dict[str, Any]] = []
    if args.suite is not None or getattr(args, "split", None) is not None:
        tasks, suites, worlds = _suite_tasks(
            args, lambda runs: parse_seeds(args.runs or runs, args.seed0), policies
        )
        seeds = sorted({t.seed for t in tasks})
        env_config_record: Any = "per world (suite)"
    else:
        tasks, worlds, seeds, env_config_record = _world_tasks(args, policies)

    Path(args.out).mkdir(parents=True, exist_ok=True)
    write_manifest(
        args.out,
        {
            "command": " ".join(shlex.quote(a) for a in sys.argv),
            "suites": suites or None,
            "splits": split_list(args.split) if getattr(args, "split", None) else None,
            "worlds": worlds,
            "policies": policies,
            "seeds": seeds,
            "max_time_s": args.max_time_s,
            "fixed_start": bool(args.fixed_start),
            "config": args.env_config,
            "env_overrides": list(args.env_overrides),
            "env_config": env_config_record,
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
        suites=[{"name": r["name"], "version": r["version"]} for r in suites] or None,
    )
    summary, plots = _write_reports(args, with_oracle)
    report = {
        "ran": res["ran"],
        "skipped": res["skipped"],
        "failed": len(res["failed"]),
        "summary": str(summary),
        "plots": [str(p) for p in plots],
    }
    print_result(args, report, Path(summary).read_text())
    return 1 if res["failed"] else 0


def _write_reports(args: argparse.Namespace, with_oracle: bool) -> tuple[Any, list[Any]]:
    """``summary.md`` and the figures; the regret outputs with the oracle; the learning table
    with ``--split``. Returns ``(summary path, figure paths)``."""
    from semexplore_gym.evaluation.report import write_plots, write_summary

    summary = write_summary(args.out)
    plots = [] if args.no_plots else write_plots(args.out)
    if with_oracle:
        from semexplore_gym.evaluation.regret import write_regret

        regret = write_regret(args.out, plots=not args.no_plots)
        plots += [regret["plot"]] if regret["plot"] else []
    from semexplore_gym.evaluation.best_known import write_best_known

    write_best_known(args.out, getattr(args, "best_known", None))
    if getattr(args, "split", None):
        from semexplore_gym.evaluation.learning_table import write_learning_table

        write_learning_table(args.out)
    return summary, plots


def team_study_request(args: argparse.Namespace) -> Any:
    """``--robots N[,M...]`` and the benchmark's flags as a ``TeamStudyRequest``."""
    from pathlib import Path

    from semexplore_gym.evaluation.team_benchmark import TeamStudyRequest

    try:
        counts = tuple(int(v) for v in str(args.robots).split(",") if v.strip())
    except ValueError:
        raise ValueError(f"--robots must be team sizes in 1..8, got {args.robots!r}") from None
    policies = _split_policies(str(args.policies))
    if args.oracle:  # the team oracle, asked for by name (never on by default for teams)
        from semexplore_gym.core.coverage_tour.team_tour import require_routing_solver
        from semexplore_gym.core.coverage_tour.tour import require_solver

        try:
            require_solver()
            require_routing_solver()
        except ImportError as e:
            raise ValueError(f"{e}; or leave the oracle out: --no-oracle") from None
        if policies == ["semantic", "frontier", "nearest"]:
            policies = ["semantic", "coordinated", "independent"]
        if "oracle" not in policies:
            policies.append("oracle")
    return TeamStudyRequest(
        robot_counts=counts,
        policies=tuple(policies),
        worlds=tuple(split_worlds(args.worlds or "")),
        out=Path(args.out),
        seed0=args.seed0,
        runs=args.runs,
        suite=getattr(args, "suite", None),
        max_time_s=args.max_time_s,
        env_config=args.env_config,
        env_overrides=tuple(args.env_overrides),
        fixed_start=bool(args.fixed_start),
        progress=not args.no_progress,
        command=" ".join(shlex.quote(a) for a in sys.argv),
        workers=args.workers,
        backend=args.backend,
        ray_address=args.ray_address,
        plots=not args.no_plots,
    )
