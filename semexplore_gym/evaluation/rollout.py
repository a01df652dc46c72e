"""Run one exploration mission of any :class:`Policy` in a SemanticExplore env.

:func:`run_mission` is the loop behind ``semexplore explore`` and the benchmark harness: reset,
then ``act`` / ``step`` until the policy says it is done or the env terminates or truncates (or
``max_time_s`` of simulated time pass). It records the standard exploration metrics (coverage,
mission time, T90/T99, path length, collisions), a coverage trace, the trajectory and the wall
time spent in each stage, and optionally writes a GIF.
"""

from __future__ import annotations

import math
import os
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from semexplore_gym.evaluation.gif import GifOptions, GifStreamWriter, save_gif
from semexplore_gym.evaluation.path_decomposition import PathDecomposition, PathLedger
from semexplore_gym.policies.base import Policy, StepStats

__all__ = [
    "STAGES",
    "GifOptions",
    "GifStreamWriter",
    "MissionResult",
    "make_mission_env",
    "map_observation_for",
    "policy_mission_metrics",
    "run_mission",
    "save_gif",
    "time_to_coverage",
]

#: Stages of the per-stage wall-time split, in the order they are reported.
STAGES: tuple[str, ...] = (
    "env_reset",
    "env_step",
    "map_generation",
    "global_planning",
    "local_planning",
    "policy_other",
    "render",
)


@dataclass
class MissionResult:
    """Outcome of one mission.

    Attributes:
        world: The env's world name.
        policy: The policy's name.
        seed: Seed given to ``env.reset`` and ``policy.reset``.
        coverage: Final coverage (fraction of the reachable free area mapped).
        explored_area_m2: Final free area in the map.
        mission_time_s: Simulated time at the end of the mission.
        self_stopped: True when the policy ended the mission (``policy.done``).
        stop_reason: The policy's reason, or why the env ended it.
        path_length_m: Distance driven.
        collisions: Wall contacts begun during the mission.
        wall_time_s: Wall-clock time of the whole mission (reset, steps, planning, rendering).
        cpu_time_s: CPU time of this process during the mission (equals the wall time on an
            idle machine: everything runs in one thread; robust to other load).
        steps: Env steps taken.
        terminated: The env terminated (coverage goal reached).
        truncated: The env truncated, or ``max_time_s`` was reached.
        t90_s: Simulated time when coverage first reached 0.90 (None if never).
        t99_s: Simulated time when coverage first reached 0.99 (None if never).
        mean_map_generation_ms: Mean wall time of the steps that built a map representation.
        mean_global_planning_ms: Mean wall time of the steps that planned globally.
        n_replans: Steps with a global replan (``StepStats.replanned``).
        stage_time_s: Wall time per stage (:data:`STAGES`).
        coverage_trace: ``(sim_time_s, coverage, explored_area_m2)`` after reset and every step.
        trajectory: ``(steps + 1, 3)`` poses ``x, y, yaw`` of the observations.
        policy_counters: The policy's ``counters`` dict, if it has one.
        policy_metrics: The policy's ``mission_metrics()`` at the end of the mission
            (policy-specific figures for benchmark rows; empty for most policies).
        path_decomposition: Where the path went (:mod:`.path_decomposition`; None for a
            result built elsewhere).
        slam_metrics: With the env's SLAM mode: ``ate_m`` (keyframe position RMSE, no
            alignment: the start pose is shared), ``rpe_m`` (over 1 m of travel),
            ``map_error``, ``loop_closures`` and ``slam_lost`` at the end (:func:`slam_metrics`); empty otherwise.
    """

    world: str
    policy: str
    seed: int | None
    coverage: float
    explored_area_m2: float
    mission_time_s: float
    self_stopped: bool
    stop_reason: str
    path_length_m: float
    collisions: int
    wall_time_s: float
    cpu_time_s: float
    steps: int
    terminated: bool
    truncated: bool
    t90_s: float | None
    t99_s: float | None
    mean_map_generation_ms: float
    mean_global_planning_ms: float
    n_replans: int
    stage_time_s: dict[str, float]
    coverage_trace: list[tuple[float, float, float]] = field(repr=False)
    trajectory: np.ndarray = field(repr=False)
    policy_counters: dict[str, int] = field(default_factory=dict)
    policy_metrics: dict[str, Any] = field(default_factory=dict)
    path_decomposition: PathDecomposition | None = field(default=None, repr=False)
    slam_metrics: dict[str, Any] = field(default_factory=dict)

    @property
    def speedup(self) -> float:
        """Simulated time per wall-clock time (inf for an instant mission)."""
        return self.mission_time_s / self.wall_time_s if self.wall_time_s > 0 else math.inf

    def summary(self) -> dict[str, Any]:
        """JSON-safe scalars (no trace, no trajectory)."""
        return {
            "world": self.world,
            "policy": self.policy,
            "seed": self.seed,
            "coverage": round(float(self.coverage), 6),
            "explored_area_m2": round(float(self.explored_area_m2), 4),
            "mission_time_s": round(float(self.mission_time_s), 3),
            "self_stopped": bool(self.self_stopped),
            "stop_reason": self.stop_reason,
            "path_length_m": round(float(self.path_length_m), 3),
            "collisions": int(self.collisions),
            "wall_time_s": round(float(self.wall_time_s), 3),
            "cpu_time_s": round(float(self.cpu_time_s), 3),
            "steps": int(self.steps),
            "T90_s": self.t90_s,
            "T99_s": self.t99_s,
            "mean_map_generation_ms": round(float(self.mean_map_generation_ms), 3),
            "mean_global_planning_ms": round(float(self.mean_global_planning_ms), 3),
            "n_replans": int(self.n_replans),
            "stage_time_s": {k: round(float(v), 4) for k, v in self.stage_time_s.items()},
            "policy_counters": dict(self.policy_counters),
            **self.slam_metrics,
        }


