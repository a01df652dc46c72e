"""``SemanticExploreMulti-v0``: a team of TurtleBot3s explores one building (PettingZoo ParallelEnv).

``pip install "semexplore-gym[multi]"`` adds PettingZoo::

    from semexplore_gym.envs.multi_robot import make_multi
    env = make_multi("SemanticExploreMulti-v0", world="office:seed=1", n_robots=3)
    observations, infos = env.reset(seed=0)
    while env.agents:
        actions = {a: env.action_space(a).sample() for a in env.agents}
        observations, rewards, terminations, truncations, infos = env.step(actions)
"""

from __future__ import annotations

import math
import os
from typing import Any

import numpy as np
from gymnasium import spaces
from gymnasium.utils import seeding

from semexplore_gym.config.extras import MissingExtraError
from semexplore_gym.core.coverage_tour.problem import PRIVILEGED_INFO_KEY
from semexplore_gym.core.grid import GridGeometry, wrap_angle_rad
from semexplore_gym.core.mapping.disc_cast import DiscObstacles
from semexplore_gym.core.mapping.map_merge import merge_grids
from semexplore_gym.core.mapping.occupancy_grid import OccupancyGrid
from semexplore_gym.core.mapping.odometry import OdometryDrift
from semexplore_gym.core.mapping.raycast import SegmentIndex
from semexplore_gym.core.mapping.scan_fusion import ScanFootprint
from semexplore_gym.core.worlds.geometry import segment_distance_field
from semexplore_gym.core.worlds.world import World
from semexplore_gym.envs.coverage_mask import coverage_mask
from semexplore_gym.envs.env_config import EnvConfig, load_env_config
from semexplore_gym.envs.multi_robot_config import (
    TeamParams,
    load_team_params,
    split_team_overrides,
)
from semexplore_gym.envs.semantic_explore import SemanticExploreEnv, is_unseeded_procedural
from semexplore_gym.envs.static_info import static_info_of
from semexplore_gym.envs.team_slam import TeamSlam
from semexplore_gym.maps import make_world
from semexplore_gym.sim.lidar import Lidar
from semexplore_gym.sim.team import TeamSim, sense_with_teammates

try:
    from pettingzoo import ParallelEnv
except ModuleNotFoundError as e:  # PettingZoo is the multi extra
    raise MissingExtraError(
        "SemanticExploreMulti-v0 (the multi-robot env)", "multi", e.name or "pettingzoo"
    ) from e

ENV_ID = "SemanticExploreMulti-v0"
#: Per-agent ``info`` numbers besides ``reward_terms`` (see ``_agent_info``).
AGENT_INFO_NUMBERS = (
    "coverage",
    "explored_area_m2",
    "collisions",
    "sim_time_s",
    "path_length_m",
    "robot_collisions",
)


