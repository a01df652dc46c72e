"""Team missions and the team benchmark: ``semexplore benchmark --robots 1,2,3``.

A team mission runs a :class:`~semexplore_gym.policies.team.TeamPolicy` in
``SemanticExploreMulti-v0`` until the team stops itself (no robot has a reachable frontier)
or the time limit: the benchmark sets ``team.end_on_coverage=false``, so that, as in the
single-robot benchmark, the mission time is the team's own and ``self_stopped`` says whether
the team or the clock ended it. Each seed draws robot 0's start in free space (the same
for every team size and policy: it is the first draw of the env's RNG) and the teammates near
it, so the rows of one seed compare teams on the same world and start.

Columns of ``runs.csv`` (one row per mission):

================== ==========================================================================
world, policy      the world spelling and the team policy
n_robots, seed     team size and seed
coverage           team coverage at the end
mission_time_s     simulated time until the team stopped (or the limit)
self_stopped       the team stopped itself; ``stop_reason`` says why (the team's reason, or
                   the time limit that ended the mission)
T90_s, T99_s       first simulated time at 0.90 / 0.99 coverage (empty if never)
path_total_m       distance driven by all robots; ``path_per_robot_m`` each, ``;``-separated
overlap_ratio      Explore-Bench: area scanned by more than one robot / area explored
robot_collisions   robot-robot contacts begun; ``contacts`` all contacts (walls included)
wall_time_s        wall-clock time of the mission
lower_bound_s      a certified lower bound on any team's T99 from these starts (this team
                   size; :mod:`semexplore_gym.evaluation.team_bound`), empty where none
ate_m ...          with ``--env-config slam`` (each robot its own SLAM): the robots' mean ATE
                   and odometry ATE, the merged SLAM map's error, all robots' loop closures
                   and lost events (:data:`SLAM_COLUMNS`; empty without SLAM)
================== ==========================================================================

The team oracle (policy ``oracle``, ``--oracle``) runs in a privileged env (the true world in
its ``info`` at reset); every other team runs in a plain one.

``summary.md`` and ``team_speedup.png`` are written by
:mod:`semexplore_gym.evaluation.team_report`.
"""

from __future__ import annotations

import csv
import json
import math
import sys
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from semexplore_gym.evaluation.team_report import write_team_plot, write_team_summary

COLUMNS = (
    "world",
    "policy",
    "n_robots",
    "seed",
    "coverage",
    "mission_time_s",
    "self_stopped",
    "stop_reason",
    "T90_s",
    "T99_s",
    "path_total_m",
    "path_per_robot_m",
    "overlap_ratio",
    "robot_collisions",
    "contacts",
    "steps",
    "wall_time_s",
    "lower_bound_s",
)
#: The env overrides of every team benchmark mission (before its start setting, time limit and
#: ``--env-set``): only the team's own stop or the time limit ends a mission.
MISSION_OVERRIDES = ("episode.coverage_goal=1.0", "team.end_on_coverage=false")
#: The SLAM columns (:meth:`~semexplore_gym.envs.team_slam.TeamSlam.metrics`), after
#: :data:`COLUMNS`; a ``runs.csv`` written before them keeps its own header when resumed.
SLAM_COLUMNS = ("ate_m", "odom_ate_m", "map_error", "loop_closures", "slam_lost_events")


@dataclass
class TeamMissionResult:
    """One team mission's figures (the columns of ``runs.csv``, see the module docstring)."""

    world: str
    policy: str
    n_robots: int
    seed: int | None
    coverage: float
    mission_time_s: float
    self_stopped: bool
    stop_reason: str
    T90_s: float | None
    T99_s: float | None
    path_total_m: float
    path_per_robot_m: list[float]
    overlap_ratio: float
    robot_collisions: int
    contacts: int
    steps: int
    wall_time_s: float
    lower_bound_s: float | None = None
    coverage_trace: list[tuple[float, float]] = field(default_factory=list, repr=False)
    slam: dict[str, Any] = field(default_factory=dict, repr=False)

    def row(self) -> dict[str, Any]:
        d = asdict(self)
        d.pop("coverage_trace")
        d.update({k: self.slam.get(k) for k in SLAM_COLUMNS})
        d.pop("slam")
        d["path_per_robot_m"] = ";".join(f"{v:.3f}" for v in self.path_per_robot_m)
        for k in ("coverage", "overlap_ratio"):
            d[k] = round(float(d[k]), 6)
        for k in ("mission_time_s", "path_total_m", "wall_time_s"):
            d[k] = round(float(d[k]), 3)
        if d["lower_bound_s"] is not None:
            d["lower_bound_s"] = round(float(d["lower_bound_s"]), 3)
        return d