def make_mission_env(world: str, env_config: Any = None, **kwargs: Any) -> Any:
    """A ``SemanticExplore-v0`` env on ``world`` (``gym.make``; registers the env ids first).

    Args:
        world: World spelling (a name, ``family:key=value,...`` or a map file).
        env_config: Env config (preset name, YAML path, mapping or None).
        **kwargs: Further ``gym.make`` arguments (``overrides``, ``render_mode`` ...).
    """
    import gymnasium as gym

    import semexplore_gym  # noqa: F401  (registers the env ids)

    return gym.make("SemanticExplore-v0", world=world, config=env_config, **kwargs)


def map_observation_for(policy: Any) -> dict[str, Any]:
    """``gym.make`` arguments for a mission env that suit ``policy``.

    A policy whose ``reads_map_in_step_only`` is True (the scripted ones) gets the env's
    read-only live map (``map_observation="shared"``): no per-step copy of the whole map, the
    same missions. The passive env checker is off for it, since its only complaint would be
    that point (successive observations share the map). Any other policy gets the default
    fresh copy per step.
    """
    # A privileged policy (the oracle) gets the true world in reset's info; no other does.
    privileged = {"privileged": True} if getattr(policy, "privileged", False) else {}
    if getattr(policy, "reads_map_in_step_only", False):
        return {"map_observation": "shared", "disable_env_checker": True, **privileged}
    return privileged


def time_to_coverage(trace: list[tuple[float, float, float]], level: float) -> float | None:
    """First simulated time at which the coverage in ``trace`` reached ``level`` (None if never)."""
    for t, c, _ in trace:
        if c >= level - 1e-12:
            return float(t)
    return None


class _MissionLog:
    """What a mission accumulates: stage wall times, planning stats, coverage trace and poses."""

    def __init__(self, obs: dict[str, Any], info: dict[str, Any]) -> None:
        self.stage = dict.fromkeys(STAGES, 0.0)
        self.trace: list[tuple[float, float, float]] = [
            (
                float(info.get("sim_time_s", 0.0)),
                float(info["coverage"]),
                float(info["explored_area_m2"]),
            )
        ]
        self.poses = [np.asarray(obs["pose"], dtype=np.float64).copy()]
        self.map_ms: list[float] = []
        self.glob_ms: list[float] = []
        self.n_replans = 0
        self.steps = 0
        self.ledger = PathLedger.for_mission(obs, info)
        self.slam: dict[str, Any] = {}  # the SLAM figures at the end (slam_metrics)

    def add_policy_stats(self, st: StepStats, act_s: float) -> None:
        """Split one ``act`` call of ``act_s`` wall seconds into stages by its :class:`StepStats`."""
        self.stage["map_generation"] += st.map_generation_ms / 1e3
        self.stage["global_planning"] += st.global_planning_ms / 1e3
        self.stage["local_planning"] += st.local_planning_ms / 1e3
        self.stage["policy_other"] += max(
            0.0,
            act_s - (st.map_generation_ms + st.global_planning_ms + st.local_planning_ms) / 1e3,
        )
        if st.map_generation_ms > 0:
            self.map_ms.append(st.map_generation_ms)
        if st.replanned or st.global_planning_ms > 0:
            self.glob_ms.append(st.global_planning_ms)
        self.n_replans += int(st.replanned)

    def add_step(self, obs: dict[str, Any], info: dict[str, Any]) -> float:
        """Record the state after an env step; returns its simulated time."""
        self.steps += 1
        sim_t = float(info["sim_time_s"])
        self.trace.append((sim_t, float(info["coverage"]), float(info["explored_area_m2"])))
        self.poses.append(np.asarray(obs["pose"], dtype=np.float64).copy())
        self.ledger.after_step(obs, info)
        return sim_t


