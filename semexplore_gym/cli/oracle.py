"""``semexplore oracle``: the full-knowledge coverage tour of a world, without driving it.

Plans the oracle explorer's static tour (:func:`semexplore_gym.core.coverage_tour.plan_coverage_tour`)
from the start pose a benchmark's seed N gets (``env.reset(seed=N)``: a random free pose, or the
world's own with ``--fixed-start``) and prints
its length, the time to drive it at top speed, the number of viewpoints and the share of the
reachable area they see. PRIVILEGED: it reads the true world.

The tour is an upper bound on the shortest drive that sees that share with the env's LiDAR: the
set cover (greedy) and the tour (LKH) are solved approximately, on a lattice of viewpoints; the
time ignores turning, so it is a lower bound on driving this tour.

Beside the tour it prints a certified lower bound (``lower_bound_m``, ``lower_bound_s``): no
explorer with this robot and LiDAR reaches the env's coverage goal from this start after a
shorter drive, or sooner at top speed (see docs/oracle.md; ``--no-bound`` skips it).

Example::

    semexplore oracle 'office:seed=1,size_m=20' --start-seed 0 --json
"""

from __future__ import annotations

import argparse
import math
import os
import time
from concurrent.futures import ThreadPoolExecutor
from typing import Any

from semexplore_gym.cli._output import print_json