def _first_time(trace: list[tuple[float, float]], level: float) -> float | None:
    for t, c in trace:
        if c >= level - 1e-12:
            return float(t)
    return None


def run_team_mission(
    env: Any,
    team: Any,
    seed: int | None,
    max_time_s: float | None = None,
    gif_path: str | Path | None = None,
    gif_every_s: float = 2.0,
) -> TeamMissionResult:
    """Run ``team`` in ``env`` (a ``SemanticExploreMulti-v0``) from ``reset(seed=seed)`` until
    the team stops itself, the env ends the episode, or ``max_time_s`` of simulated time.

    With ``gif_path`` (the env made with ``render_mode="rgb_array"``) a team GIF is written,
    one frame every ``gif_every_s`` simulated seconds, goals and paths from the policy.
    """
    wall0 = time.perf_counter()
    obs, infos = env.reset(seed=seed)
    team.reset(obs, infos, seed=seed)
    first = env.possible_agents[0]
    trace = [(0.0, float(infos[first]["coverage"]))]
    limit = math.inf if max_time_s is None else float(max_time_s)
    frames: list[np.ndarray] = []
    next_frame_s = 0.0
    info = infos[first]
    steps = 0
    terminated = truncated = False
    while env.agents:
        actions = team.act(obs, infos)
        if team.done:
            break
        obs, _, terms, truncs, infos = env.step(actions)
        terminated, truncated = bool(terms[first]), bool(truncs[first])
        steps += 1
        info = infos[first]
        trace.append((float(info["sim_time_s"]), float(info["coverage"])))
        if gif_path is not None and info["sim_time_s"] >= next_frame_s - 1e-9:
            for agent, overlay in team.overlays().items():
                env.set_overlay(agent, overlay)
            frames.append(env.render())
            next_frame_s += gif_every_s
        if info["sim_time_s"] >= limit - 1e-9:
            break
    if gif_path is not None:
        from semexplore_gym.evaluation.rollout import save_gif

        frames.append(env.render())
        save_gif(frames, gif_path, fps=10.0)
    paths = [float(v) for v in env.path_length_m]
    reason = _stop_reason(team, terminated, truncated, max_time_s)
    return TeamMissionResult(
        world=str(getattr(env.world, "name", env.world_spec)),
        policy=team.name,
        n_robots=len(env.possible_agents),
        seed=seed,
        coverage=float(info["coverage"]),
        mission_time_s=float(info["sim_time_s"]),
        self_stopped=bool(team.done),
        stop_reason=reason,
        T90_s=_first_time(trace, 0.90),
        T99_s=_first_time(trace, 0.99),
        path_total_m=float(sum(paths)),
        path_per_robot_m=paths,
        overlap_ratio=float(env.overlap_ratio()),
        robot_collisions=int(env.sim.robot_collisions),
        contacts=int(sum(env.sim.collisions)),
        steps=steps,
        wall_time_s=time.perf_counter() - wall0,
        coverage_trace=trace,
        slam=env.slam.metrics(env.grid) if getattr(env, "slam", None) is not None else {},
    )


def _stop_reason(team: Any, terminated: bool, truncated: bool, max_time_s: float | None) -> str:
    """Why a team mission ended, in the single-robot benchmark's words."""
    if team.done:
        return str(team.stop_reason or "team done")
    if terminated:
        return "env terminated (coverage goal reached)"
    if truncated:
        return "env truncated (episode time limit)"
    return f"max_time_s reached ({max_time_s} s)"


