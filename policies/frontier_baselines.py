"""Frontier-exploration baselines: ROS ``frontier_exploration`` (FE) and Yamauchi's nearest frontier.

Both drive with the same move_base-like :class:`~semexplore_gym.policies.navigation.Navigator` (Navfn global
plan, DWA local control, planner and controller patience, rotate recoveries, abort), and skip
goals near aborted ones with a :class:`~semexplore_gym.policies.navigation.GoalBlacklist`.

:class:`FrontierExplorationPolicy` (``"frontier"``) follows ``frontier_exploration``
(``explore_server`` + ``BoundedExploreLayer``, indigo; blacklist of the melodic plugin):

* every ``1 / frequency_hz`` (default 2 Hz, as FE's example launch files set it; the robot
  then tends to flip between frontiers at similar distances, the goal switching users report),
  or, with ``frequency_hz = 0`` (``frontier[frequency_hz=0]``, the ``explore_server`` node's
  own default), only when the current goal has ended (it commits to each goal until move_base
  reports success or abort), it runs the wavefront
  frontier search (:func:`~semexplore_gym.core.frontiers.detect_frontiers`) **on its explore
  costmap** (``search_on_costmap``): only cells of cost 0 are free, so frontiers hide within
  ``explore_costmap.inflation_radius_m`` (0.15 m) of walls, exactly as FE's search on its
  layered costmap;
* it picks the frontier with the smallest Euclidean ``min_distance`` (``selection="euclidean"``,
  indigo) or the first in BFS discovery order (``"bfs_order"``, the melodic plugin), and sends
  its travel point (``"closest"`` = first-contact cell, FE's default; ``"middle"``, which in
  FE's code is the Euclidean-nearest cell; or ``"centroid"``);
* the goal is re-sent only when it moved farther than ``0.9 * goal_aliasing_m`` (1 m) from the
  current one, or when the robot is not moving;
* **it does not check reachability before committing** (the paper names this as one reason FE
  is slow): an unreachable travel point costs planner patience plus recoveries before it is
  aborted. ``check_reachability=True`` skips frontiers whose travel point the planner cannot
  reach (one Dijkstra from the robot per selection), drops the committed goal as soon as the
  map shows it next to a wall or a replan finds it unreachable, and replans as soon as the
  path runs into a newly mapped wall;
* aborted goals are blacklisted (travel points within ``blacklist_box_m`` are skipped); the
  blacklist is cleared when a goal succeeds (melodic ``FrontierPlugin``);
* exploration is complete when no frontier is found ``no_frontier_retries + 1`` times in a row.

:class:`NearestFrontierPolicy` (``"nearest"``, Yamauchi 1997) picks the frontier closest by
**grid path length** through known free cells the robot fits in (geodesic Dijkstra from the
robot) and drives to its nearest such cell. It re-selects when that cell stops being a frontier
cell (it has been seen), when the goal is reached or aborted, and every ``replan_period_s`` only
if the current target is gone. Aborted targets stay blacklisted for the mission.

Both policies are honest: they read ``obs`` (``map``, ``pose``, ``scan``) and the static facts of
``info`` (``map_geometry``, ``robot``, ``lidar``, ``dt_s``). Time is the policy's own clock
(steps times ``dt_s``). ``last_stats.map_generation_ms`` is the frontier search (and the explore
costmap it runs on), ``global_planning_ms`` the goal selection and Navfn, and
``local_planning_ms`` the DWA.
"""

from __future__ import annotations

import abc
import dataclasses
import math
import time
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from semexplore_gym.policies.base import DriveIntent, Policy, StepStats, off_map_msg, read_env_facts
from semexplore_gym.policies.navigation import (
    GoalBlacklist,
    MoveBaseParams,
    Navigator,
    NavStatus,
    check_int_at_least,
    check_positive,
    warm_up_navigation_kernels,
)