#: Keys of the ``--json`` object, in order.
JSON_KEYS: tuple[str, ...] = (
    "world",
    "start_seed",
    "start_pose",
    "tour_length_m",
    "time_at_top_speed_s",
    "n_viewpoints",
    "covered_share",
    "coverable_share",
    "n_candidates",
    "planning_s",
    "lower_bound_m",
    "lower_bound_s",
    "lower_bound_groups",
    "lower_bound_branch_m",
    "bound_planning_s",
)


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    from semexplore_gym.cli import describe

    p = sub.add_parser(
        "oracle",
        help="the full-knowledge coverage tour of a world (privileged static bound): length, "
        "time at top speed, viewpoints, covered share",
        description=describe(__doc__),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("world", help="a world spelling ('maze:seed=3,size_m=10', maze1, a map file)")
    p.add_argument(
        "--start-seed",
        type=int,
        default=0,
        help="seed of env.reset that picks the start: the start of a benchmark's seed N "
        "(default: 0)",
    )
    p.add_argument(
        "--fixed-start",
        action="store_true",
        help="start at the world's own start pose, as 'benchmark --fixed-start' does (default: "
        "a random free pose drawn from --start-seed, as benchmark does)",
    )
    p.add_argument(
        "--env-config", default=None, help="env config: preset name or YAML path (default: default)"
    )
    p.add_argument(
        "--env-set",
        dest="env_overrides",
        action="append",
        default=[],
        metavar="SECTION.KEY=VALUE",
        help="env config override, e.g. lidar.max_range_m=5 (repeatable)",
    )
    p.add_argument(
        "--no-bound",
        action="store_true",
        help="skip the certified lower bound (its keys are then null)",
    )
    p.add_argument(
        "--json",
        action="store_true",
        help="print one JSON object (keys: " + ", ".join(JSON_KEYS) + ")",
    )
    return p


def static_bound(
    world: str,
    start_seed: int = 0,
    env_config: Any = None,
    env_overrides: list[str] | None = None,
    bound: bool = True,
) -> dict[str, Any]:
    """The static tour of ``world`` from the start of ``env.reset(seed=start_seed)``, as the
    ``--json`` object of ``semexplore oracle``.

    With ``bound``, also the certified lower bound
    (:func:`~semexplore_gym.core.coverage_tour.lower_bound`); otherwise its keys are None.

    Raises:
        ValueError: an unknown world, a start the robot cannot stand at, or a world where no
            bound can be computed.
        ImportError: the tour solver (``elkai``) is missing.
    """
    from semexplore_gym.core.coverage_tour import plan_coverage_tour

    facts, config = privileged_facts(world, start_seed, env_config, env_overrides)

    def timed_tour() -> tuple[Any, float]:
        t0 = time.perf_counter()
        return plan_coverage_tour(facts), time.perf_counter() - t0

    # The tour and the bound are independent: the tour's serial parts overlap the bound's.
    with ThreadPoolExecutor(max_workers=1) as pool:
        planned = pool.submit(timed_tour)
        lb = _bound_of(facts, config) if bound else None
        tour, planning_s = planned.result()
    return {
        "world": str(world),
        "start_seed": start_seed,
        "start_pose": [round(float(v), 4) for v in facts.start_pose],
        "tour_length_m": round(tour.length_m, 3),
        "time_at_top_speed_s": round(tour.length_m / facts.max_linear_speed_mps, 2),
        "n_viewpoints": tour.n_viewpoints,
        "covered_share": round(tour.covered_share, 5),
        "coverable_share": round(tour.coverable_share, 5),
        "n_candidates": tour.n_candidates,
        "planning_s": round(planning_s, 2),
        "lower_bound_m": None if lb is None else _finite_or_none(lb.distance_m, 3),
        "lower_bound_s": None if lb is None else _finite_or_none(lb.time_s, 2),
        "lower_bound_groups": None if lb is None else lb.n_groups,
        "lower_bound_branch_m": None if lb is None else _finite_or_none(lb.branch_m, 3),
        "bound_planning_s": None if lb is None else round(lb.planning_s, 2),
    }


def privileged_facts(
    world: str,
    start_seed: int = 0,
    env_config: Any = None,
    env_overrides: list[str] | None = None,
) -> tuple[Any, Any]:
    """The :class:`~semexplore_gym.core.coverage_tour.PrivilegedWorld` of ``world`` after
    ``env.reset(seed=start_seed)`` (the start a benchmark's seed gets), and the env config.

    Raises:
        ValueError: an unknown world, a bad seed, or a start the robot cannot stand at.
    """
    from semexplore_gym.core.coverage_tour import PRIVILEGED_INFO_KEY
    from semexplore_gym.envs.semantic_explore import SemanticExploreEnv

    if not 0 <= start_seed <= 2**32 - 1:
        raise ValueError(f"--start-seed must be in 0..2**32-1, got {start_seed}")
    env = SemanticExploreEnv(world, config=env_config, overrides=env_overrides, privileged=True)
    try:
        _, info = env.reset(seed=start_seed)
    finally:
        env.close()
    return info[PRIVILEGED_INFO_KEY], env.config


def certified_bound(
    world: str,
    start_seed: int = 0,
    env_config: Any = None,
    env_overrides: list[str] | None = None,
    threads: int | None = None,
    params: dict[str, Any] | None = None,
) -> Any:
    """The certified :class:`~semexplore_gym.core.coverage_tour.LowerBound` of ``world`` from
    the start of ``env.reset(seed=start_seed)``, with the env's LiDAR mount offset, its
    searches on ``threads`` threads (None: one per CPU this process may use); ``params``:
    other :class:`~semexplore_gym.core.coverage_tour.LowerBoundParams` fields (any values give
    a valid bound).

    Raises:
        ValueError: as :func:`privileged_facts`, a noisy LiDAR or odometry, a bad ``params``
            field or value, or a world where no bound can be computed.
    """
    facts, config = privileged_facts(world, start_seed, env_config, env_overrides)
    return _bound_of(facts, config, threads, params)


def usable_cpus() -> int:
    """The CPUs this process may run on."""
    if hasattr(os, "sched_getaffinity"):
        return max(1, len(os.sched_getaffinity(0)))
    return max(1, os.cpu_count() or 1)


def _bound_of(
    facts: Any, config: Any, threads: int | None = None, params: dict[str, Any] | None = None
) -> Any:
    """The bound for the env's LiDAR, which it models noise-free and fused at the true pose;
    its searches on ``threads`` threads (None: :func:`usable_cpus`); ``params``: other
    ``LowerBoundParams`` fields."""
    from dataclasses import fields

    from semexplore_gym.core.coverage_tour import LowerBoundParams, lower_bound

    extra = dict(params or {})
    known = {f.name for f in fields(LowerBoundParams)} - {"mount_offset_m", "threads"}
    for key in extra:
        if key not in known:
            raise ValueError(f"unknown bound parameter {key!r}; known: {', '.join(sorted(known))}")

    odo = config.odometry
    drift = (odo.rot_from_rot, odo.rot_from_trans, odo.trans_from_trans, odo.trans_from_rot)
    if config.lidar.range_noise_std_m > 0 or any(v > 0 for v in drift):
        raise ValueError(
            "the lower bound assumes a noise-free LiDAR and odometry (lidar.range_noise_std_m=0, "
            "no odometry noise); pass --no-bound"
        )
    mount_m = math.hypot(config.lidar.mount_x_m, config.lidar.mount_y_m)
    n = usable_cpus() if threads is None else threads
    return lower_bound(facts, LowerBoundParams(mount_offset_m=mount_m, threads=n, **extra))


def _finite_or_none(value: float, digits: int) -> float | None:
    """``value`` rounded; None when infinite (no explorer reaches the goal)."""
    return round(value, digits) if math.isfinite(value) else None


def run(args: argparse.Namespace) -> int:
    try:
        start = [f"episode.random_start={'false' if args.fixed_start else 'true'}"]
        overrides = start + args.env_overrides
        out = static_bound(
            args.world, args.start_seed, args.env_config, overrides, bound=not args.no_bound
        )
    except ImportError as e:  # the optional solver: one line saying what to install
        raise ValueError(str(e)) from None
    if args.json:
        print_json(args, out)
    else:
        print(
            f"{out['world']} (start seed {out['start_seed']}): tour {out['tour_length_m']} m, "
            f"{out['time_at_top_speed_s']} s at top speed, {out['n_viewpoints']} viewpoints, "
            f"covered {float(out['covered_share']):.2%} (planned in {out['planning_s']} s)"
        )
        if out["bound_planning_s"] is not None:
            m, s = out["lower_bound_m"], out["lower_bound_s"]
            said = "no explorer reaches the goal" if m is None else f"{m} m, {s} s"
            print(
                f"lower bound: {said} ({out['lower_bound_groups']} groups; the branches alone "
                f"{out['lower_bound_branch_m']} m; computed in {out['bound_planning_s']} s)"
            )
    return 0