@dataclass(frozen=True)
class TeamBenchmarkConfig:
    """What :func:`run_team_benchmark` runs: every (world, policy, robots, seed) mission.

    ``time_limits`` gives some worlds their own limit (a suite's), else ``max_time_s``.
    ``team.end_on_coverage`` is set to false (the team, not the env's coverage goal, ends a
    mission) and ``episode.random_start`` to true unless ``fixed_start``; ``env_overrides``
    come last. ``workers`` > 1 runs missions in that many processes (``backend="ray"``: on
    Ray, at ``ray_address`` or a local one); rows are the same either way.
    """

    worlds: tuple[str, ...]
    policies: tuple[str, ...]
    robot_counts: tuple[int, ...]
    seeds: tuple[int, ...]
    out: Path
    max_time_s: float | None = None
    env_config: Any = None
    env_overrides: tuple[str, ...] = ()
    fixed_start: bool = False
    progress: bool = True
    time_limits: dict[str, float | None] = field(default_factory=dict)
    workers: int = 1
    backend: str = "process"
    ray_address: str | None = None


@dataclass(frozen=True)
class TeamTask:
    """One team mission: ``world`` (its ``seed=*`` already replaced), the team policy spec,
    the team size, the seed, the time limit and the env's config and overrides."""

    world: str
    policy: str
    n_robots: int
    seed: int
    max_time_s: float | None
    env_config: Any
    overrides: tuple[str, ...]
    lower_bound: bool = True


#: Per process: the last env a team task made, reused while tasks share its world, size and
#: config (a reset with the task's seed makes every mission independent of the one before).
_ENV_CACHE: dict[str, Any] = {}


def run_team_task(task: TeamTask) -> dict[str, Any]:
    """The ``runs.csv`` row of one team mission (runs in this process or in a worker)."""
    from semexplore_gym.envs.multi_robot import make_multi
    from semexplore_gym.policies.team import make_team_policy

    team = make_team_policy(task.policy)
    privileged = bool(getattr(team, "privileged", False))
    key = (task.world, task.n_robots, repr(task.env_config), task.overrides, privileged)
    if _ENV_CACHE.get("key") != key:
        _ENV_CACHE.clear()
        _ENV_CACHE.update(
            key=key,
            env=make_multi(
                world=task.world,
                config=task.env_config,
                overrides=list(task.overrides),
                n_robots=task.n_robots,
                privileged=privileged,
            ),
        )
    env = _ENV_CACHE["env"]
    result = run_team_mission(env, team, task.seed, task.max_time_s)
    if task.lower_bound:
        from semexplore_gym.evaluation.team_bound import team_lower_bound_s

        result.lower_bound_s = team_lower_bound_s(env, (task.world, task.seed))
    row = result.row()
    row["world"] = task.world  # the spelling, as resume reads it back
    return row


def team_tasks(config: TeamBenchmarkConfig) -> list[TeamTask]:
    """Every mission of ``config``, world-major, then team size, policy and seed."""
    c = config
    base = [*MISSION_OVERRIDES, f"episode.random_start={'false' if c.fixed_start else 'true'}"]

    def overrides(limit_s: float | None) -> tuple[str, ...]:
        # The env's own limit must not cut a mission short of its world's (a suite's limits
        # exceed the env's default); the user's overrides win.
        own = [f"episode.max_time_s={limit_s!r}"] if limit_s is not None else []
        return (*base, *own, *c.env_overrides)

    limits = {w: (c.time_limits or {}).get(w, c.max_time_s) for w in c.worlds}
    return [
        TeamTask(
            world=world.replace("seed=*", f"seed={seed}"),
            policy=spec,
            n_robots=int(n),
            seed=int(seed),
            max_time_s=limits[world],
            env_config=c.env_config,
            overrides=overrides(limits[world]),
        )
        for world in c.worlds
        for n in c.robot_counts
        for spec in c.policies
        for seed in c.seeds
    ]


