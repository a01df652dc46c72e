"""One benchmark mission in this process: warm-up, env, policy, :func:`run_mission`, row."""

from __future__ import annotations

import json
from typing import Any

import numpy as np

from semexplore_gym.evaluation.path_decomposition import DECOMPOSITION_COLUMNS
from semexplore_gym.evaluation.run_row import POLICY_COLUMNS, SLAM_COLUMNS, RunRow
from semexplore_gym.evaluation.tasks import Task


def _warm_up_config_key(env_config: Any) -> str:
    """The env config without its episode section: the warm-up sets its own time limit, so
    suite worlds that differ only in ``episode.max_time_s`` warm up once."""
    if env_config is None or isinstance(env_config, str):
        return repr(env_config)
    from semexplore_gym.config import to_dict

    d = to_dict(env_config)
    if not isinstance(d, dict):
        return repr(env_config)
    return json.dumps({k: v for k, v in d.items() if k != "episode"}, sort_keys=True, default=str)


def mission_row(task: Task, res: Any, coverage_at_planner_clearance: float | None = None) -> RunRow:
    """The ``runs.csv`` row of ``task`` from its :class:`~.rollout.MissionResult`; the
    policy-specific columns come from the policy's ``mission_metrics()`` (None if absent),
    ``coverage_at_planner_clearance`` from :mod:`.planner_coverage` (given by the caller,
    which still holds the env), the path decomposition's from the result's (None without one),
    ``policy_version`` from the spec (:func:`~semexplore_gym.policies.expert.versions.expert_version`),
    the SLAM columns from the result's ``slam_metrics`` (None without the SLAM mode)."""
    from semexplore_gym.policies.expert.versions import expert_version

    parts = getattr(res, "path_decomposition", None)
    decomposition = parts.columns() if parts is not None else dict.fromkeys(DECOMPOSITION_COLUMNS)
    return RunRow(
        world=task.world,
        policy=task.policy,
        seed=task.seed,
        mission_time_s=res.mission_time_s,
        coverage=res.coverage,
        self_stopped=res.self_stopped,
        stop_reason=res.stop_reason,
        path_length_m=res.path_length_m,
        collisions=res.collisions,
        T90_s=res.t90_s,
        T99_s=res.t99_s,
        mean_map_generation_ms=res.mean_map_generation_ms,
        mean_global_planning_ms=res.mean_global_planning_ms,
        wall_time_s=res.wall_time_s,
        explored_area_m2=res.explored_area_m2,
        steps=res.steps,
        **{k: res.policy_metrics.get(k) for k in POLICY_COLUMNS},
        coverage_at_planner_clearance=coverage_at_planner_clearance,
        **decomposition,
        policy_version=expert_version(task.policy),
        **{k: getattr(res, "slam_metrics", {}).get(k) for k in SLAM_COLUMNS},
    )


def warm_up_task(task: Task) -> None:
    """Load (or compile) the kernels of ``task``'s policy and env config in this process, once
    per policy, config and overrides (see :func:`~semexplore_gym.evaluation.warmup.warm_up`)."""
    from semexplore_gym.evaluation.warmup import warm_up
    from semexplore_gym.policies.registry import make_policy

    warm_up(
        lambda: make_policy(task.policy, **task.policy_overrides),
        task.env_config,
        key=(task.policy, _warm_up_config_key(task.env_config), repr(task.policy_overrides)),
    )


def run_task(task: Task) -> dict[str, Any]:
    """Run one mission in this process; returns a picklable record (row + trace + trajectory)."""
    from semexplore_gym.evaluation.planner_coverage import coverage_at_planner_clearance
    from semexplore_gym.evaluation.rollout import (
        make_mission_env,
        map_observation_for,
        run_mission,
    )
    from semexplore_gym.policies.registry import make_policy

    warm_up_task(task)  # kernels compiled or loaded before the mission's clocks start
    policy = make_policy(task.policy, **task.policy_overrides)
    env = make_mission_env(task.resolved_world, task.env_config, **map_observation_for(policy))
    try:
        # Missions end when the policy stops itself (or at the time limit), not at the env's
        # coverage goal: mission time is each method's own exploration time; T90/T99 compare
        # all methods on the same coverage levels.
        res = run_mission(
            env,
            policy,
            seed=task.seed,
            max_time_s=task.max_time_s,
            progress=False,
            ignore_terminated=True,
        )
        planner_coverage = coverage_at_planner_clearance(env, policy)
    finally:
        env.close()
    return {
        "row": mission_row(task, res, planner_coverage).to_dict(),
        "trace": np.asarray(res.coverage_trace, dtype=np.float64),
        "trajectory": np.asarray(res.trajectory),
    }
