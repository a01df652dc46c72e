"""``semexplore explore``: run one exploration mission and print its metrics.

Example::

    semexplore explore --world maze1 --policy semantic --seed 0 --gif maze1.gif
    semexplore explore --world ../shared/maps/turtlebot3/world/map.yaml --json
    semexplore explore --world maze2 --policy-config configs/expert/robust_paper_weights.yaml --policy-set cost.w_v=2
    semexplore explore --world maze2 --policy 'semantic[cost.w_v=0]'
    semexplore explore --world office:seed=304,size_m=8 --robots 3 --policy coordinated --gif team.gif
"""

from __future__ import annotations

import argparse
import sys
from typing import Any

from semexplore_gym.cli._flags import add_renamed_flag, check_output_flag
from semexplore_gym.cli._output import print_json
from semexplore_gym.evaluation.run_row import SLAM_COLUMNS
from semexplore_gym.evaluation.warmup import COMPILE_ESTIMATE

#: Keys of the ``--json`` object, in order.
JSON_KEYS: tuple[str, ...] = (
    "coverage",
    "mission_time_s",
    "T90_s",
    "T99_s",
    "self_stopped",
    "stop_reason",
    "path_length_m",
    "collisions",
    "wall_time_s",
    "policy_version",
)
#: Added to the ``--json`` object when the env runs SLAM (``--env-config slam``): the same
#: figures as ``runs.csv``'s SLAM columns.
SLAM_JSON_KEYS: tuple[str, ...] = SLAM_COLUMNS


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    p = sub.add_parser(
        "explore",
        help="run one exploration mission and print coverage, mission time, path length, collisions",
        description="Run one exploration mission of a policy (default: the semantic expert) and "
        "print its metrics. The first run after installing compiles the numba kernels ("
        + COMPILE_ESTIMATE
        + ", said on stderr); reported times never include it.",
    )
    p.add_argument(
        "--world",
        default="maze1",
        help="maze1, maze2, a procedural family with parameters ('maze:seed=3,size_m=10', "
        "'office:...', 'cave:...', 'noisecave:...', 'forest:...'), a catalogue map 'map:NAME' (semexplore maps "
        "list), a ROS map .yaml or a HouseExpo .json (default: maze1)",
    )
    p.add_argument(
        "--policy",
        default=None,
        help="policy spec: semantic (default: the expert's newest version, semantic-v3), "
        "semantic-v2 (the 0.2.0 expert), semantic-paper (the paper's method alone), "
        "frontier, nearest, random, oracle (PRIVILEGED: reads the true world through the env's "
        "privileged channel; a full-knowledge yardstick, not an explorer), pretrained:NAME (see 'semexplore pretrained'), "
        "sb3:MODEL.zip, py:FILE.py:CLASS or py:package.module:CLASS (your own Policy); a bracket sets "
        "parameters, 'semantic[cost.w_v=0;cost.w_p=0]' (the spelling benchmark and "
        "compare-weights use; applied after --policy-set). sb3: and py: specs run code from "
        "the named file: use only files from trusted sources",
    )
    p.add_argument(
        "--seed", type=int, default=0, help="seed for env.reset and the policy (default: 0)"
    )
    p.add_argument(
        "--robots",
        type=int,
        default=None,
        metavar="N",
        help="explore with a team of N robots (1 to 8; SemanticExploreMulti-v0, needs the "
        "'multi' extra); --policy then names a team policy: semantic (default), coordinated, "
        "coordinated_nobranch, greedy, independent, semantic_nosem; the mission ends when no "
        "robot has a reachable frontier (or at --max-time-s); --gif draws one colour per robot",
    )
    _add_config_flags(p)
    p.add_argument(
        "--max-time-s",
        type=float,
        default=1200.0,
        help="simulated time limit of the mission (default: 1200)",
    )
    _add_output_flags(p)
    add_renamed_flag(
        p, "--config", "use --policy-config FILE (policy config) or --env-config (env config)"
    )
    add_renamed_flag(
        p, "--set", "use --policy-set KEY=VALUE (policy parameter) or --env-set (env config)"
    )
    return p