class _GifRecorder:
    """Grabs a rendered frame every ``every_s`` simulated seconds and streams it to the GIF file
    (one frame in memory at a time, however long the mission); render time goes to ``stage``."""

    def __init__(
        self,
        env: Any,
        policy: Policy,
        every_s: float,
        stage: dict[str, float],
        path: str | os.PathLike,
        fps: float,
    ) -> None:
        self.env = env
        self.policy = policy
        self.every_s = every_s
        self.stage = stage
        self.writer = GifStreamWriter(path, fps=fps)
        self.next_frame_s = 0.0

    @property
    def n_frames(self) -> int:
        return self.writer.n_frames

    def grab(self) -> None:
        tr = time.perf_counter()
        getattr(self.env, "unwrapped", self.env).set_overlay(self.policy.overlay())
        frame = self.env.render()
        if frame is not None:
            self.writer.append(np.asarray(frame))
        self.stage["render"] += time.perf_counter() - tr

    def start(self) -> None:
        self.grab()
        self.next_frame_s = self.every_s

    def after_step(self, sim_t: float) -> None:
        if sim_t >= self.next_frame_s - 1e-9:
            self.grab()
            self.next_frame_s += self.every_s

    def save(self) -> None:
        t_save = time.perf_counter()
        self.writer.close()
        self.stage["render"] += time.perf_counter() - t_save

    def abort(self) -> None:
        self.writer.abort()


def _check_mission_args(env: Any, max_time_s: float | None, gif: GifOptions | None) -> None:
    if max_time_s is not None and not (max_time_s > 0 and math.isfinite(max_time_s)):
        raise ValueError(f"max_time_s must be a positive number or None, got {max_time_s!r}")
    if gif is not None:
        if getattr(env, "render_mode", None) != "rgb_array":
            raise ValueError(
                f"gif needs an env made with render_mode='rgb_array', got render_mode={getattr(env, 'render_mode', None)!r}"
            )
        if not gif.every_s > 0:
            raise ValueError(f"gif.every_s must be positive, got {gif.every_s!r}")


def _gif_recorder(
    env: Any, policy: Policy, gif: GifOptions | None, stage: dict[str, float]
) -> _GifRecorder | None:
    if gif is None:
        return None
    return _GifRecorder(env, policy, gif.every_s, stage, gif.path, gif.fps)


def _end_bar_full(bar: Any) -> None:
    """The mission is over: the bar ends full, at the time reached."""
    if bar is not None:
        bar.total = max(bar.n, 1e-9)
        bar.refresh()


