"""The paper's semantic exploration strategy as a scripted expert :class:`Policy`.

Each replanning step (section II of Fredriksson et al.):

1. **Pose identification.** Segment the observed occupancy grid into the semantic topometric
   map (``segment_map``); the frontiers ``F_i`` are those of its frontier pathways.
2. **Goal selection.** Algorithm 1 (:mod:`semexplore_gym.core.planning.graph_search`) finds the path
   along the map to every frontier and scores it with
   ``C = d / L_path + w_v v - (w_p p_l + w_I (O(I) + P_u(I)))``; ``F* = argmin C``.
3. **Navigation.** Every step, the modified potential field
   (:mod:`semexplore_gym.core.planning.potential_field`) follows the path to ``F*``.
4. **Stop.** The mission ends when no frontier remains.

The policy is honest: it reads only the observation (``map``, ``pose``, ``scan``) and the
static facts of ``info`` (``map_geometry``, ``robot``, ``lidar``, ``dt_s``), never ground truth.

What the paper leaves open (replanning events, goal commitment, narrow frontiers, the
grid-frontier fallback, stop confirmation, local minima, stuck recovery, blacklisting) and the
parameters for it are described in :mod:`semexplore_gym.policies.semantic_expert_params`. Goals are
blacklisted, progress is watched and stuck recoveries are driven by the navigation stack the
frontier baselines share (:mod:`semexplore_gym.policies.navigation`).

Subclasses steer the expert through its public hooks: :meth:`SemanticExpertPolicy.choose_goal`
(which scored frontier to pursue), :meth:`~SemanticExpertPolicy.on_replan_due` and
:meth:`~SemanticExpertPolicy.on_replanned` (notifications around each replan), and
:meth:`~SemanticExpertPolicy.request_replan`; :meth:`~SemanticExpertPolicy.frontier_candidates`
scores the frontiers of any observation without changing the plan.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from semexplore_gym.policies.base import Policy, StepStats, read_env_facts
from semexplore_gym.policies.navigation import BackoffRecovery, GoalBlacklist, ProgressWatch
from semexplore_gym.policies.semantic_expert_params import SemanticExpertParams
from semexplore_gym.policies.semantic_expert_persistence import TRAIL_CELL_M, GoalPersistence

from semexplore_gym.core.frontiers.reachable import (
    FrontierFilter,
    clearance_field_m,
    grid_path_to,
    nearest_reachable_frontier,
)
from semexplore_gym.core.grid import UNKNOWN
from semexplore_gym.core.planning.graph_search import (
    FrontierCandidate,
    FrontierCostWeights,
    search_frontier_paths,
)
from semexplore_gym.core.planning.grid_scan import known_cell_count
from semexplore_gym.core.planning.line_of_sight import segment_is_clear
from semexplore_gym.core.planning.potential_field import (
    PotentialFieldCommand,
    PotentialFieldFollower,
    RobotLimits,
    beam_angles_rad,
    resample_polyline,
)
from semexplore_gym.core.topometric.types import TopometricMap

__all__ = [
    "REPLAN_REASONS",
    "Segmenter",
    "SemanticExpertParams",
    "SemanticExpertPolicy",
    "area_type_raster",
]

Segmenter = Callable[..., TopometricMap]

#: Why a replan runs (``counters["replan_<reason>"]``, :meth:`SemanticExpertPolicy.on_replan_due`).
REPLAN_REASONS = ("no_plan", "period", "goal_reached", "path_done", "goal_vanished")

#: The rest of the path must shrink by more than this to count as progress.
_PATH_PROGRESS_MARGIN_M = 0.1


#: Where a plan's goal comes from: a semantic frontier, the grid fallback, a retry of a failed
#: goal by another approach, or a look at a frontier too narrow to reach.
PlanSource = Literal["semantic", "fallback", "retry", "look"]


@dataclass
class _Plan:
    source: PlanSource
    goal_xy_m: tuple[float, float]
    path_m: np.ndarray
    candidate: FrontierCandidate | None
    progress: int = 0
    frontier_xy_m: tuple[float, float] | None = None
    arc_m: np.ndarray = field(default_factory=lambda: np.zeros(1))

    def __post_init__(self) -> None:
        seg = np.hypot(*np.diff(self.path_m, axis=0).T) if len(self.path_m) > 1 else np.zeros(0)
        self.arc_m = np.concatenate(([0.0], np.cumsum(seg)))


class SemanticExpertPolicy(GoalPersistence, Policy):
    """The paper's exploration strategy (semantic goal selection + modified potential field).

    Args:
        params: Parameters (default: the paper's weights and our robustness settings).
        segmenter: ``segment_map``-compatible callable ``(grid, geometry, clearance_m,
            params=..., previous=...) -> TopometricMap``; default a
            :class:`semexplore_gym.core.topometric.TopometricSegmenter` of its own.

    Attributes (after ``reset``): ``tmap`` the last topometric map, ``candidates`` the scored
    frontiers of the last replan, ``mode`` (``"semantic"``, ``"fallback"``, ``"escape"``,
    ``"recovery"``, ``"waiting"``, ``"done"``) and ``counters`` (replans, recoveries, ...).
    """

    name = "semantic"
    reads_map_in_step_only = True  # tested: missions identical with a copied or a shared map

    def __init__(
        self, params: SemanticExpertParams | None = None, segmenter: Segmenter | None = None
    ) -> None:
        super().__init__()
        self.params = params if params is not None else SemanticExpertParams()
        self._segmenter = segmenter
        self.tmap: TopometricMap | None = None
        self.candidates: list[FrontierCandidate] = []
        self.mode = "idle"
        self.counters: dict[str, int] = {}
        self.events: list[tuple[float, str, str]] = []
        self.memory = self._new_memory()
        self._time_s = 0.0

    # ------------------------------------------------------------------ lifecycle
    def reset(
        self, obs: dict[str, np.ndarray], info: dict[str, Any], seed: int | None = None
    ) -> None:
        super().reset(obs, info, seed=seed)
        facts = read_env_facts(info, type(self).__name__)
        self.geometry = facts.geometry
        self.dt_s = facts.dt_s
        self.limits = RobotLimits(
            radius_m=facts.radius_m,
            max_linear_speed_mps=facts.max_linear_speed_mps,
            max_angular_speed_radps=facts.max_angular_speed_radps,
            max_range_m=facts.max_range_m,
        )
        if self._segmenter is None:
            # one segmenter per policy: it keeps its scratch memory between replans
            from semexplore_gym.core.topometric import TopometricSegmenter

            self._segmenter = TopometricSegmenter()
        self.clearance_m = self.limits.radius_m + self.params.clearance_margin_m
        self.tmap = None
        self.candidates = []
        self.mode = "idle"
        self.events = []
        self.counters = {
            "replans": 0,
            "segmentations": 0,
            "semantic_plans": 0,
            "fallback_plans": 0,
            "entry_detours": 0,
            "escapes": 0,
            "recoveries": 0,
            "blacklisted": 0,
            "switches": 0,
            "retries": 0,
            "revived": 0,
            "looks": 0,
            "look_drives": 0,
            "pocket_escapes": 0,
            "goal_timeouts": 0,
            "oscillations_blocked": 0,
            # Instrumentation only (no decision reads them): replans with scored frontiers, and
            # those where the metric cost alone would have picked another frontier.
            "scored_replans": 0,
            "semantic_decisive": 0,
        }
        self._angles: np.ndarray | None = None
        self._time_s = 0.0
        self._goal_since_s = 0.0
        self._goal_budget_s = math.inf
        self._plan: _Plan | None = None
        self._next_replan_s = 0.0
        self._last_reason = ""
        self._seg_known_cells = 0
        self._empty_replans = 0
        self.blacklist = GoalBlacklist(self.params.blacklist_radius_m)
        self.memory = self._new_memory()
        self._retry: tuple[tuple[float, float], int, tuple[float, float]] | None = None
        # Where the robot has been, on a coarse lattice: a narrow frontier it already passed
        # close to has had its closer look.
        self._trail: set[tuple[int, int]] = set()
        self._reaches: list[tuple[float, float, int]] = []
        self._area_types: np.ndarray | None = None
        self._last_cmd: PotentialFieldCommand | None = None
        self._still_s = 0.0
        self._escape_until_s = -1.0
        self._known_cells = known_cell_count(obs["map"])
        prm = self.params
        self._backoff = BackoffRecovery(prm.backoff_duration_s, prm.backoff_speed_fraction)
        # Stuck: the robot stayed near one point while the map hardly grew ...
        self._motion_watch = ProgressWatch(
            prm.stuck_timeout_s,
            radius_m=prm.stuck_radius_m,
            min_new_cells=prm.progress_min_new_cells,
        )
        self._motion_watch.reset(
            0.0, (float(obs["pose"][0]), float(obs["pose"][1])), self._known_cells
        )
        # ... or neither its path to the goal shrank nor the map grew, for longer.
        self._path_watch = ProgressWatch(
            prm.progress_timeout_s,
            min_new_cells=prm.progress_min_new_cells,
            path_margin_m=_PATH_PROGRESS_MARGIN_M,
        )
        self._path_watch.reset(0.0, None, self._known_cells)

    # ------------------------------------------------------------------ stepping
    def act(self, obs: dict[str, np.ndarray], info: dict[str, Any]) -> np.ndarray:
        t_start = time.perf_counter()
        stats = StepStats()
        if self.done:
            self.last_stats = stats
            return np.zeros(2, dtype=np.float32)
        grid = obs["map"]
        p = obs["pose"]
        pose = (float(p[0]), float(p[1]), float(p[2]))
        scan = np.asarray(obs["scan"], dtype=np.float64)
        if self._angles is None or len(self._angles) != len(scan):
            self._angles = beam_angles_rad(len(scan))
        self._known_cells = known_cell_count(grid)
        self._trail.add((int(pose[0] // TRAIL_CELL_M), int(pose[1] // TRAIL_CELL_M)))

        if self._backoff.active(self._time_s):
            v, w = self._recovery_command(grid, pose, scan)
            self.mode = "recovery"
        else:
            if self._backoff.finish():
                # Recovery just ended: retry the goal that got us stuck another way, or drop it.
                self._goal_failed(grid, pose)
            if self._needs_replan(grid, pose):
                self._replan(grid, pose, stats)
            if self.done:
                v, w = 0.0, 0.0
            elif self._plan is None:
                v, w = 0.0, 0.0
                self.mode = "waiting"
            else:
                v, w = self._follow(grid, pose, scan)
                if self.params.stuck_recovery:
                    self._watch_progress(pose)
                if self._backoff.active(self._time_s):
                    v, w = self._recovery_command(grid, pose, scan)
        self._time_s += self.dt_s
        action = np.array(
            [
                np.clip(v / self.limits.max_linear_speed_mps, -1.0, 1.0),
                np.clip(w / self.limits.max_angular_speed_radps, -1.0, 1.0),
            ],
            dtype=np.float32,
        )
        total_ms = (time.perf_counter() - t_start) * 1e3
        stats.local_planning_ms = max(
            0.0, total_ms - stats.map_generation_ms - stats.global_planning_ms
        )
        stats.extra["mode"] = self.mode
        self.last_stats = stats
        return action

    def _needs_replan(self, grid: np.ndarray, pose: tuple[float, float, float]) -> bool:
        reason = self._replan_reason(grid, pose)
        self._last_reason = reason
        if reason:
            self.counters[f"replan_{reason}"] = self.counters.get(f"replan_{reason}", 0) + 1
            self.on_replan_due(reason)
        return bool(reason)

    def _replan_reason(self, grid: np.ndarray, pose: tuple[float, float, float]) -> str:
        plan = self._plan
        if plan is None:
            return "no_plan"
        if self._time_s >= self._next_replan_s - 1e-9:
            return "period"
        if (
            math.hypot(pose[0] - plan.goal_xy_m[0], pose[1] - plan.goal_xy_m[1])
            <= self.params.goal_reached_radius_m
        ):
            self._on_goal_reached(grid, plan)
            return "goal_reached"
        if plan.progress >= len(plan.path_m) - 1:
            return "path_done"
        # Goal vanished: no unknown cell is left near it (its frontier has been mapped).
        if not self._unknown_near(grid, plan.goal_xy_m, self.params.goal_check_radius_m):
            return "goal_vanished"
        return ""

    def _unknown_near(self, grid: np.ndarray, xy: tuple[float, float], radius_m: float) -> bool:
        g = self.geometry
        # g.world_to_grid's arithmetic on scalars (called every step: no arrays)
        ox, oy, res = g.origin_x_m, g.origin_y_m, g.resolution_m
        c0 = math.floor((float(xy[0] - radius_m) - ox) / res)
        r0 = math.floor((float(xy[1] - radius_m) - oy) / res)
        c1 = math.floor((float(xy[0] + radius_m) - ox) / res)
        r1 = math.floor((float(xy[1] + radius_m) - oy) / res)
        if r0 < 0 or c0 < 0 or r1 >= g.height or c1 >= g.width:
            return True  # the map's edge: beyond it is unknown
        return bool((grid[r0 : r1 + 1, c0 : c1 + 1] == UNKNOWN).any())

    # ------------------------------------------------------------------ hooks
    @property
    def goal_xy_m(self) -> tuple[float, float] | None:
        """The goal the robot drives to (metres, world frame), or None without a plan."""
        return self._plan.goal_xy_m if self._plan is not None else None

    @property
    def plan_source(self) -> PlanSource | None:
        """Where the current goal comes from (see :data:`PlanSource`), or None without a plan."""
        return self._plan.source if self._plan is not None else None

    def request_replan(self) -> None:
        """Replan (segmentation and goal selection) at the next ``act``."""
        self._next_replan_s = self._time_s

    def choose_goal(self, candidates: list[FrontierCandidate]) -> FrontierCandidate:
        """Pick the frontier to pursue among the scored ``candidates`` (cheapest ``C`` first).

        The default is goal commitment: keep the frontier pursued so far (same frontier
        pathway, or within ``commitment_radius_m`` of the old goal) unless the best one is
        cheaper by more than ``switch_margin``. Subclasses override it to choose otherwise.

        Args:
            candidates: The non-blacklisted candidates of this replan, at least one.
        """
        best = candidates[0]
        old = self._plan
        if (
            not self.params.goal_commitment
            or old is None
            or old.source != "semantic"
            or old.candidate is None
        ):
            return best
        same = [
            c
            for c in candidates
            if c.frontier.area_id == old.candidate.frontier.area_id
            or math.hypot(c.goal_xy_m[0] - old.goal_xy_m[0], c.goal_xy_m[1] - old.goal_xy_m[1])
            <= self.params.commitment_radius_m
        ]
        if not same:
            return best
        keep = min(same, key=lambda c: c.cost)
        if keep.cost <= best.cost + self.params.switch_margin:
            return keep
        if self.params.oscillation_guard and self.memory.recently_abandoned(
            best.goal_xy_m, self._time_s, self.params.oscillation_window_s
        ):
            # Switching back to a goal given up a moment ago would start a shuttle between two
            # frontiers whose costs trade places as the robot moves: finish this one first.
            self.counters["oscillations_blocked"] += 1
            return keep
        return best

    def on_replan_due(self, reason: str) -> None:
        """Called when a replan is due, just before it runs; does nothing by default.

        Args:
            reason: Why (one of :data:`REPLAN_REASONS`).
        """

    def on_replanned(self, source: PlanSource | None) -> None:
        """Called after every replan with :attr:`plan_source`; does nothing by default."""

    def frontier_candidates(
        self, obs: dict[str, np.ndarray], weights: FrontierCostWeights | None = None
    ) -> list[FrontierCandidate]:
        """Scored, non-blacklisted frontier candidates of ``obs`` (cheapest ``C`` first).

        Runs the pose identification and Algorithm 1 without changing the plan.

        Args:
            obs: The env observation (``map``, ``pose``).
            weights: Cost weights to score with (default: the policy's current ones).

        Raises:
            ValueError: called before ``reset``.
        """
        if self._segmenter is None:
            raise ValueError("frontier_candidates needs reset() first")
        prm = self.params
        grid = obs["map"]
        x_m, y_m, yaw_rad = (float(v) for v in obs["pose"][:3])
        tmap = self._segmenter(
            grid, self.geometry, self.clearance_m, params=prm.segmentation, previous=self.tmap
        )
        return self._scored_candidates(tmap, (x_m, y_m, yaw_rad), weights or prm.cost)

    # ------------------------------------------------------------------ planning
    def _replan(self, grid: np.ndarray, pose: tuple[float, float, float], stats: StepStats) -> None:
        """One replanning step: pose identification, then goal selection and its path."""
        prm = self.params
        stats.replanned = True
        self.counters["replans"] += 1
        self._next_replan_s = self._time_s + prm.replan_period_s
        t0 = time.perf_counter()
        tmap, segmented = self._update_topometric_map(grid)
        t1 = time.perf_counter()
        stats.map_generation_ms = (t1 - t0) * 1e3 if segmented else 0.0

        if segmented and self.memory.dropped:
            self._revive_dropped(grid)
        self.candidates = self._scored_candidates(tmap, pose, prm.cost)
        self._count_semantic_decisive(self.candidates)
        new_plan, clearance = None, None
        if self._retry is not None:
            new_plan, clearance = self._retry_plan(grid, pose)
        if new_plan is None:
            new_plan, clearance = self._semantic_plan(grid, pose)
        if new_plan is None and prm.grid_fallback:
            if clearance is None:
                clearance = clearance_field_m(grid, self.geometry.resolution_m)
            new_plan = self._committed_fallback_plan(grid, pose, clearance)
            if new_plan is None:
                new_plan = self._nearest_fallback_plan(grid, pose, clearance)
            if new_plan is None and prm.pocket_escape:
                new_plan = self._pocket_escape_plan(grid, pose, clearance)
        stats.global_planning_ms = (time.perf_counter() - t1) * 1e3

        if new_plan is None and prm.grid_fallback and prm.look_at_narrow_frontiers:
            if clearance is None:
                clearance = clearance_field_m(grid, self.geometry.resolution_m)
            new_plan = self._look_plan(grid, pose, clearance)
        if new_plan is None:
            self._give_up_plan()
        else:
            self._adopt_plan(new_plan)
        self.on_replanned(self.plan_source)

    def _count_semantic_decisive(self, candidates: list[FrontierCandidate]) -> None:
        """Count a replan whose cheapest frontier by ``C`` is not cheapest by the metric part.

        The metric part ``d / L_path + w_v v`` is ``C`` with ``w_p = w_I = 0``; both choices are
        made among the same candidates (the ones Algorithm 1 found with the full cost). A tie
        on the metric cost counts as agreement. ``semantic_decisive / scored_replans`` is the
        share of replans in which the semantic gain changed the chosen frontier.
        """
        if not candidates:
            return
        self.counters["scored_replans"] += 1
        best_metric = min(c.metric_cost for c in candidates)
        if candidates[0].metric_cost > best_metric + 1e-9:
            self.counters["semantic_decisive"] += 1

    def _update_topometric_map(self, grid: np.ndarray) -> tuple[TopometricMap, bool]:
        """The topometric map to plan on, and whether it was segmented anew."""
        prm = self.params
        assert self._segmenter is not None
        min_new = prm.resegment_min_new_m2 / self.geometry.resolution_m**2
        segmented = (
            self.tmap is None
            or self._last_reason != "period"
            or self._known_cells - self._seg_known_cells >= min_new
        )
        if not segmented:
            # Map-change gating: the map has hardly grown since the last segmentation (the
            # robot drives through explored space): search the same map from the new pose.
            assert self.tmap is not None
            return self.tmap, False
        self.tmap = self._segmenter(
            grid, self.geometry, self.clearance_m, params=prm.segmentation, previous=self.tmap
        )
        self._seg_known_cells = self._known_cells
        self._area_types = None
        self.counters["segmentations"] += 1
        return self.tmap, True

    def _scored_candidates(
        self, tmap: TopometricMap, pose: tuple[float, float, float], weights: FrontierCostWeights
    ) -> list[FrontierCandidate]:
        """Algorithm 1 from ``pose``: the non-blacklisted candidates, cheapest first."""
        prm = self.params
        cands, _ = search_frontier_paths(
            tmap,
            pose[:2],
            pose[2],
            weights,
            prune_by=prm.prune_by,
            min_frontier_width_m=prm.min_frontier_width_m,
        )
        return [c for c in cands if c.goal_xy_m not in self.blacklist]

    def _semantic_plan(
        self, grid: np.ndarray, pose: tuple[float, float, float]
    ) -> tuple[_Plan | None, np.ndarray | None]:
        """The plan to the chosen candidate (None: no candidate, or no way onto its path), and
        the clearance field if the entry check computed one."""
        if not self.candidates:
            return None, None
        chosen = self.choose_goal(self.candidates)
        path: np.ndarray | None = chosen.path_m
        clearance: np.ndarray | None = None
        if (
            self.params.entry_detour
            and len(chosen.path_m) >= 2
            and not segment_is_clear(grid, self.geometry, pose[:2], tuple(chosen.path_m[1]))
        ):
            # The straight first leg crosses a wall: reach the map's path over the grid.
            clearance = clearance_field_m(grid, self.geometry.resolution_m)
            detour = grid_path_to(
                grid,
                self.geometry,
                pose[:2],
                tuple(chosen.path_m[1]),
                self.clearance_m,
                clearance_field=clearance,
            )
            path = None if detour is None else np.vstack([detour, chosen.path_m[2:]])
            self.counters["entry_detours"] += int(detour is not None)
        if path is None:
            return None, clearance
        plan = _Plan(
            "semantic",
            chosen.goal_xy_m,
            resample_polyline(path, self.geometry.resolution_m),
            chosen,
        )
        return plan, clearance

    def _committed_fallback_plan(
        self, grid: np.ndarray, pose: tuple[float, float, float], clearance: np.ndarray
    ) -> _Plan | None:
        """Goal commitment for the fallback too: keep driving to the same frontier while it is
        there and reachable, rather than to whichever is nearest right now."""
        prm = self.params
        old = self._plan
        if (
            old is None
            or old.source != "fallback"
            or old.goal_xy_m in self.blacklist
            or math.hypot(pose[0] - old.goal_xy_m[0], pose[1] - old.goal_xy_m[1])
            <= prm.goal_reached_radius_m
            or not self._unknown_near(grid, old.goal_xy_m, prm.goal_check_radius_m)
        ):
            return None
        path = grid_path_to(
            grid,
            self.geometry,
            pose[:2],
            old.goal_xy_m,
            self.clearance_m,
            clearance_field=clearance,
        )
        if path is None:
            return None
        return _Plan(
            "fallback", old.goal_xy_m, resample_polyline(path, self.geometry.resolution_m), None
        )

    def _nearest_fallback_plan(
        self, grid: np.ndarray, pose: tuple[float, float, float], clearance: np.ndarray
    ) -> _Plan | None:
        """The nearest frontier a grid search with the robot's clearance reaches (or None)."""
        found = nearest_reachable_frontier(
            grid,
            self.geometry,
            pose[:2],
            self.clearance_m,
            frontiers=FrontierFilter(**self._fallback_search_kwargs()),
            clearance_field=clearance,
        )
        if found is None:
            return None
        res_m = self.geometry.resolution_m
        return _Plan("fallback", found.goal_xy_m, resample_polyline(found.path_m, res_m), None)

    def _fallback_search_kwargs(self) -> dict[str, Any]:
        """Which frontiers the grid check counts (the same for its every search)."""
        prm = self.params
        res_m = self.geometry.resolution_m
        return {
            "min_frontier_cells": max(1, math.ceil(prm.fallback_min_frontier_m / res_m - 1e-9)),
            "min_unknown_depth_cells": prm.fallback_min_unknown_depth_m / res_m,
            "reach_m": prm.fallback_reach_m,
            "excluded_xy_m": self.memory.active_points(),
            "excluded_radius_m": prm.blacklist_radius_m + prm.fallback_reach_m,
        }

    def _give_up_plan(self) -> None:
        """No frontier from either source: wait a step, stop after ``stop_confirmations``."""
        self._plan = None
        self._empty_replans += 1
        # Look again at the next step before giving up.
        self._next_replan_s = self._time_s
        if self._empty_replans >= self.params.stop_confirmations:
            self.done = True
            self.mode = "done"
            self.stop_reason = self._stop_reason()

    def _adopt_plan(self, new_plan: _Plan) -> None:
        """Follow ``new_plan`` from now on (logging a goal switch)."""
        self._empty_replans = 0
        old = self._plan
        if (
            old is None
            or math.hypot(
                old.goal_xy_m[0] - new_plan.goal_xy_m[0], old.goal_xy_m[1] - new_plan.goal_xy_m[1]
            )
            > self.params.commitment_radius_m
        ):
            if old is not None:
                self.counters["switches"] += 1
                self.memory.abandon(old.goal_xy_m, self._time_s)
            # A new goal gets a time budget: a few times the time its path takes at full speed.
            self._goal_since_s = self._time_s
            self._goal_budget_s = max(
                self.params.min_goal_time_s,
                self.params.goal_time_factor
                * self._remaining_m(new_plan)
                / self.limits.max_linear_speed_mps,
            )
            self._log("goal", f"{new_plan.source} {tuple(round(v, 2) for v in new_plan.goal_xy_m)}")
        if old is None or old.source != new_plan.source:
            self._log(
                new_plan.source,
                f"goal={new_plan.goal_xy_m}, {len(self.candidates)} semantic frontier(s)",
            )
        self._plan = new_plan
        # Progress is measured along each new path from its start (the robot's position): a
        # replanned route may be longer than the rest of the old one without anything being wrong.
        self._path_watch.track_path(self._remaining_m(new_plan))
        self.mode = new_plan.source
        self.counters["semantic_plans" if new_plan.source == "semantic" else "fallback_plans"] += 1

    # ------------------------------------------------------------------ following
    def _follow(
        self, grid: np.ndarray, pose: tuple[float, float, float], scan: np.ndarray
    ) -> tuple[float, float]:
        plan = self._plan
        assert plan is not None
        prm = self.params
        escaping = self._time_s < self._escape_until_s
        cmd = PotentialFieldFollower(self.limits, prm.potential_field).command(
            scan,
            pose,
            plan.path_m,
            grid,
            self.geometry,
            start_index=plan.progress,
            repulsion_scale=prm.escape_repulsion_scale if escaping else 1.0,
        )
        self._last_cmd = cmd
        self._advance_progress(plan, pose)
        if not escaping:
            self.mode = plan.source
            if cmd.v_mps < 0.1 * self.limits.max_linear_speed_mps:
                self._still_s += self.dt_s
            else:
                self._still_s = 0.0
            if prm.local_min_escape and self._still_s >= prm.local_min_timeout_s:
                self._still_s = 0.0
                self._escape_until_s = self._time_s + prm.escape_duration_s
                self.counters["escapes"] += 1
                self._log("escape", f"goal={plan.goal_xy_m}")
        else:
            self.mode = "escape"
        return cmd.v_mps, cmd.omega_radps

    def _advance_progress(self, plan: _Plan, pose: tuple[float, float, float]) -> None:
        # The nearest path point in a short window ahead: the part behind is done.
        lo = plan.progress
        hi = min(len(plan.path_m), lo + int(math.ceil(1.5 / self.geometry.resolution_m)) + 1)
        seg = plan.path_m[lo:hi]
        d = np.hypot(seg[:, 0] - pose[0], seg[:, 1] - pose[1])
        i = int(np.argmin(d))
        if d[i] <= 0.5:
            plan.progress = lo + i

    def _remaining_m(self, plan: _Plan) -> float:
        return float(plan.arc_m[-1] - plan.arc_m[plan.progress])

    # ------------------------------------------------------------------ stuck handling
    def _watch_progress(self, pose: tuple[float, float, float]) -> None:
        t = self._time_s
        stuck = self._motion_watch.update(t, (pose[0], pose[1]), self._known_cells)
        if self._plan is not None:
            self._path_watch.update(
                t, known_cells=self._known_cells, remaining_m=self._remaining_m(self._plan)
            )
        overdue = self._plan is not None and t - self._goal_since_s > self._goal_budget_s
        if overdue:
            # Moving, but not getting there (a limit cycle round clutter, a path that keeps
            # changing): treat it as a failed approach, so the goal is retried another way.
            self.counters["goal_timeouts"] += 1
            self._log("goal_timeout", f"goal={self.goal_xy_m}")
        if stuck or self._path_watch.stalled(t) or overdue:
            self._goal_since_s, self._goal_budget_s = t, math.inf
            self._start_recovery()

    def _log(self, event: str, detail: str = "") -> None:
        self.events.append((round(self._time_s, 2), event, detail))

    def _start_recovery(self) -> None:
        self.counters["recoveries"] += 1
        goal = self._plan.goal_xy_m if self._plan is not None else None
        self._log("recovery", f"goal={goal}")
        self._backoff.start(self._time_s, self.rng)
        self.mode = "recovery"
        self._reset_watchdogs()

    def _reset_watchdogs(self) -> None:
        until_s = self._time_s + self.params.backoff_duration_s
        self._motion_watch.hold(until_s, self._known_cells)
        self._path_watch.hold(until_s, self._known_cells)
        self._still_s = 0.0

    def _recovery_command(
        self, grid: np.ndarray, pose: tuple[float, float, float], scan: np.ndarray
    ) -> tuple[float, float]:
        assert self._angles is not None
        return self._backoff.command(
            grid, self.geometry, pose, scan, self._angles, self.limits, self.params.potential_field
        )

    # ------------------------------------------------------------------ drawing
    def overlay(self) -> dict[str, Any]:
        out: dict[str, Any] = {}
        if self.tmap is not None:
            if self._area_types is None:
                self._area_types = area_type_raster(self.tmap)
            out["area_types"] = self._area_types
        if self._plan is not None:
            out["paths_m"] = [self._plan.path_m]
            out["goal_m"] = self._plan.goal_xy_m
        out["frontiers_m"] = [c.goal_xy_m for c in self.candidates]
        if self._last_cmd is not None and self._plan is not None:
            out["points_m"] = [self._last_cmd.goal_xy_m]
        text = f"{self.name}: {self.mode}"
        if self.done:
            text += f" ({self.stop_reason})"
        out["text"] = text
        return out


def area_type_raster(tmap: TopometricMap) -> np.ndarray:
    """``(H, W)`` int16 raster of :class:`AreaType` values of the map's areas; -1 elsewhere."""
    ids = tmap.area_ids
    out = np.full(ids.shape, -1, dtype=np.int16)
    inside = ids >= 0
    if not inside.any() or not tmap.areas:
        return out
    uniq, inv = np.unique(ids[inside], return_inverse=True)
    lut = np.array(
        [int(tmap.areas[int(a)].type) if int(a) in tmap.areas else -1 for a in uniq], dtype=np.int16
    )
    out[inside] = lut[inv]
    return out