def _add_config_flags(p: argparse.ArgumentParser) -> None:
    """The policy and env config files and their ``KEY=VALUE`` overrides."""
    p.add_argument(
        "--policy-config",
        default=None,
        help="policy config YAML with sections env / policy / params (e.g. configs/expert/robust_paper_weights.yaml)",
    )
    p.add_argument(
        "--env-config",
        default=None,
        help="env config: preset name (default, paper, slam) or YAML path; replaces the config file's env section",
    )
    p.add_argument(
        "--policy-set",
        dest="overrides",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help="policy parameter override, e.g. cost.w_v=2 or potential_field.f_l=1.2 (repeatable)",
    )
    p.add_argument(
        "--env-set",
        dest="env_overrides",
        action="append",
        default=[],
        metavar="SECTION.KEY=VALUE",
        help="env config override, e.g. robot.max_linear_speed_mps=0.15 (repeatable)",
    )


def _add_output_flags(p: argparse.ArgumentParser) -> None:
    """What the command writes besides its metrics: the GIF, JSON, the progress bar."""
    p.add_argument(
        "--gif",
        default=None,
        metavar="OUT.gif",
        help="write an animation with the semantic areas, chosen frontier and path",
    )
    p.add_argument(
        "--gif-every-s",
        type=float,
        default=2.0,
        help="simulated seconds between GIF frames (default: 2)",
    )
    p.add_argument(
        "--json",
        action="store_true",
        help="print the result as one JSON object (keys: " + ", ".join(JSON_KEYS) + ")",
    )
    p.add_argument("--no-progress", action="store_true", help="no progress bar on stderr")


def run(args: argparse.Namespace) -> int:
    import math

    import gymnasium as gym

    import semexplore_gym  # noqa: F401  (registers the env)
    from semexplore_gym.evaluation.rollout import GifOptions, map_observation_for, run_mission
    from semexplore_gym.evaluation.warmup import warm_up
    from semexplore_gym.policies.expert.versions import expert_version
    from semexplore_gym.policies.registry import make_policy
    from semexplore_gym.policies.specs import load_policy_config

    if not (0 < args.max_time_s <= 1e7):
        raise ValueError(f"--max-time-s must be in (0, 1e7] s, got {args.max_time_s!r}")
    if not (math.isfinite(args.gif_every_s) and args.gif_every_s > 0):
        raise ValueError(
            f"--gif-every-s must be a positive finite number, got {args.gif_every_s!r}"
        )
    if not (0 <= args.seed <= 2**32 - 1):
        raise ValueError(f"--seed must be in 0..2**32-1, got {args.seed}")
    if args.gif is not None:
        # the GIF writer creates missing parent directories
        check_output_flag("--gif", args.gif, (".gif",), parent_must_exist=False)
    if args.robots is not None:
        return run_team(args)
    cfg = load_policy_config(args.policy_config)
    spec = args.policy or cfg.policy or "semantic"
    policy_kwargs: dict[str, Any] = cfg.policy_kwargs(args.overrides)
    policy = make_policy(spec, **policy_kwargs)

    env_config = args.env_config if args.env_config is not None else cfg.env
    # The env's own time limit must not cut the mission short.
    env_overrides = [f"episode.max_time_s={args.max_time_s!r}", *args.env_overrides]
    env = gym.make(
        "SemanticExplore-v0",
        world=args.world,
        config=env_config,
        overrides=env_overrides,
        render_mode="rgb_array" if args.gif else None,
        **map_observation_for(policy),
    )
    # Kernels compiled or loaded before the clocks start (and before the progress bar).
    warm_up(lambda: make_policy(spec, **policy_kwargs), env_config, args.env_overrides)
    try:
        result = run_mission(
            env,
            policy,
            seed=args.seed,
            max_time_s=args.max_time_s,
            progress=not args.no_progress,
            gif=GifOptions(args.gif, every_s=args.gif_every_s) if args.gif else None,
            # The mission lasts until the policy stops (or the time limit), not until the env's
            # coverage goal: mission_time_s is the policy's own.
            ignore_terminated=True,
        )
    finally:
        env.close()

    summary = result.summary()
    # The spec as given: a policy's own name may shorten it (sb3:model.zip for sb3:runs/x/model.zip).
    summary["policy"] = spec
    # The expert's named version the spec ran ("semantic" runs the newest); "" for other policies.
    summary["policy_version"] = expert_version(spec)
    if args.json:
        keys = JSON_KEYS + tuple(k for k in SLAM_JSON_KEYS if k in summary)
        print_json(args, {k: summary[k] for k in keys})
    else:
        print(format_result(summary))
    if args.gif:
        print(f"wrote {args.gif}", file=sys.stderr)
    return 0