def run_mission(
    env: Any,
    policy: Policy,
    seed: int | None,
    max_time_s: float | None = None,
    progress: bool = False,
    on_step: Callable[[int, dict[str, Any], dict[str, Any], np.ndarray, Policy], None]
    | None = None,
    *,
    gif: GifOptions | None = None,
    ignore_terminated: bool = True,
) -> MissionResult:
    """Run one mission of ``policy`` in ``env``.

    By default the mission ends when the policy stops (``policy.done``), the env truncates or
    ``max_time_s`` passes, not when the env's coverage goal is reached: the same stop as
    ``semexplore explore`` and the benchmark harness, so one world, policy and seed give one
    result everywhere. ``ignore_terminated=False`` ends it at the env's coverage goal instead.

    Args:
        env: A SemanticExplore env (``gym.make`` result, possibly wrapped, raw observations).
        policy: The policy.
        seed: Seed for ``env.reset`` and ``policy.reset``.
        max_time_s: Stop after this much simulated time (None: only the env's own truncation).
        progress: Show a tqdm bar on stderr (simulated seconds, coverage); off by default
            (the CLI turns it on).
        on_step: Called after every step as ``on_step(step, obs, info, action, policy)``.
        gif: Write an animated GIF of the mission (the env needs ``render_mode="rgb_array"``).
        ignore_terminated: Keep going when the env terminates (its coverage goal is reached),
            so that the mission lasts until the policy stops (or the time limit): the mission
            time is then the policy's own (the default). Truncation still ends the mission.
            False: the env's coverage goal ends the mission too.

    Returns:
        The :class:`MissionResult`.

    Raises:
        ValueError: a non-positive ``max_time_s``, or ``gif`` with an env that cannot render
            RGB frames.
    """
    _check_mission_args(env, max_time_s, gif)
    cpu0 = time.process_time()
    wall0 = time.perf_counter()
    obs, info = env.reset(seed=seed, options=None)
    t1 = time.perf_counter()
    log = _MissionLog(obs, info)
    log.stage["env_reset"] = t1 - wall0
    policy.reset(obs, info, seed=seed)
    log.stage["policy_other"] += time.perf_counter() - t1

    world_name = _world_name(env)
    limit_s = max_time_s if max_time_s is not None else math.inf
    recorder = _gif_recorder(env, policy, gif, log.stage)
    bar = _progress_bar(
        progress, limit_s if math.isfinite(limit_s) else None, world_name, policy.name
    )
    try:
        info, terminated, truncated = _drive(
            env, policy, obs, info, log, recorder, bar, on_step, limit_s, ignore_terminated
        )
        _end_bar_full(bar)
    except BaseException:
        if recorder is not None:
            recorder.abort()
        raise
    finally:
        if bar is not None:
            bar.close()
    reason = _stop_reason(policy, terminated, truncated, ignore_terminated, max_time_s)
    wall = time.perf_counter() - wall0
    if recorder is not None:
        recorder.save()
        wall = time.perf_counter() - wall0
    cpu = time.process_time() - cpu0
    return _mission_result(
        world_name, policy, seed, info, (terminated, truncated), reason, (wall, cpu), log
    )


def slam_metrics(env: Any, self_stopped: bool = False) -> dict[str, Any]:
    """The SLAM figures of the env's mission so far (``ate_m``, ``odom_ate_m``,
    ``map_error``, ``loop_closures``, ``slam_lost``, ``slam_false_stop``;
    :meth:`~semexplore_gym.envs.slam_mode.SlamMode.metrics`), or ``{}`` when the env does not
    run SLAM. ``self_stopped``: the policy ended the mission (a stop below the env's coverage
    goal is then checked for a SLAM artefact)."""
    unwrapped = getattr(env, "unwrapped", env)
    slam = getattr(unwrapped, "slam", None)
    if slam is None:
        return {}
    grid = unwrapped.grid
    coverage = grid.n_free_in_mask / max(1, grid.n_mask_cells)
    short = self_stopped and coverage < unwrapped.config.episode.coverage_goal
    return slam.metrics(grid, stopped_short=short)


def _mission_result(
    world_name: str,
    policy: Policy,
    seed: int | None,
    info: dict[str, Any],
    ended: tuple[bool, bool],
    reason: str,
    clocks: tuple[float, float],
    log: _MissionLog,
) -> MissionResult:
    """The :class:`MissionResult` of a finished mission (``ended``: terminated, truncated;
    ``clocks``: wall and CPU seconds)."""
    terminated, truncated = ended
    return MissionResult(
        world=world_name,
        policy=policy.name,
        seed=seed,
        coverage=float(info["coverage"]),
        explored_area_m2=float(info["explored_area_m2"]),
        mission_time_s=float(info["sim_time_s"]),
        self_stopped=bool(policy.done),
        stop_reason=reason,
        path_length_m=float(info["path_length_m"]),
        collisions=int(info["collisions"]),
        wall_time_s=clocks[0],
        cpu_time_s=clocks[1],
        steps=log.steps,
        terminated=bool(terminated),
        truncated=bool(truncated or (not terminated and not policy.done)),
        t90_s=time_to_coverage(log.trace, 0.90),
        t99_s=time_to_coverage(log.trace, 0.99),
        mean_map_generation_ms=float(np.mean(log.map_ms)) if log.map_ms else 0.0,
        mean_global_planning_ms=float(np.mean(log.glob_ms)) if log.glob_ms else 0.0,
        n_replans=log.n_replans,
        stage_time_s=log.stage,
        coverage_trace=log.trace,
        trajectory=np.asarray(log.poses),
        policy_counters=dict(getattr(policy, "counters", {}) or {}),
        policy_metrics=policy_mission_metrics(policy),
        path_decomposition=log.ledger.finish(),
        slam_metrics=log.slam,
    )