def run_team_benchmark(config: TeamBenchmarkConfig) -> dict[str, Any]:
    """Every mission of ``config``, appended to ``config.out/runs.csv`` as it ends.

    Rerunning the same command skips the missions already in ``runs.csv`` (resumes). A
    mission that raises is reported on stderr and in ``failed``; the others go on.
    """
    from semexplore_gym.evaluation.backends import mission_stream
    from semexplore_gym.evaluation.progress_bar import MissionsBar
    from semexplore_gym.policies.team import make_team_policy

    c = config
    out_dir = Path(c.out)
    out_dir.mkdir(parents=True, exist_ok=True)
    csv_path = out_dir / "runs.csv"
    done: set[tuple[str, str, int, int]] = set()
    if csv_path.exists():
        with csv_path.open(newline="") as f:
            for r in csv.DictReader(f):
                done.add((r["world"], r["policy"], int(r["n_robots"]), int(r["seed"])))
    names = {spec: make_team_policy(spec).name for spec in c.policies}
    tasks = team_tasks(c)
    todo = [t for t in tasks if (t.world, names[t.policy], t.n_robots, t.seed) not in done]
    failed: list[tuple[tuple[str, str, int, int], str]] = []
    _upgrade_header(csv_path)
    write_header = not csv_path.exists()
    header = list((*COLUMNS, *SLAM_COLUMNS))
    if not write_header:
        with csv_path.open(newline="") as f:
            header = next(csv.reader(f), header)
    bar = MissionsBar(c.progress, total=len(tasks), done=len(tasks) - len(todo))
    stream = mission_stream(todo, c.backend, c.workers, c.ray_address, run_team_task, run_team_task)
    with csv_path.open("a", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=header, extrasaction="ignore")
        if write_header:
            writer.writeheader()
        try:
            for task, row in stream:
                bar.finished(task)
                if isinstance(row, BaseException):
                    key = (task.world, task.policy, task.n_robots, task.seed)
                    failed.append((key, f"{type(row).__name__}: {row}"))
                    print(f"mission {key} failed: {failed[-1][1]}", file=sys.stderr)
                    continue
                writer.writerow(row)
                f.flush()
        finally:
            bar.close()
    return {
        "ran": len(todo) - len(failed),
        "skipped": len(tasks) - len(todo),
        "failed": failed,
        "runs": str(csv_path),
    }


def _upgrade_header(csv_path: Path) -> None:
    """A ``runs.csv`` from before a column was added gets the column (empty) so resumed rows
    line up with its header."""
    if not csv_path.exists():
        return
    with csv_path.open(newline="") as f:
        reader = csv.DictReader(f)
        if reader.fieldnames is None or set(COLUMNS) <= set(reader.fieldnames):
            return
        fieldnames = [*COLUMNS, *(c for c in SLAM_COLUMNS if c in reader.fieldnames)]
        rows = list(reader)
    with csv_path.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=fieldnames, restval="", extrasaction="ignore")
        writer.writeheader()
        writer.writerows(rows)


@dataclass(frozen=True)
class TeamStudyRequest:
    """``semexplore benchmark --robots N[,M...]`` as typed values (the CLI builds it).

    ``policies`` are team policy names (the single-robot default list means "the usual
    comparison": semantic, coordinated, independent); ``suite`` (comma-separated suite names)
    replaces ``worlds`` and sets the time limits; ``runs`` of None means 5 (or the suites').
    ``command`` is the command line written to the manifest.
    """

    robot_counts: tuple[int, ...]
    policies: tuple[str, ...]
    worlds: tuple[str, ...]
    out: Path
    seed0: int = 0
    runs: int | None = None
    suite: str | None = None
    max_time_s: float | None = None
    env_config: Any = None
    env_overrides: tuple[str, ...] = ()
    fixed_start: bool = False
    progress: bool = True
    command: str = ""
    workers: int = 1
    backend: str = "process"
    ray_address: str | None = None
    plots: bool = True