def run_team(args: argparse.Namespace) -> int:
    """``semexplore explore --robots N``: one team mission, its metrics and optional GIF."""
    from semexplore_gym.envs.multi_robot import make_multi
    from semexplore_gym.envs.multi_robot_config import MAX_ROBOTS
    from semexplore_gym.evaluation.team_benchmark import run_team_mission
    from semexplore_gym.policies.team import make_team_policy

    if not 1 <= args.robots <= MAX_ROBOTS:
        raise ValueError(f"--robots must be in 1..{MAX_ROBOTS}, got {args.robots}")
    if args.policy_config or args.overrides:
        raise ValueError("--policy-config and --policy-set do not apply with --robots")
    spec = args.policy or "semantic"
    try:
        team = make_team_policy(spec)  # an unknown name or a bad bracket fails before the env
    except ValueError as e:
        raise ValueError(f"--policy with --robots: {e}") from None
    # Only the team's own stop or the time limit end the mission (as in the team benchmark).
    overrides = [f"episode.max_time_s={args.max_time_s!r}", "team.end_on_coverage=false"]
    env = make_multi(
        world=args.world,
        config=args.env_config,
        overrides=[*overrides, *args.env_overrides],
        n_robots=args.robots,
        render_mode="rgb_array" if args.gif else None,
        privileged=bool(getattr(team, "privileged", False)),  # the team oracle reads the truth
    )
    try:
        res = run_team_mission(
            env,
            team,
            args.seed,
            max_time_s=args.max_time_s,
            gif_path=args.gif,
            gif_every_s=args.gif_every_s,
        )
    finally:
        env.close()
    row = res.row()
    row.pop("lower_bound_s")  # the benchmark's column (a bound per start), not computed here
    if args.json:
        print_json(args, row)
    else:
        print("\n".join(f"{k:<17}{row[k]}" for k in row))
    if args.gif:
        print(f"wrote {args.gif}", file=sys.stderr)
    return 0


def _version(summary: dict[str, Any]) -> str:
    """``"semantic-v3, "`` when the spec runs a named expert version it does not spell out."""
    version = summary.get("policy_version") or ""
    return f"{version}, " if version and version != summary["policy"] else ""


def format_result(summary: dict[str, Any]) -> str:
    """Human-readable lines of a :meth:`MissionResult.summary`."""
    lines = [
        f"world            {summary['world']}",
        f"policy           {summary['policy']} ({_version(summary)}seed {summary['seed']})",
        f"coverage         {summary['coverage']:.4f}  ({summary['explored_area_m2']:.2f} m^2 mapped)",
        f"mission_time_s   {summary['mission_time_s']:.1f}",
        f"self_stopped     {summary['self_stopped']}",
        f"stop_reason      {summary['stop_reason']}",
        f"path_length_m    {summary['path_length_m']:.2f}",
        f"collisions       {summary['collisions']}",
        f"T90_s / T99_s    {_fmt_t(summary['T90_s'])} / {_fmt_t(summary['T99_s'])}",
        f"wall_time_s      {summary['wall_time_s']:.2f}  ({_speedup(summary)}x faster than simulated time)",
    ]
    # Only the stages the policy has: a learned policy builds no map representation and never
    # replans, so 0.00 ms would only mislead.
    stages = summary["stage_time_s"]
    if stages.get("map_generation", 1.0) > 0:
        lines.append(f"map generation   {summary['mean_map_generation_ms']:.2f} ms mean per call")
    if summary["n_replans"] > 0:
        lines.append(
            f"global planning  {summary['mean_global_planning_ms']:.2f} ms mean per replan "
            f"({summary['n_replans']} replans)"
        )
    used = {k: v for k, v in stages.items() if v > 0}
    lines.append("stage split (s)  " + ", ".join(f"{k} {v:.3f}" for k, v in used.items()))
    return "\n".join(lines)


def _fmt_t(t: float | None) -> str:
    return "-" if t is None else f"{t:.1f}"


def _speedup(summary: dict[str, Any]) -> str:
    wall = summary["wall_time_s"]
    return f"{summary['mission_time_s'] / wall:.0f}" if wall > 0 else "inf"