def policy_mission_metrics(policy: Any) -> dict[str, Any]:
    """The policy's ``mission_metrics()`` (empty when it has none)."""
    hook = getattr(policy, "mission_metrics", None)
    metrics = dict(hook() or {}) if callable(hook) else {}
    return metrics


def _drive(
    env: Any,
    policy: Policy,
    obs: dict[str, Any],
    info: dict[str, Any],
    log: _MissionLog,
    gif: _GifRecorder | None,
    bar: Any,
    on_step: Callable[[int, dict[str, Any], dict[str, Any], np.ndarray, Policy], None] | None,
    limit_s: float,
    ignore_terminated: bool,
) -> tuple[dict[str, Any], bool, bool]:
    """The act / step loop of :func:`run_mission`; returns the last info, terminated, truncated."""
    dt_s = float(info.get("dt_s", 0.2))
    terminated = truncated = False
    if gif is not None:
        gif.start()
    while True:
        ta = time.perf_counter()
        action = policy.act(obs, info)
        tb = time.perf_counter()
        st = policy.last_stats
        log.add_policy_stats(st, tb - ta)
        if policy.done:
            break
        log.ledger.before_step(_drive_intent(policy), obs)
        obs, _, terminated, truncated, info = env.step(action)
        log.stage["env_step"] += time.perf_counter() - tb
        sim_t = log.add_step(obs, info)
        if on_step is not None:
            on_step(log.steps, obs, info, action, policy)
        if gif is not None:
            gif.after_step(sim_t)
        if bar is not None:
            bar.update(dt_s)
            if log.steps % 25 == 0:
                shown = {"coverage": f"{info['coverage']:.3f}"}
                if st.extra.get("mode"):  # only policies that have modes report one
                    shown["mode"] = str(st.extra["mode"])
                bar.set_postfix(shown, refresh=False)
        if (terminated and not ignore_terminated) or truncated or sim_t >= limit_s - 1e-9:
            break
    if gif is not None:
        gif.grab()
    log.slam = slam_metrics(env, self_stopped=bool(policy.done))
    return info, terminated, truncated


def _drive_intent(policy: Any) -> Any:
    """The policy's ``drive_intent()`` (None for an object without one)."""
    hook = getattr(policy, "drive_intent", None)
    return hook() if callable(hook) else None


def _world_name(env: Any) -> str:
    unwrapped = getattr(env, "unwrapped", env)
    return str(
        getattr(getattr(unwrapped, "world", None), "name", getattr(unwrapped, "world_spec", "?"))
    )


def _stop_reason(
    policy: Policy,
    terminated: bool,
    truncated: bool,
    ignore_terminated: bool,
    max_time_s: float | None,
) -> str:
    if policy.done:
        return policy.stop_reason or "policy done"
    if terminated and not ignore_terminated:
        return "env terminated (coverage goal reached)"
    if truncated:
        return "env truncated (episode time limit)"
    return f"max_time_s reached ({max_time_s:g} s)"


def _progress_bar(enabled: bool, total_s: float | None, world: str, policy: str) -> Any:
    if not enabled:
        return None
    try:
        from tqdm import tqdm
    except ImportError:  # pragma: no cover - tqdm is a dependency
        return None
    return tqdm(
        total=total_s,
        unit="sim s",
        desc=f"{policy} on {Path(world).name if os.sep in world else world}",
        file=sys.stderr,
        leave=False,
        bar_format="{desc}: {percentage:3.0f}%|{bar}| {n:.0f}/{total:.0f} sim s [{elapsed}<{remaining}{postfix}]"
        if total_s is not None
        else "{desc}: {n:.0f} sim s [{elapsed}{postfix}]",
        dynamic_ncols=True,
    )