class SemanticExploreMultiEnv(ParallelEnv):
    """A team of 1 to 8 TurtleBot3 Burgers explores a building together.

    ## Description
    ``SemanticExplore-v0`` for a team: the robots drive in one pymunk space (they collide with
    the walls and with each other), each scans with its own LiDAR (which sees the other robots'
    bodies) and the scans are fused into a map shared by the team (or one map per robot, merged
    within a communication range: ``team.map_sharing``). Agents are ``robot_0`` ...
    ``robot_{n-1}``. With one robot every observation, reward and ``info`` number equals
    ``SemanticExplore-v0``'s for the same seed, start and actions (tested): the step is the
    single-robot env's chain per robot (scale action, simulate, odometry, scan and map, reward
    terms), with the same random draws in the same order.

    ## Action Space (per agent)
    ``Box(-1, 1, (2,), float32)``: ``[v, omega]``, scaled, clipped and checked as in
    ``SemanticExplore-v0``. An agent missing from the ``actions`` dict stands still.

    ## Observation Space (per agent)
    ``Dict``:

    =========  ==============  =======  ==================================================
    key        shape           dtype    meaning
    =========  ==============  =======  ==================================================
    map        (H, W)          uint8    the team map (``"range"`` sharing: the robot's own)
    pose       (3,)            float32  own x, y, yaw (m, m, rad), map frame
    scan       (n_beams,)      float32  own LiDAR ranges (m), teammates included
    teammates  (n - 1, 3)      float32  the other robots' poses, in agent order without self
    =========  ==============  =======  ==================================================

    With ``"team"`` sharing and two or more robots every agent's ``map`` is the same read-only
    snapshot of the team map (one copy per step, not one per agent; ``np.array(...)`` gives a
    writable copy). The team shares one map frame (relative start poses known). Poses are the ones the maps
    are built with (odometry estimates under odometry noise). Teammates' poses are always
    known (they are small messages; only maps are limited by ``comm_range_m``).

    ## Rewards (per agent)
    The single-robot terms for this robot: ``free_area_change`` (m^2 its scan added to its map:
    the team map, robots fused in agent order, or its own map), ``time``, ``collision`` (1 when
    a new contact with a wall *or a teammate* begins); plus ``team`` = ``team.team_reward_weight``
    x the free area the other robots added to the team map this step (0 with one robot).

    ## Starting State
    Robot 0 starts where ``SemanticExplore-v0`` would (``options["start_pose"]``,
    ``episode.start_pose``, the world's start, or sampled). Teammates start at free poses (at
    least ``radius + episode.start_clearance_margin_m`` from walls, ``team.start_gap_m``
    between robots) drawn from the env's RNG: within ``team.start_spread_m`` of robot 0
    (``team.start="near"``) or anywhere robot 0 can reach (``"spread"``). ``options
    ["start_poses"]`` (one pose per robot) sets them all.

    ## Episode End
    All agents terminate together when the team's coverage (the union of every scan, over the
    reachable free space from robot 0's start) reaches ``episode.coverage_goal`` (unless
    ``team.end_on_coverage`` is false), and are truncated together at ``episode.max_time_s``.

    ## Arguments
    ``world``, ``config``, ``render_mode`` as ``SemanticExplore-v0``; ``overrides``: its
    ``section.key=value`` strings plus ``team.key=value`` for :class:`TeamParams`; ``team``:
    None, a mapping, a YAML path or :class:`TeamParams`; ``n_robots``: shortcut for
    ``team.n_robots``; ``privileged`` (False by default) as ``SemanticExplore-v0``'s: True puts
    the ground truth in each agent's ``info`` of ``reset`` (``info["privileged_world"]``, that
    agent's own start pose in it), for the team oracle only.

    ## Info (per agent)
    The single env's static entries (``map_geometry``, ``robot``, ``lidar``, ``dt_s``), then
    ``coverage`` (team), ``explored_area_m2`` (this agent's map), ``collisions`` (this robot's
    contacts), ``sim_time_s``, ``path_length_m`` (this robot's), ``robot_collisions`` (robot-robot
    contacts of the team so far), ``reward_terms``; with SLAM also this robot's ``slam_pose``,
    ``slam_pose_error_m``, ``loop_closures``, ``slam_lost``, ``slam_lost_events`` and
    ``slam_degenerate_matches``.

    ## SLAM
    With ``slam.enabled`` (``config="slam"``) each robot runs its own SLAM on its own drifting
    odometry and scans, the observed ``map`` is the merge of the robots' SLAM maps and each
    ``pose`` the robot's SLAM estimate; coverage and rewards stay on the map fused at the true
    poses (:mod:`~semexplore_gym.envs.team_slam`; ``team.map_sharing: team`` only).

    ## Version History
    - v0: initial version; later the ``privileged`` option (off by default; nothing changes
      without it).
    """

    metadata: dict[str, Any] = {"name": ENV_ID, "render_modes": ["rgb_array"], "render_fps": 5}

    def __init__(
        self,
        world: str | os.PathLike | World = "maze1",
        config: EnvConfig | str | os.PathLike | dict | None = None,
        overrides: list[str] | None = None,
        team: TeamParams | str | os.PathLike | dict | None = None,
        n_robots: int | None = None,
        render_mode: str | None = None,
        privileged: bool = False,
    ) -> None:
        self.privileged = bool(privileged)
        team_overrides, env_overrides = split_team_overrides(overrides)
        if n_robots is not None:
            team_overrides.append(f"n_robots={int(n_robots)}")
        self.team: TeamParams = load_team_params(team, team_overrides)
        self.config: EnvConfig = load_env_config(config, env_overrides)
        if render_mode is not None and render_mode not in self.metadata["render_modes"]:
            raise ValueError(
                f"render_mode {render_mode!r} is not one of {self.metadata['render_modes']}"
            )
        self.render_mode = render_mode
        cfg = self.config
        self.world_spec = world
        self._randomise_world = is_unseeded_procedural(world)
        self.world: World = (
            world if isinstance(world, World) else make_world(world, rng=np.random.default_rng(0))
        )
        self.map_geometry: GridGeometry = GridGeometry.covering(
            *self.world.bounds_m, cfg.mapping.resolution_m, cfg.mapping.margin_m
        )
        self.n_robots = int(self.team.n_robots)
        self.possible_agents = [f"robot_{i}" for i in range(self.n_robots)]
        # Per robot, the indices of its teammates in agent order.
        self._others = [
            np.array([j for j in range(self.n_robots) if j != i], dtype=np.intp)
            for i in range(self.n_robots)
        ]
        self.agents: list[str] = []
        self._build_world_state()
        self._build_spaces()
        self._static_info = static_info_of(cfg, self.map_geometry)
        self._area_per_cell_m2 = cfg.mapping.resolution_m**2
        self._np_random: np.random.Generator | None = None
        self._started = False
        self._overlays: list[dict[str, Any]] = [{} for _ in range(self.n_robots)]
        self._renderer: Any = None

    # ----------------------------------------------------------------- set-up
    def _build_spaces(self) -> None:
        """Per-agent observation (map, pose, scan, teammates) and action spaces."""
        cfg = self.config
        h, w = self.map_geometry.shape
        big = np.float32(1e6)
        pose_low = np.array([-big, -big, -np.pi], dtype=np.float32)
        pose_high = np.array([big, big, np.pi], dtype=np.float32)
        self._observation_spaces = {
            a: spaces.Dict(
                {
                    "map": spaces.Box(0, 255, shape=(h, w), dtype=np.uint8),
                    "pose": spaces.Box(pose_low, pose_high, dtype=np.float32),
                    "scan": spaces.Box(
                        0.0, cfg.lidar.max_range_m, shape=(cfg.lidar.n_beams,), dtype=np.float32
                    ),
                    "teammates": spaces.Box(
                        np.tile(pose_low, (self.n_robots - 1, 1)),
                        np.tile(pose_high, (self.n_robots - 1, 1)),
                        dtype=np.float32,
                    ),
                }
            )
            for a in self.possible_agents
        }
        self._action_spaces = {
            a: spaces.Box(-1.0, 1.0, shape=(2,), dtype=np.float32) for a in self.possible_agents
        }

    @property
    def np_random(self) -> np.random.Generator:
        """The env's random source (seeded by ``reset(seed=...)``, as gymnasium envs)."""
        if self._np_random is None:
            self._np_random, _ = seeding.np_random()
        return self._np_random

    def observation_space(self, agent: str) -> spaces.Dict:
        return self._observation_spaces[agent]

    def action_space(self, agent: str) -> spaces.Box:
        return self._action_spaces[agent]

    def _build_world_state(self) -> None:
        cfg = self.config
        self.sim = TeamSim(self.world, cfg.robot, cfg.physics, self.n_robots)
        self.lidar = Lidar(cfg.lidar, SegmentIndex(self.world.segments_m))
        self.grid = OccupancyGrid(self.map_geometry, cfg.mapping)
        self.odometry = [OdometryDrift(cfg.odometry) for _ in range(self.n_robots)]
        self._odometry_noisy = not cfg.odometry.is_perfect
        self.slam = TeamSlam.create(
            cfg, self.map_geometry, self.lidar.beam_angles_rad, self.n_robots, self.team.map_sharing
        )
        self._slam_ranges: list[np.ndarray] = [np.zeros(0, np.float32)] * self.n_robots

    def _choose_start(self, options: dict[str, Any] | None) -> tuple[float, float, float]:
        # Robot 0's start is the single-robot env's, by the same code.
        return SemanticExploreEnv.choose_start(self, options)  # type: ignore[arg-type]

    def _scale_action(self, action: Any) -> tuple[float, float]:
        return SemanticExploreEnv.scale_action(self, action)  # type: ignore[arg-type]

    def _teammate_starts(
        self, first: tuple[float, float, float], reach: np.ndarray
    ) -> list[tuple[float, float, float]]:
        cfg, tp = self.config, self.team
        g = self.map_geometry
        r = cfg.robot.radius_m
        clearance = r + cfg.episode.start_clearance_margin_m
        dist = segment_distance_field(self.world.segments_m, g, clearance + g.resolution_m)
        ok = reach & (dist >= clearance)
        rows, cols = np.nonzero(ok)
        xs, ys = g.grid_to_world(rows, cols)
        xs, ys = np.asarray(xs, dtype=np.float64), np.asarray(ys, dtype=np.float64)
        placed = [first]
        spread = tp.start_spread_m if tp.start == "near" else math.inf
        min_gap = 2.0 * r + tp.start_gap_m
        while len(placed) < self.n_robots:
            keep = np.hypot(xs - first[0], ys - first[1]) <= spread
            for px, py, _ in placed:
                keep &= np.hypot(xs - px, ys - py) >= min_gap
            cand = np.flatnonzero(keep)
            if cand.size == 0:
                if math.isinf(spread) or spread > 1e4:
                    raise ValueError(
                        f"no room for {self.n_robots} robots {min_gap:.2f} m apart in {self.world.name!r}"
                    )
                spread = max(2.0 * spread, 1.0)  # no room that near: look farther
                continue
            k = int(cand[int(self.np_random.integers(cand.size))])
            yaw = float(self.np_random.uniform(-np.pi, np.pi))
            placed.append((float(xs[k]), float(ys[k]), yaw))
        return placed

    # ------------------------------------------------------------------- API
    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, dict[str, np.ndarray]], dict[str, dict[str, Any]]]:
        if seed is not None:
            self._np_random, _ = seeding.np_random(seed)
        if self._randomise_world and (self._started or seed is not None):
            world_seed = int(self.np_random.integers(0, 2**31 - 1))
            family, _, params = str(self.world_spec).partition(":")
            params = f"{params},seed={world_seed}" if params.strip() else f"seed={world_seed}"
            self.world = make_world(f"{family}:{params}")
            self._build_world_state()
        self._started = True
        cfg = self.config
        n = self.n_robots
        given = (options or {}).get("start_poses")
        first = (
            self._choose_start({"start_pose": given[0]}) if given else self._choose_start(options)
        )
        reach = coverage_mask(self.world, self.map_geometry, first[:2], cfg)
        if given:
            if len(given) != n:
                raise ValueError(f"options['start_poses'] needs {n} poses, got {len(given)}")
            poses = [first] + [self._choose_start({"start_pose": p}) for p in given[1:]]
        else:
            poses = self._teammate_starts(first, reach) if n > 1 else [first]
        self.sim.reset(poses)
        self._n_reachable = max(1, int(reach.sum()))
        self.grid = OccupancyGrid(self.map_geometry, cfg.mapping, count_mask=reach)
        self.own_grids: list[OccupancyGrid] = (
            [OccupancyGrid(self.map_geometry, cfg.mapping, count_mask=reach) for _ in range(n)]
            if self.team.map_sharing == "range"
            else []
        )
        for odo, p in zip(self.odometry, poses, strict=True):
            odo.reset(p)
        self._est_poses: list[Any] = list(poses)
        self.sim_time_s = 0.0
        self._n_steps = 0
        self.path_length_m = [0.0] * n
        self.trajectories: list[list[tuple[float, float]]] = [[(p[0], p[1])] for p in poses]
        self._overlays = [{} for _ in range(n)]
        self.scanned_count = np.zeros(self.map_geometry.shape, dtype=np.uint8)
        xy = np.array(poses, dtype=np.float64)[:, :2]
        self._scans = [self._sense(i, poses, xy) for i in range(n)]
        if self.slam is not None:
            self.slam.reset(list(poses), self._slam_ranges, reach)
        self.agents = list(self.possible_agents)
        zero = {"free_area_change": 0.0, "time": 0.0, "collision": 0.0, "team": 0.0}
        infos = {a: self._agent_info(i, dict(zero), True) for i, a in enumerate(self.agents)}
        self._start_poses, self._reach = list(poses), reach
        if self.privileged:
            for i, a in enumerate(self.agents):
                infos[a][PRIVILEGED_INFO_KEY] = self.ground_truth(i)
        return self._observations(), infos

    def ground_truth(self, index: int) -> Any:
        """The episode's :class:`~semexplore_gym.core.coverage_tour.PrivilegedWorld` seen from
        robot ``index``'s start (what ``privileged=True`` hands that agent at ``reset``; the
        benchmark reads it for the lower bound). For runners, never for policies."""
        if not self._started:
            raise RuntimeError("ground_truth() needs reset() first")
        pose = self._start_poses[index]
        return SemanticExploreEnv._privileged_world(self, pose, self._reach)  # type: ignore[arg-type]

    def step(
        self, actions: dict[str, Any]
    ) -> tuple[
        dict[str, dict[str, np.ndarray]],
        dict[str, float],
        dict[str, bool],
        dict[str, bool],
        dict[str, dict[str, Any]],
    ]:
        if not self.agents:
            raise RuntimeError("step() after the episode ended; call reset()")
        cfg = self.config
        n = self.n_robots
        commands = [
            self._scale_action(actions[a]) if a in actions else (0.0, 0.0)
            for a in self.possible_agents
        ]
        before = self.sim.poses
        new_contact = self.sim.step(commands, cfg.episode.dt_s)
        after = self.sim.poses
        after_xy = np.array(after, dtype=np.float64)[:, :2]
        self._n_steps += 1
        self.sim_time_s = round(self._n_steps * cfg.episode.dt_s, 9)
        gains: list[int] = []
        team_gains: list[int] = []
        for i in range(n):
            b, a = before[i], after[i]
            self.path_length_m[i] += math.hypot(a[0] - b[0], a[1] - b[1])
            self.trajectories[i].append((a[0], a[1]))
            self._est_poses[i] = (
                self.odometry[i].update(b, a, self.np_random) if self._odometry_noisy else a
            )
            own = self._map_of(i)
            own_before, team_before = own.n_free_cells, self.grid.n_free_cells
            self._scans[i] = self._sense(i, after, after_xy)
            if self.slam is not None:
                self._est_poses[i] = self.slam.update(
                    i, self._est_poses[i], self._slam_ranges[i], a
                )
            gains.append(own.n_free_cells - own_before)
            team_gains.append(self.grid.n_free_cells - team_before)
        if self.slam is not None:
            self.slam.merge()
        if self.own_grids:
            self._merge_in_range(after)
        res2 = cfg.mapping.resolution_m**2
        rw = cfg.reward
        total_team_gain = sum(team_gains)
        rewards: dict[str, float] = {}
        infos: dict[str, dict[str, Any]] = {}
        for i, agent in enumerate(self.possible_agents):
            terms = {
                "free_area_change": rw.free_area_change_weight * (gains[i] * res2),
                "time": rw.time_weight * cfg.episode.dt_s,
                "collision": rw.collision_weight * float(new_contact[i]),
            }
            reward = float(sum(terms.values()))
            team_term = self.team.team_reward_weight * (total_team_gain - team_gains[i]) * res2
            terms["team"] = team_term
            if n > 1:
                reward += team_term
            rewards[agent] = reward
            infos[agent] = self._agent_info(i, terms, True)
        coverage = self.grid.n_free_in_mask / self._n_reachable
        terminated = bool(self.team.end_on_coverage and coverage >= cfg.episode.coverage_goal)
        truncated = bool(self.sim_time_s >= cfg.episode.max_time_s - 1e-9)
        observations = self._observations()
        terminations = {a: terminated for a in self.possible_agents}
        truncations = {a: truncated for a in self.possible_agents}
        if terminated or truncated:
            self.agents = []
        return observations, rewards, terminations, truncations, infos

    # ------------------------------------------------------------ the chain
    def _map_of(self, i: int) -> OccupancyGrid:
        return self.own_grids[i] if self.own_grids else self.grid

    def _sense(
        self, i: int, true_poses: list[tuple[float, float, float]], xy: np.ndarray
    ) -> np.ndarray:
        """Robot ``i``'s scan (``xy``: every robot's true position), fused into its map(s);
        with teammates, its cells are counted in ``scanned_count`` (bit ``i``: its
        footprint, for the overlap ratio). With SLAM the map is fused at the true pose (for
        coverage) and the ranges it fused are kept for the robot's SLAM."""
        teammates = footprint = None
        if self.n_robots > 1:
            teammates = DiscObstacles(
                xy[self._others[i]], self.config.robot.radius_m, self.team.map_teammates
            )
            footprint = ScanFootprint(self.scanned_count, i)
        grids = [self.own_grids[i], self.grid] if self.own_grids else [self.grid]
        scan = sense_with_teammates(
            self.lidar,
            true_poses[i],
            true_poses[i] if self.slam is not None else self._est_poses[i],
            grids,
            self.np_random,
            teammates,
            footprint,
        )
        if self.slam is not None:
            self._slam_ranges[i] = self.lidar.last_map_ranges.astype(np.float32)
        return scan

    def _merge_in_range(self, true_poses: list[tuple[float, float, float]]) -> None:
        xy = np.array([p[:2] for p in true_poses])
        d = np.hypot(*(xy[:, None, :] - xy[None, :, :]).transpose(2, 0, 1))
        n_groups, labels = _components(d <= self.team.comm_range_m)
        for k in range(n_groups):
            members = np.flatnonzero(labels == k)
            if members.size > 1:
                merge_grids([self.own_grids[int(j)] for j in members])

    def _observations(self) -> dict[str, dict[str, np.ndarray]]:
        poses = np.array(
            [(x, y, wrap_angle_rad(yaw)) for x, y, yaw in self._est_poses], dtype=np.float32
        )
        out = {}
        team_map = None
        if self.n_robots > 1 and not self.own_grids:
            # One snapshot of the team map per step, shared read-only by every agent.
            team_map = self._observed_grid(0).encoded_copy()
            team_map.flags.writeable = False
        for i, agent in enumerate(self.possible_agents):
            out[agent] = {
                "map": team_map if team_map is not None else self._observed_grid(i).encoded_copy(),
                "pose": poses[i].copy(),
                "scan": self._scans[i],
                "teammates": poses[self._others[i]],
            }
        return out

    def _observed_grid(self, i: int) -> OccupancyGrid:
        """The map robot ``i`` observes: the merged SLAM map with SLAM, else its map."""
        return self.slam.grid if self.slam is not None else self._map_of(i)

    def _agent_info(self, i: int, terms: dict[str, float], static: bool) -> dict[str, Any]:
        info = self._static_info.copy() if static else {}
        info["coverage"] = self.grid.n_free_in_mask / self._n_reachable
        info["explored_area_m2"] = self._map_of(i).n_free_cells * self._area_per_cell_m2
        info["collisions"] = self.sim.collisions[i]
        info["sim_time_s"] = self.sim_time_s
        info["path_length_m"] = self.path_length_m[i]
        info["robot_collisions"] = self.sim.robot_collisions
        info["reward_terms"] = terms
        if self.slam is not None:
            info.update(self.slam.info(i, self.sim.poses[i]))
        return info

    # -------------------------------------------------------------- metrics
    def overlap_ratio(self) -> float:
        """Explore-Bench's overlap ratio: area scanned by more than one robot / area explored
        (explored = free or occupied in the team map)."""
        from semexplore_gym.core.grid import UNKNOWN

        explored = self.grid.encoded != UNKNOWN
        c = self.scanned_count
        multi = (c & (c - np.uint8(1))) != 0  # more than one bit set
        n_explored = int(explored.sum())
        return float((multi & explored).sum() / n_explored) if n_explored else 0.0

    # ------------------------------------------------------------- rendering
    def set_overlay(self, agent: str, overlay: dict[str, Any] | None) -> None:
        """Draw a robot's policy overlay (its goal and path) on the next frames."""
        self._overlays[self.possible_agents.index(agent)] = dict(overlay or {})

    def render(self) -> np.ndarray | None:
        if self.render_mode is None:
            return None
        from semexplore_gym.rendering.team import TeamSnapshot, draw_team

        if self._renderer is None:
            from semexplore_gym.rendering.renderer import Renderer

            self._renderer = Renderer(self.map_geometry)
        snap = TeamSnapshot(
            map=self.grid.encoded.copy(),
            geometry=self.map_geometry,
            segments_m=self.world.segments_m,
            poses=self.sim.poses,
            radius_m=self.config.robot.radius_m,
            trajectories_m=[np.asarray(t, dtype=np.float64) for t in self.trajectories],
            goals_m=[ov.get("goal_m") for ov in self._overlays],
            paths_m=[(ov.get("paths_m") or [None])[0] for ov in self._overlays],
            text=f"t={self.sim_time_s:6.1f} s  coverage="
            f"{self.grid.n_free_in_mask / self._n_reachable:5.1%}  robots={self.n_robots}",
        )
        return draw_team(self._renderer, snap)

    def close(self) -> None:
        self._renderer = None

    def __getstate__(self) -> dict[str, Any]:
        state = self.__dict__.copy()
        state["_renderer"] = None
        return state


def _components(adjacent: np.ndarray) -> tuple[int, np.ndarray]:
    """Connected components of a small symmetric adjacency matrix: ``(count, labels)``."""
    from scipy.sparse import csr_matrix
    from scipy.sparse.csgraph import connected_components

    n, labels = connected_components(csr_matrix(adjacent), directed=False)
    return int(n), labels


def make_multi(env_id: str = ENV_ID, **kwargs: Any) -> SemanticExploreMultiEnv:
    """Make a multi-robot env by id (PettingZoo has no registry): ``"SemanticExploreMulti-v0"``."""
    if env_id != ENV_ID:
        raise ValueError(f"unknown multi-robot env id {env_id!r}; known: {ENV_ID!r}")
    return SemanticExploreMultiEnv(**kwargs)


def parallel_env(**kwargs: Any) -> SemanticExploreMultiEnv:
    """PettingZoo's conventional constructor name."""
    return SemanticExploreMultiEnv(**kwargs)


__all__ = ["ENV_ID", "SemanticExploreMultiEnv", "make_multi", "parallel_env"]