def run_team_study(req: TeamStudyRequest) -> dict[str, Any]:
    """Run the team benchmark of ``req`` and write ``manifest.json`` and ``summary.md``.

    Returns:
        ``ran``, ``skipped``, ``failed`` (a count) and ``summary`` (the path of
        ``summary.md``), what ``semexplore benchmark --robots`` prints.
    """
    from semexplore_gym.policies.team import make_team_policy

    counts = list(req.robot_counts)
    if not counts or any(not 1 <= c <= 8 for c in counts):
        raise ValueError(f"--robots must be team sizes in 1..8, got {counts!r}")
    policies = list(req.policies)
    if policies == ["semantic", "frontier", "nearest"]:
        # The single-robot default means "the usual comparison".
        policies = ["semantic", "coordinated", "independent"]
    for p in policies:
        try:
            make_team_policy(p)  # an unknown name or a bad bracket fails before any mission
        except ValueError as e:
            raise ValueError(f"--policies with --robots: {e}") from None
    time_limits: dict[str, float | None] = {}
    runs = req.runs or 5
    worlds = list(req.worlds)
    if req.suite:
        worlds, time_limits, suite_runs = _suite_worlds(req.suite, req.max_time_s)
        runs = req.runs or suite_runs
    if not worlds:
        raise ValueError("--worlds is empty")
    seeds = list(range(req.seed0, req.seed0 + runs))
    out_dir = Path(req.out)
    out_dir.mkdir(parents=True, exist_ok=True)
    _record_run(
        out_dir / "manifest.json",
        {
            "command": req.command,
            "worlds": worlds,
            "policies": policies,
            "robots": counts,
            "seeds": seeds,
            "max_time_s": req.max_time_s,
            "suite": req.suite,
            "env_overrides": list(req.env_overrides),
        },
    )
    res = run_team_benchmark(
        TeamBenchmarkConfig(
            worlds=tuple(worlds),
            policies=tuple(policies),
            robot_counts=tuple(counts),
            seeds=tuple(seeds),
            out=out_dir,
            max_time_s=req.max_time_s,
            env_config=req.env_config,
            env_overrides=tuple(req.env_overrides),
            fixed_start=req.fixed_start,
            progress=req.progress,
            workers=req.workers,
            backend=req.backend,
            ray_address=req.ray_address,
            time_limits=time_limits,
        )
    )
    summary = write_team_summary(out_dir)
    if req.plots:
        write_team_plot(out_dir)
    return {**res, "failed": len(res["failed"]), "summary": str(summary)}


def _record_run(path: Path, entry: dict[str, Any]) -> None:
    """Add ``entry`` to the ``runs`` of the manifest at ``path``: several commands may share an
    output directory (one per world family, say), and ``summary.md`` covers all their rows."""
    runs: list[dict[str, Any]] = []
    if path.exists():
        try:
            old = json.loads(path.read_text())
        except json.JSONDecodeError:
            old = {}
        runs = old.get("runs", [old] if "command" in old else [])
    if entry not in runs:
        runs.append(entry)
    path.write_text(json.dumps({"runs": runs}, indent=2))


def _suite_worlds(
    names: str, max_time_s: float | None
) -> tuple[list[str], dict[str, float | None], int]:
    """The worlds of comma-separated suites, each world's time limit (``max_time_s`` wins) and
    the largest of the suites' run counts."""
    from semexplore_gym.evaluation.suites import load_suite, world_time_limit_s
    from semexplore_gym.maps import make_world

    worlds: list[str] = []
    limits: dict[str, float | None] = {}
    runs = 1
    for name in [n.strip() for n in names.split(",") if n.strip()]:
        suite = load_suite(name)
        runs = max(runs, suite.runs)
        for entry in suite.worlds:
            worlds.append(entry.world)
            if max_time_s is not None:
                limits[entry.world] = max_time_s
                continue
            w = make_world(entry.world.replace("seed=*", "seed=0"))
            area = float(w.free_mask.sum()) * w.free_geometry.resolution_m**2
            limits[entry.world] = world_time_limit_s(suite, entry, area)
    return worlds, limits, runs