from semexplore_gym.core.frontiers.detection import GridFrontier, detect_frontiers
from semexplore_gym.core.grid import FREE, OCCUPIED, UNKNOWN
from semexplore_gym.core.planning.dwa import scan_points_m
from semexplore_gym.core.planning.grid_search import (
    INSCRIBED_COST,
    NO_INFORMATION,
    CostmapParams,
    cells_near_occupied,
    distance_field,
    geodesic_distance_m,
    inflate_costmap,
    navfn_cell_costs,
)

__all__ = [
    "FrontierExplorationParams",
    "FrontierExplorationPolicy",
    "NearestFrontierParams",
    "NearestFrontierPolicy",
]


class _FrontierBaseline(Policy):
    """Shared plumbing: reading obs/info, the navigator, the step, actions, stats and overlay.

    A step reads the observation, lets the subclass choose or keep the navigator's goal
    (:meth:`_update_goal`), then drives (:meth:`_drive`, one navigator step by default).

    Args:
        params: The subclass's parameters (``None``: its ``params_type()`` defaults).
        overrides: Keyword overrides applied on top.
    """

    params_type: type[Any]
    reads_map_in_step_only = True  # tested: missions identical with a copied or a shared map

    def __init__(self, params: Any = None, **overrides: Any) -> None:
        super().__init__()
        p = params if params is not None else self.params_type()
        if overrides:
            p = dataclasses.replace(p, **overrides)
        self.params = p
        self.nav: Navigator | None = None
        self.frontiers: list[GridFrontier] = []
        self.blacklist = self._new_blacklist()
        self.counters: dict[str, int] = {}

    @abc.abstractmethod
    def _new_blacklist(self) -> GoalBlacklist:
        """The (empty) blacklist of aborted goals, as the subclass's rule has it."""

    @abc.abstractmethod
    def _update_goal(self, grid: np.ndarray, pose: np.ndarray, stats: StepStats) -> None:
        """Choose or keep the navigator's goal for this step; may end the mission (``_finish``)."""

    def reset(
        self, obs: dict[str, np.ndarray], info: dict[str, Any], seed: int | None = None
    ) -> None:
        super().reset(obs, info, seed=seed)
        facts = read_env_facts(info, type(self).__name__)
        self.geometry = facts.geometry
        self.radius_m = facts.radius_m
        self.max_v = facts.max_linear_speed_mps
        self.max_w = facts.max_angular_speed_radps
        self.max_range_m = facts.max_range_m
        self.min_range_m = facts.min_range_m
        self.dt_s = facts.dt_s
        if not (self.max_v > 0 and self.max_w > 0 and self.dt_s > 0):
            raise ValueError(
                f"robot limits and dt_s must be positive, got {self.max_v}, {self.max_w}, {self.dt_s}"
            )
        self.nav = Navigator(
            self.params.navigation, self.radius_m, (self.max_v, self.max_w), self.dt_s
        )
        warm_up_navigation_kernels()
        self.now_s = 0.0
        self.frontiers = []
        self.blacklist.clear()
        self.counters = {"selections": 0, "goals_sent": 0, "blacklisted": 0}
        self._no_frontier_count = 0

    def _read(self, obs: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        grid = np.asarray(obs["map"])
        if grid.shape != self.geometry.shape:
            raise ValueError(
                f"obs['map'] shape {grid.shape} differs from info map_geometry {self.geometry.shape}"
            )
        pose = np.asarray(obs["pose"], dtype=np.float64).ravel()[:3]
        scan = scan_points_m(pose, obs["scan"], self.max_range_m, self.min_range_m)
        return grid, pose, scan

    def act(self, obs: dict[str, np.ndarray], info: dict[str, Any]) -> np.ndarray:
        if self.nav is None:
            raise RuntimeError("call reset() before act()")
        stats = StepStats()
        self.last_stats = stats
        if self.done:
            return self._action(0.0, 0.0)
        grid, pose, scan = self._read(obs)
        if note := off_map_msg(self.geometry, pose):  # a diverged SLAM: no search starts there
            self._finish(note)  # (explore_lite: "Robot out of costmap bounds")
        else:
            self._update_goal(grid, pose, stats)
        if self.done:
            return self._action(0.0, 0.0)
        v, w = self._drive(grid, pose, scan, stats)
        # The navigator's counts (plans, recoveries, aborts, ...) travel with the policy's.
        self.counters.update({f"nav_{k}": n for k, n in self.nav.counters.items()})
        stats.extra = {"nav_status": self.nav.status, "n_frontiers": len(self.frontiers)}
        self.now_s += self.dt_s
        return self._action(v, w)

    def _drive(
        self, grid: np.ndarray, pose: np.ndarray, scan: np.ndarray, stats: StepStats
    ) -> tuple[float, float]:
        assert self.nav is not None
        return self.nav.step(self.now_s, pose, grid, self.geometry, scan, stats)

    def _blacklist_aborted_goal(self) -> None:
        assert self.nav is not None
        if self.nav.goal_xy_m is not None:
            self.blacklist.add(self.nav.goal_xy_m)
            self.counters["blacklisted"] += 1

    def drive_intent(self) -> DriveIntent | None:
        return None if self.nav is None else self.nav.drive_intent()

    def _action(self, v: float, w: float) -> np.ndarray:
        a = np.array([v / self.max_v, w / self.max_w], dtype=np.float32)
        return np.clip(a, -1.0, 1.0)

    def resume(self) -> None:
        """Restart a stopped robot: clear ``done``, ``stop_reason`` and the no-frontier run."""
        self.done, self.stop_reason, self._no_frontier_count = False, "", 0

    def _finish(self, reason: str) -> None:
        """End the mission: the robot stops, ``stop_reason`` says why."""
        self.done, self.stop_reason = True, reason
        if self.nav is not None:
            self.nav.cancel()

    def overlay(self) -> dict[str, Any]:
        if self.nav is None:
            return {}
        out: dict[str, Any] = {
            "frontiers_m": [f.centroid_m for f in self.frontiers],
            "points_m": list(self.blacklist),
        }
        paths = [] if self.nav.path is None else [self.nav.path.points_m]
        if self.nav.trajectory_m.shape[0] > 1:
            paths.append(self.nav.trajectory_m)
        out["paths_m"] = paths
        if self.nav.goal_xy_m is not None:
            out["goal_m"] = self.nav.goal_xy_m
        out["text"] = f"{self.name}: {self.nav.status}, {len(self.frontiers)} frontiers"
        return out


@dataclass(frozen=True)
class FrontierExplorationParams:
    """ROS ``frontier_exploration`` (indigo explore_server + BoundedExploreLayer).

    Attributes:
        frequency_hz: Frontier search / goal update rate (``frequency``). 2.0, the default,
            is what FE's example launch files (``global_map.launch``, ``no_global_map.launch``)
            set, so what users run: every 0.5 s the frontier search runs again and the goal is
            re-sent if it moved (``goal_aliasing_m``). 0 is the ``explore_server`` node's own
            default: it waits until each goal ends (reached or aborted) before choosing the
            next; spell it ``frontier[frequency_hz=0]``.
        goal_aliasing_m: A new travel point is sent only if farther than 0.9 times this from
            the current goal (``goal_aliasing``, the launch sets it to the sensor range, 1.0).
        travel_point: ``"closest"`` (first-contact cell, FE's default), ``"middle"`` (FE's
            ``middle`` field, the Euclidean-nearest cell) or ``"centroid"``.
        selection: ``"euclidean"`` (smallest ``min_distance``, indigo) or ``"bfs_order"``
            (first frontier found, the melodic plugin).
        min_frontier_cells: Smallest frontier kept (FE indigo: more than one cell).
        search_on_costmap: Search on the explore costmap (free = cost 0), as FE does, rather
            than on the raw occupancy grid.
        explore_costmap: The explore costmap's inflation (``global_map.launch``: 0.15 m; ROS
            default ``cost_scaling_factor`` 10). Its inscribed radius becomes the robot radius.
        check_reachability: Skip frontiers the global planner cannot reach, abort a goal as
            soon as it is next to a wall or planning to it fails, replan when the path is
            blocked (none of this is in FE).
        blacklist_box_m: Travel points within this box half-size of an aborted goal are skipped
            (melodic ``blacklist_box_size`` 0.5).
        no_frontier_retries: Searches without a frontier tolerated before stopping (FE: 5).
        navigation: The move_base-like navigator (with ``local_goal_check``: a goal that
            turned out to be a wall makes the local planner fail, as ROS's DWA does).
    """

    frequency_hz: float = 2.0
    goal_aliasing_m: float = 1.0
    travel_point: Literal["closest", "middle", "centroid"] = "closest"
    selection: Literal["euclidean", "bfs_order"] = "euclidean"
    min_frontier_cells: int = 2
    search_on_costmap: bool = True
    explore_costmap: CostmapParams = field(
        default_factory=lambda: CostmapParams(inflation_radius_m=0.15)
    )
    check_reachability: bool = False
    blacklist_box_m: float = 0.5
    no_frontier_retries: int = 5
    navigation: MoveBaseParams = field(
        default_factory=lambda: MoveBaseParams(local_goal_check=True)
    )

    def __post_init__(self) -> None:
        check_positive(
            self, ("frequency_hz", "goal_aliasing_m", "blacklist_box_m"), allow_zero=True
        )
        if self.travel_point not in ("closest", "middle", "centroid"):
            raise ValueError(
                f"travel_point must be 'closest', 'middle' or 'centroid', got {self.travel_point!r}"
            )
        if self.selection not in ("euclidean", "bfs_order"):
            raise ValueError(
                f"selection must be 'euclidean' or 'bfs_order', got {self.selection!r}"
            )
        check_int_at_least(self, "min_frontier_cells", 1)
        check_int_at_least(self, "no_frontier_retries", 0)


class FrontierExplorationPolicy(_FrontierBaseline):
    """ROS ``frontier_exploration`` with Navfn + DWA (the paper's FE baseline).

    Args:
        params: Parameters; ``None`` = FE's defaults. Keyword overrides (e.g.
            ``check_reachability=True``) are applied on top.
    """

    name = "frontier"
    params_type = FrontierExplorationParams
    params: FrontierExplorationParams

    def __init__(self, params: FrontierExplorationParams | None = None, **overrides: Any) -> None:
        super().__init__(params, **overrides)

    def _new_blacklist(self) -> GoalBlacklist:
        return GoalBlacklist(self.params.blacklist_box_m, shape="box")

    def reset(
        self, obs: dict[str, np.ndarray], info: dict[str, Any], seed: int | None = None
    ) -> None:
        super().reset(obs, info, seed=seed)
        ec = self.params.explore_costmap
        self._explore_costmap = dataclasses.replace(
            ec,
            inscribed_radius_m=self.radius_m,
            inflation_radius_m=max(ec.inflation_radius_m, self.radius_m),
        )
        self._last_search_s = -math.inf
        self._moving = False
        assert self.nav is not None
        self.nav.check_blocked = self.params.check_reachability

    def _update_goal(self, grid: np.ndarray, pose: np.ndarray, stats: StepStats) -> None:
        assert self.nav is not None
        nav = self.nav
        prm = self.params
        if nav.status == NavStatus.SUCCEEDED:
            self.blacklist.clear()  # melodic FrontierPlugin clears the blacklist on success
            self._moving = False
        elif nav.status == NavStatus.ABORTED:
            self._blacklist_aborted_goal()
            nav.cancel()
            self._moving = False
        due = (
            prm.frequency_hz > 0
            and self.now_s - self._last_search_s >= 1.0 / prm.frequency_hz - 1e-9
        )
        if not self._moving or due:
            self._last_search_s = self.now_s
            goal = self._next_goal(grid, pose, stats)
            if goal is None:
                self._no_frontier_count += 1
                if self._no_frontier_count > prm.no_frontier_retries:
                    self._finish(
                        "no frontiers left"
                        if not self.frontiers
                        else "all frontiers blacklisted or unreachable"
                    )
            else:
                self._no_frontier_count = 0
                far = (
                    nav.goal_xy_m is None
                    or math.dist(goal, nav.goal_xy_m) > 0.9 * prm.goal_aliasing_m
                )
                if not self._moving or far:
                    nav.set_goal(goal, self.now_s)
                    self._moving = True
                    self.counters["goals_sent"] += 1

    def _drive(
        self, grid: np.ndarray, pose: np.ndarray, scan: np.ndarray, stats: StepStats
    ) -> tuple[float, float]:
        assert self.nav is not None
        nav = self.nav
        check = self.params.check_reachability
        if check and nav.goal_xy_m is not None and self._goal_blocked(grid, nav.goal_xy_m):
            # The committed goal is now (next to) a wall: drop it before driving on.
            nav.abort()
        v, w = super()._drive(grid, pose, scan, stats)
        if check and nav.last_plan_failed:
            # The committed goal became unreachable on the updated map: drop it at once.
            nav.abort()
        return v, w

    def _next_goal(
        self, grid: np.ndarray, pose: np.ndarray, stats: StepStats
    ) -> tuple[float, float] | None:
        prm = self.params
        t0 = time.perf_counter()
        search_grid = grid
        if prm.search_on_costmap:
            cost = inflate_costmap(grid, self.geometry.resolution_m, self._explore_costmap)
            search_grid = np.full(grid.shape, OCCUPIED, dtype=np.uint8)
            search_grid[cost == 0] = FREE
            search_grid[cost == NO_INFORMATION] = UNKNOWN
        self.frontiers = detect_frontiers(
            search_grid, self.geometry, pose[:2], min_frontier_cells=prm.min_frontier_cells
        )
        stats.map_generation_ms += (time.perf_counter() - t0) * 1e3

        t0 = time.perf_counter()
        self.counters["selections"] += 1
        candidates = [(f, self._travel_point(f)) for f in self.frontiers]
        candidates = [(f, p) for f, p in candidates if p not in self.blacklist]
        if prm.selection == "euclidean":
            candidates.sort(key=lambda fp: fp[0].min_distance_m)
        if prm.check_reachability and candidates:
            reach = self._reachable_mask(grid, pose)
            kept = []
            for f, p in candidates:
                r, c = self.geometry.world_to_grid(p[0], p[1])
                if self.geometry.contains(r, c) and reach[int(r), int(c)]:
                    kept.append((f, p))
            candidates = kept
        stats.global_planning_ms += (time.perf_counter() - t0) * 1e3
        return candidates[0][1] if candidates else None

    def _goal_blocked(self, grid: np.ndarray, goal: tuple[float, float]) -> bool:
        r, c = self.geometry.world_to_grid(goal[0], goal[1])
        cell = np.array([[int(r), int(c)]])
        return bool(cells_near_occupied(grid, cell, self.radius_m, self.geometry.resolution_m)[0])

    def _travel_point(self, f: GridFrontier) -> tuple[float, float]:
        tp = self.params.travel_point
        if tp == "centroid":
            return f.centroid_m
        return f.cell_xy_m(self.geometry, "initial" if tp == "closest" else "nearest")

    def _reachable_mask(self, grid: np.ndarray, pose: np.ndarray) -> np.ndarray:
        assert self.nav is not None
        costmap = inflate_costmap(grid, self.geometry.resolution_m, self.nav.costmap_params)
        cost = navfn_cell_costs(costmap, self.nav.params.navfn)
        r_a, c_a = self.geometry.world_to_grid(pose[0], pose[1])
        if not self.geometry.contains(r_a, c_a):
            return np.zeros(grid.shape, dtype=bool)
        r, c = int(r_a), int(c_a)
        # Same start handling as the planner (robot cell and escape radius are passable).
        if not np.isfinite(cost[r, c]):
            cost[r, c] = float(INSCRIBED_COST)
        k = int(self.nav.params.navfn.escape_radius_m / self.geometry.resolution_m)
        if k > 0:
            r0, r1 = max(r - k, 0), min(r + k + 1, grid.shape[0])
            c0, c1 = max(c - k, 0), min(c + k + 1, grid.shape[1])
            rr, cc = np.mgrid[r0:r1, c0:c1]
            near = ((rr - r) ** 2 + (cc - c) ** 2 <= k * k) & (
                costmap[r0:r1, c0:c1] == INSCRIBED_COST
            )
            cost[r0:r1, c0:c1][near] = float(INSCRIBED_COST)
        dist, _ = distance_field(cost, (r, c))
        return np.isfinite(dist)


@dataclass(frozen=True)
class NearestFrontierParams:
    """Yamauchi's nearest-frontier exploration.

    Attributes:
        replan_period_s: How often the frontier search runs while a target is pursued.
        min_frontier_cells: Smallest frontier kept, in cells.
        cell_convention: Frontier cells are ``"free"`` cells next to unknown (Yamauchi) or
            ``"unknown"`` cells next to free (FE).
        blacklist_radius_m: Targets within this distance of an aborted target are skipped for
            the rest of the mission.
        no_frontier_retries: Searches without a reachable frontier tolerated before stopping.
        navigation: The move_base-like navigator.
    """

    replan_period_s: float = 0.5
    min_frontier_cells: int = 2
    cell_convention: Literal["free", "unknown"] = "free"
    blacklist_radius_m: float = 0.5
    no_frontier_retries: int = 2
    navigation: MoveBaseParams = field(default_factory=MoveBaseParams)

    def __post_init__(self) -> None:
        check_positive(self, ("replan_period_s",))
        check_positive(self, ("blacklist_radius_m",), allow_zero=True)
        if self.cell_convention not in ("free", "unknown"):
            raise ValueError(
                f"cell_convention must be 'free' or 'unknown', got {self.cell_convention!r}"
            )
        check_int_at_least(self, "min_frontier_cells", 1)
        check_int_at_least(self, "no_frontier_retries", 0)


class NearestFrontierPolicy(_FrontierBaseline):
    """Yamauchi (1997): go to the frontier nearest by path length, with Navfn + DWA.

    Args:
        params: Parameters; ``None`` = defaults. Keyword overrides are applied on top.
    """

    name = "nearest"
    params_type = NearestFrontierParams
    params: NearestFrontierParams

    def __init__(self, params: NearestFrontierParams | None = None, **overrides: Any) -> None:
        super().__init__(params, **overrides)

    def _new_blacklist(self) -> GoalBlacklist:
        return GoalBlacklist(self.params.blacklist_radius_m)

    def reset(
        self, obs: dict[str, np.ndarray], info: dict[str, Any], seed: int | None = None
    ) -> None:
        super().reset(obs, info, seed=seed)
        self._last_search_s = -math.inf
        self.blacklist_hits = 0  # public: frontiers skipped as blacklisted by the last selection
        self.target_cell: tuple[int, int] | None = None  # public: the frontier cell chased now
        self.path_length_m = math.inf

    def _update_goal(self, grid: np.ndarray, pose: np.ndarray, stats: StepStats) -> None:
        assert self.nav is not None
        nav = self.nav
        prm = self.params
        if nav.status == NavStatus.ABORTED:
            self._blacklist_aborted_goal()
        need_target = nav.status in (NavStatus.IDLE, NavStatus.SUCCEEDED, NavStatus.ABORTED)
        need_target = need_target or not self.target_still_frontier(grid)
        due = self.now_s - self._last_search_s >= prm.replan_period_s - 1e-9
        if need_target:
            self._last_search_s = self.now_s
            goal = self.select_target(grid, pose, stats)
            if goal is None:
                self._no_frontier_count += 1
                nav.cancel()
                if self._no_frontier_count > prm.no_frontier_retries:
                    if self.blacklist_hits:
                        reason = "all reachable frontiers blacklisted"
                    elif self.frontiers:
                        reason = "no reachable frontier left"
                    else:
                        reason = "no frontiers left"
                    self._finish(reason)
            else:
                self._no_frontier_count = 0
                nav.set_goal(goal, self.now_s)
                self.counters["goals_sent"] += 1
        elif due:
            # The target is still a frontier: keep it, and keep the frontier list current.
            self._last_search_s = self.now_s
            t0 = time.perf_counter()
            self.frontiers = self.detect(grid, pose)
            stats.map_generation_ms += (time.perf_counter() - t0) * 1e3

    def detect(self, grid: np.ndarray, pose: np.ndarray) -> list[GridFrontier]:
        """The frontiers of ``grid`` (this policy's size and cell-convention settings)."""
        prm = self.params
        return detect_frontiers(
            grid, self.geometry, pose[:2], prm.min_frontier_cells, prm.cell_convention
        )

    def target_still_frontier(self, grid: np.ndarray) -> bool:
        """Whether :attr:`target_cell` is still a frontier cell of ``grid`` (False without one)."""
        if self.target_cell is None:
            return False
        r, c = self.target_cell
        own = FREE if self.params.cell_convention == "free" else UNKNOWN
        other = UNKNOWN if own == FREE else FREE
        if grid[r, c] != own:
            return False
        h, w = grid.shape
        return any(
            0 <= r + dr < h and 0 <= c + dc < w and grid[r + dr, c + dc] == other
            for dr, dc in ((1, 0), (-1, 0), (0, 1), (0, -1))
        )

    def select_target(
        self, grid: np.ndarray, pose: np.ndarray, stats: StepStats
    ) -> tuple[float, float] | None:
        """Next goal (m) or None; sets frontiers, target_cell, blacklist_hits, path_length_m."""
        assert self.nav is not None
        t0 = time.perf_counter()
        self.frontiers = self.detect(grid, pose)
        stats.map_generation_ms += (time.perf_counter() - t0) * 1e3
        self.target_cell = None
        self.blacklist_hits = 0
        if not self.frontiers:
            return None
        t0 = time.perf_counter()
        self.counters["selections"] += 1
        costmap = inflate_costmap(grid, self.geometry.resolution_m, self.nav.costmap_params)
        # Known free cells the robot fits in; unknown frontier cells count as enterable targets.
        traversable = (costmap < INSCRIBED_COST) & (grid == FREE)
        fmask = np.zeros(grid.shape, dtype=bool)
        for f in self.frontiers:
            fmask[f.cells[:, 0], f.cells[:, 1]] = True
        traversable |= fmask & ((costmap < INSCRIBED_COST) | (costmap == NO_INFORMATION))
        dist = geodesic_distance_m(traversable, self.geometry, pose[:2])
        best: tuple[float, tuple[int, int]] | None = None
        for f in self.frontiers:
            d = dist[f.cells[:, 0], f.cells[:, 1]]
            i = int(np.argmin(d))
            if not np.isfinite(d[i]):
                continue
            cell = (int(f.cells[i, 0]), int(f.cells[i, 1]))
            x, y = self.geometry.grid_to_world(*cell)
            if (float(x), float(y)) in self.blacklist:
                self.blacklist_hits += 1
                continue
            if best is None or d[i] < best[0]:
                best = (float(d[i]), cell)
        stats.global_planning_ms += (time.perf_counter() - t0) * 1e3
        if best is None:
            return None
        self.path_length_m = best[0]
        self.target_cell = best[1]
        x, y = self.geometry.grid_to_world(*best[1])
        return (float(x), float(y))
