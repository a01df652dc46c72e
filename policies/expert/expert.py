"""The paper's semantic exploration strategy as a scripted expert :class:`Policy`.

Each replanning step (section II of Fredriksson et al.):

1. **Pose identification.** Segment the observed occupancy grid into the semantic topometric
   map (``segment_map``); the frontiers ``F_i`` are those of its frontier pathways.
2. **Goal selection.** Algorithm 1 (:mod:`semexplore_gym.core.planning.graph_search`) finds the
   path along the map to every frontier and scores it with
   ``C = d / L_path + w_v v - (w_p p_l + w_I (O(I) + P_u(I)))``; ``F* = argmin C``.
3. **Navigation.** Every step, the modified potential field
   (:mod:`semexplore_gym.core.planning.potential_field`) follows the path to ``F*``.
4. **Stop.** The mission ends when no frontier remains.

The policy is honest: it reads only the observation and the static facts of ``info``, never
ground truth. What the paper leaves open, and the parameters for it:
:mod:`semexplore_gym.policies.expert.params`.

The parts
---------
:class:`SemanticExpertPolicy` schedules replans and holds three parts, built from its recipe
(:mod:`~semexplore_gym.policies.expert.recipes`) and a parameter group each:

* ``plan_sources``: the recipe's ordered :class:`PlanSource` objects
  (:mod:`~semexplore_gym.policies.expert.plan_sources`); at each replan the first
  :class:`Plan` proposed is adopted; when all pass, the expert waits, and stops after
  ``stop_confirmations`` such replans.
* ``goal_memory``: a :class:`~semexplore_gym.policies.expert.goal_memory.GoalMemory` with the
  recipe's goal rules (drops, reaches, retries, revivals, the trail, the stop reason).
* ``follower``: a :class:`~semexplore_gym.policies.expert.path_following.PathFollower`
  (potential field, local-minimum escape, progress watch, back-off recovery).

``counts`` (an ``ExpertCounters``) and ``events`` record what fired.

Plug-in points
--------------
For a learned frontier chooser, an oracle or a team coordinator; none needs a private member.
*Replace the frontier ranking*: give a ``ranker`` (candidates, cheapest ``C`` first, in; the
same candidates in the new order, ``cost`` rewritten if you like, out), or override
:meth:`~SemanticExpertPolicy.rank_frontiers`; goal commitment then works on the new order.
Override :meth:`~SemanticExpertPolicy.choose_goal` to pick outright::

    expert = SemanticExpertPolicy(ranker=lambda cands: sorted(cands, key=lambda c: c.d_m))

*Add a plan source*: a :class:`PlanSource` whose ``propose(ctx)`` returns a :class:`Plan` or
None, put where it belongs in the order of a recipe (the class attribute ``recipe``, or the
argument ``plan_sources``; ``recipe.with_source`` places one by name)::

    class TeamGoal(PlanSource):  # a coordinator's assignment before the expert's own choice
        name = "team"
        def propose(self, ctx):
            goal = coordinator.assignment(ctx.xy_m)  # None: no assignment now
            path = None if goal is None else ctx.grid_route(goal)
            return None if path is None else Plan(PlanKind.COMMANDED, goal, ctx.resampled(path))

    class TeamExpert(SemanticExpertPolicy):
        recipe = SEMANTIC_V4.with_source(TeamGoal(), before="semantic")

*Drive to this goal*: :meth:`~SemanticExpertPolicy.drive_to` commands a point in world
coordinates; the expert's navigation drives there over a clearance-aware grid route (with its
escapes and recoveries), then chooses again by itself. :attr:`~SemanticExpertPolicy.
commanded_goal_xy_m` turns None once the goal is reached, failed or unreachable::

    expert.drive_to((4.0, 2.5))
    while expert.commanded_goal_xy_m is not None:
        obs, *_ = env.step(expert.act(obs, info))

Also: ``on_replan_due``, ``on_replanned``, ``request_replan``, ``frontier_candidates``.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from semexplore_gym.policies.base import Policy, StepStats, read_env_facts
from semexplore_gym.policies.expert.counters import ExpertCounters
from semexplore_gym.policies.expert.drawing import area_type_raster
from semexplore_gym.policies.expert.goal_memory import GoalMemory
from semexplore_gym.policies.expert.map_reading import MapReader
from semexplore_gym.policies.expert.params import SemanticExpertParams
from semexplore_gym.policies.expert.path_following import PathFollower
from semexplore_gym.policies.expert.plan import ExpertMode, Plan, PlanKind
from semexplore_gym.policies.expert.plan_sources import (
    DEFAULT_PLAN_SOURCES,
    PlanContext,
    PlanSource,
    goal_open,
    insert_plan_source,
)
from semexplore_gym.policies.expert.recipes import SEMANTIC_V4, ExpertRecipe

from semexplore_gym.core.planning.graph_search import (
    FrontierCandidate,
    FrontierCostWeights,
    search_frontier_paths,
)
from semexplore_gym.core.planning.grid_scan import known_cell_count
from semexplore_gym.core.planning.potential_field import RobotLimits
from semexplore_gym.core.topometric.types import TopometricMap

__all__ = [
    "DEFAULT_PLAN_SOURCES",
    "REPLAN_REASONS",
    "ExpertMode",
    "FrontierRanker",
    "Plan",
    "PlanContext",
    "PlanKind",
    "PlanSource",
    "Segmenter",
    "SemanticExpertParams",
    "SemanticExpertPolicy",
    "area_type_raster",
    "insert_plan_source",
]

Segmenter = Callable[..., TopometricMap]

#: Re-ranks Algorithm 1's candidates (cheapest ``C`` first in; the chosen order out).
FrontierRanker = Callable[[list[FrontierCandidate]], list[FrontierCandidate]]

#: Why a replan runs (``counters["replan_<reason>"]``, :meth:`SemanticExpertPolicy.on_replan_due`).
REPLAN_REASONS = ("no_plan", "period", "goal_reached", "path_done", "goal_vanished")


class SemanticExpertPolicy(Policy):
    """The paper's exploration strategy (semantic goal selection + modified potential field).

    Args:
        params: Parameters (default: the paper's weights and our robustness settings).
        segmenter: ``segment_map``-compatible callable ``(grid, geometry, clearance_m,
            params=..., previous=...) -> TopometricMap``; default a
            :class:`semexplore_gym.core.topometric.TopometricSegmenter` of its own.
        ranker: Re-ranks the scored frontiers before goal commitment (see the module
            docstring); default none (cheapest ``C`` first).
        plan_sources: The plan sources in the order they are asked (default: the recipe's).
        recipe: Its parts (default :attr:`recipe`, today's); ``make_policy`` layers its
            parameter values below ``params``.

    Attributes (after ``reset``): ``tmap`` the last topometric map, ``candidates`` the scored
    frontiers of the last replan, ``mode`` an :class:`ExpertMode`, ``counts`` and ``events``
    (what fired, and when), ``goal_memory`` and ``follower`` (the parts).
    """

    name = "semantic"
    reads_map_in_step_only = True  # tested: missions identical with a copied or a shared map
    #: What the expert is made of: its plan sources and goal rules (see the module docstring).
    recipe: ExpertRecipe = SEMANTIC_V4
    plan_sources: tuple[PlanSource, ...]

    def __init__(
        self,
        params: SemanticExpertParams | None = None,
        segmenter: Segmenter | None = None,
        ranker: FrontierRanker | None = None,
        plan_sources: Sequence[PlanSource] | None = None,
        recipe: ExpertRecipe | None = None,
    ) -> None:
        super().__init__()
        prm = params if params is not None else SemanticExpertParams()
        #: The parameters; the parts take their groups at ``reset`` (and construction).
        self.params: SemanticExpertParams = prm
        self.counts = ExpertCounters()
        self.events: list[tuple[float, str, str]] = []
        self._time_s = 0.0
        self.recipe = recipe if recipe is not None else type(self).recipe
        rules = self.recipe.goal_rules
        self.goal_memory = GoalMemory(prm.goal_memory, self.counts, self._log, rules)
        self.follower = PathFollower(prm.path_following, self.counts, self._log)
        self._segmenter = segmenter
        self.ranker = ranker
        mine = plan_sources if plan_sources is not None else self.recipe.plan_sources
        self.plan_sources = tuple(mine)
        self.tmap: TopometricMap | None = None
        self.candidates: list[FrontierCandidate] = []
        self.mode = ExpertMode.IDLE
        self._plan: Plan | None = None

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
        self.tmap, self.candidates, self.mode, self.events = None, [], ExpertMode.IDLE, []
        part = self.recipe.map_reading
        self._map_reader = (
            MapReader(self.params.sliver_max_width_m, self.geometry.resolution_m)
            if part is not None and part.applies(info, self.params.sliver_maps)
            else None
        )
        self.counts.clear()
        self._time_s, self._next_replan_s, self._plan = 0.0, 0.0, None
        self._last_reason, self._min_range_m = "", facts.min_range_m
        self._seg_known_cells = self._empty_replans = 0
        self._area_types: np.ndarray | None = None
        self._known_cells = known_cell_count(self.read_map(obs))
        self.goal_memory.reset(self.geometry, self.params.goal_memory)
        xy_m = (float(obs["pose"][0]), float(obs["pose"][1]))
        where = (self.geometry, self.limits, self.dt_s, xy_m, self._known_cells)
        self.follower.reset(*where, self.params.path_following, min_range_m=self._min_range_m)

    # ------------------------------------------------------------------ stepping
    def act(self, obs: dict[str, np.ndarray], info: dict[str, Any]) -> np.ndarray:
        t_start = time.perf_counter()
        stats = StepStats()
        if self.done:
            self.last_stats = stats
            return np.zeros(2, dtype=np.float32)
        grid = self.read_map(obs)
        p = obs["pose"]
        pose = (float(p[0]), float(p[1]), float(p[2]))
        scan = np.asarray(obs["scan"], dtype=np.float64)
        self._known_cells = known_cell_count(grid)
        self.goal_memory.visit((pose[0], pose[1]))
        follower, now_s = self.follower, self._time_s
        if follower.recovering(now_s):
            v, w = follower.recovery_command(grid, pose, scan)
            self.mode = ExpertMode.RECOVERY
        else:
            if follower.recovery_ended():
                # Recovery just ended: retry the goal that got us stuck another way, or drop it.
                self._goal_failed(grid, pose)
            if self._needs_replan(grid, pose):
                self._replan(grid, pose, stats)
            plan = self._plan
            if self.done:
                v, w = 0.0, 0.0
            elif plan is None:
                v, w = 0.0, 0.0
                self.mode = ExpertMode.WAITING
            else:
                v, w, escaping = follower.follow(plan, grid, pose, scan, now_s)
                self.mode = ExpertMode.ESCAPE if escaping else ExpertMode(plan.kind.value)
                if follower.watch(plan, pose, now_s, self._known_cells, self.rng):
                    self.mode = ExpertMode.RECOVERY
                if follower.recovering(now_s):
                    v, w = follower.recovery_command(grid, pose, scan)
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

    def _goal_failed(self, grid: np.ndarray, pose: tuple[float, float, float]) -> None:
        """A stuck recovery ended: the goal memory retries the goal another way or drops it."""
        plan = self._plan
        self._plan = None
        self.request_replan()
        if plan is not None:
            self.goal_memory.goal_failed(grid, plan, (pose[0], pose[1]))

    def _needs_replan(self, grid: np.ndarray, pose: tuple[float, float, float]) -> bool:
        reason = self._replan_reason(grid, pose)
        self._last_reason = reason
        if reason:
            self.counts.count_replan_reason(reason)
            self.on_replan_due(reason)
        return bool(reason)

    def _replan_reason(self, grid: np.ndarray, pose: tuple[float, float, float]) -> str:
        plan = self._plan
        if plan is None:
            return "no_plan"
        if self._time_s >= self._next_replan_s - 1e-9 and not self.follower.tight(plan):
            return "period"
        reach_m = plan.reached_within_m or self.params.goal_reached_radius_m
        if math.hypot(pose[0] - plan.goal_xy_m[0], pose[1] - plan.goal_xy_m[1]) <= reach_m:
            self.goal_memory.goal_reached(grid, plan, (pose[0], pose[1]))
            return "goal_reached"
        if plan.progress >= len(plan.path_m) - 1:
            return "path_done"
        # Goal vanished: no frontier (vanish_on_frontier; else unknown) cell is left near it. A
        # commanded goal may lie in known space: it lasts until reached; a view's is its frontier.
        view = plan.kind == PlanKind.VIEW and plan.frontier_xy_m is not None
        watched = plan.frontier_xy_m if view and plan.frontier_xy_m else plan.goal_xy_m
        radius_m, rules = self.params.goal_check_radius_m, self.goal_memory.rules
        if plan.kind != PlanKind.COMMANDED and not goal_open(
            grid, self.geometry, watched, radius_m, on_frontier=rules.vanish_on_frontier
        ):
            return "goal_vanished"
        return ""

    def read_map(self, obs: dict[str, np.ndarray]) -> np.ndarray:
        """``obs["map"]`` as the expert reads it: with its wall slivers read as wall where the
        recipe's ``map_reading`` applies (:mod:`.map_reading`)."""
        reader = getattr(self, "_map_reader", None)
        return obs["map"] if reader is None else reader(obs["map"])

    # ------------------------------------------------------------------ read-outs
    @property
    def plan(self) -> Plan | None:
        """The plan followed now (None: none)."""
        return self._plan

    @property
    def goal_xy_m(self) -> tuple[float, float] | None:
        """The goal the robot drives to (metres, world frame), or None without a plan."""
        return self._plan.goal_xy_m if self._plan is not None else None

    @property
    def plan_source(self) -> PlanKind | None:
        """Where the current goal comes from (see :class:`PlanKind`), or None without a plan."""
        return self._plan.kind if self._plan is not None else None

    @property
    def time_s(self) -> float:
        """The expert's clock (simulated seconds since ``reset``)."""
        return self._time_s

    @property
    def counters(self) -> dict[str, int]:
        """The mission's counts as ``{name: int}`` (``replan_<reason>`` for each reason seen)."""
        return self.counts.as_dict()

    def mission_metrics(self) -> dict[str, Any]:
        """``scored_replans`` and ``semantic_share`` (the share of scored replans in which the
        semantic gain changed the chosen frontier; None before any scored replan)."""
        return {
            "scored_replans": int(self.counts.scored_replans),
            "semantic_share": self.counts.semantic_share(),
        }

    # ------------------------------------------------------------------ hooks
    def request_replan(self) -> None:
        """Replan (segmentation and goal selection) at the next ``act``."""
        self._next_replan_s = self._time_s

    def resume(self) -> None:
        """Restart a stopped expert: not done, no stop reason, idle, replanning at next ``act``."""
        self.done, self.stop_reason, self.mode, self._empty_replans = False, "", ExpertMode.IDLE, 0
        self.request_replan()

    @property
    def commanded_goal_xy_m(self) -> tuple[float, float] | None:
        """The goal commanded by :meth:`drive_to`; None once reached, failed or unreachable."""
        return self.goal_memory.commanded_xy_m

    def drive_to(self, goal_xy_m: tuple[float, float] | None) -> None:
        """Drive to ``goal_xy_m`` (metres, world frame) from the next ``act`` on.

        The ``commanded`` plan source plans a clearance-aware grid route there; the path
        following drives it (escapes, recoveries included). Once the goal is reached, its
        approach fails or no route reaches it, the command ends. None ends it now.
        """
        xy = None if goal_xy_m is None else (float(goal_xy_m[0]), float(goal_xy_m[1]))
        self.goal_memory.command(xy)
        self.request_replan()

    def rank_frontiers(self, candidates: list[FrontierCandidate]) -> list[FrontierCandidate]:
        """The scored candidates in the order goal commitment should prefer them.

        Default: the ``ranker``'s order if one was given, else Algorithm 1's (cheapest ``C``
        first). Subclasses override it to rank by another value (keep ``cost`` consistent
        with the order: the switch margin compares costs).
        """
        return self.ranker(candidates) if self.ranker is not None else candidates

    def choose_goal(self, candidates: list[FrontierCandidate]) -> FrontierCandidate:
        """Pick the frontier to pursue among the scored ``candidates`` (cheapest ``C`` first).

        The default ranks them (:meth:`rank_frontiers`), then applies goal commitment
        (:meth:`keep_committed_goal`). Subclasses override it to choose otherwise.

        Args:
            candidates: The non-blacklisted candidates of this replan, at least one.
        """
        return self.keep_committed_goal(self.rank_frontiers(candidates))

    def keep_committed_goal(self, ranked: list[FrontierCandidate]) -> FrontierCandidate:
        """Goal commitment: the frontier pursued so far (same frontier pathway, or within
        ``commitment_radius_m`` of the old goal) unless the first of ``ranked`` is cheaper by
        more than ``switch_margin``; the oscillation guard may keep it even then."""
        best = ranked[0]
        old = self._plan
        if (
            not self.params.goal_commitment
            or old is None
            or old.kind != PlanKind.SEMANTIC
            or old.candidate is None
        ):
            return best
        held = self.goal_memory.shuttle_candidate(ranked)
        if held is not None:  # adopted again without the map growing: see it through
            return held
        same = [
            c
            for c in ranked
            if c.frontier.area_id == old.candidate.frontier.area_id
            or math.hypot(c.goal_xy_m[0] - old.goal_xy_m[0], c.goal_xy_m[1] - old.goal_xy_m[1])
            <= self.params.commitment_radius_m
        ]
        if not same:
            return best
        keep = min(same, key=lambda c: c.cost)
        if keep.cost <= best.cost + self.params.switch_margin:
            return keep
        if self.goal_memory.recently_abandoned(best.goal_xy_m, self._time_s):
            # Switching back to a goal given up a moment ago would start a shuttle between two
            # frontiers whose costs trade places as the robot moves: finish this one first.
            self.counts.oscillations_blocked += 1
            return keep
        return best

    def on_replan_due(self, reason: str) -> None:
        """Called when a replan is due (``reason``: one of :data:`REPLAN_REASONS`), just before
        it runs; does nothing by default."""

    def on_replanned(self, source: PlanKind | None) -> None:
        """Called after every replan with :attr:`plan_source`; does nothing by default."""

    def frontier_candidates(
        self, obs: dict[str, np.ndarray], weights: FrontierCostWeights | None = None
    ) -> list[FrontierCandidate]:
        """Scored, non-blacklisted frontier candidates of ``obs`` (``map``, ``pose``), cheapest
        ``C`` by ``weights`` (default: the current ones) first; the plan stays as it is.

        Raises:
            ValueError: called before ``reset``.
        """
        if self._segmenter is None:
            raise ValueError("frontier_candidates needs reset() first")
        prm = self.params
        grid = self.read_map(obs)
        x_m, y_m, yaw_rad = (float(v) for v in obs["pose"][:3])
        tmap = self._segmenter(
            grid, self.geometry, self.clearance_m, params=prm.segmentation, previous=self.tmap
        )
        return self._scored_candidates(tmap, (x_m, y_m, yaw_rad), weights or prm.cost)

    # ------------------------------------------------------------------ planning
    def _replan(self, grid: np.ndarray, pose: tuple[float, float, float], stats: StepStats) -> None:
        """One replanning step: pose identification, then the plan sources in order."""
        prm = self.params
        stats.replanned = True
        self.counts.replans += 1
        self._next_replan_s = self._time_s + prm.replan_period_s
        t0 = time.perf_counter()
        tmap, segmented = self._update_topometric_map(grid)
        t1 = time.perf_counter()
        stats.map_generation_ms = (t1 - t0) * 1e3 if segmented else 0.0
        if segmented:
            self.goal_memory.revive(grid)
        self.candidates = self._scored_candidates(tmap, pose, prm.cost)
        self.counts.record_scored_replan(self.candidates)
        ctx = PlanContext(
            grid=grid,
            pose=pose,
            geometry=self.geometry,
            params=prm,
            clearance_m=self.clearance_m,
            robot_radius_m=self.limits.radius_m,
            candidates=self.candidates,
            current=self._plan,
            memory=self.goal_memory,
            counts=self.counts,
            choose_goal=self.choose_goal,
            log=self._log,
            lidar_range_m=(self._min_range_m, self.limits.max_range_m),
            time_s=self._time_s,
        )
        new_plan = None
        for source in self.plan_sources:
            new_plan = source.propose(ctx)
            if new_plan is not None:
                break
        stats.global_planning_ms = (time.perf_counter() - t1) * 1e3
        if new_plan is None:
            self._give_up_plan()
        else:
            self._adopt_plan(new_plan)
        self.on_replanned(self.plan_source)

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
        self.counts.segmentations += 1
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
        return [c for c in cands if not self.goal_memory.is_blacklisted(c.goal_xy_m)]

    def _give_up_plan(self) -> None:
        """Every source passed: wait a step, stop after ``stop_confirmations``."""
        self._plan = None
        self._empty_replans += 1
        self._next_replan_s = self._time_s  # look again at the next step before giving up
        if self._empty_replans >= self.params.stop_confirmations:
            self.done = True
            self.mode = ExpertMode.DONE
            self.stop_reason = self.goal_memory.stop_reason()

    def _adopt_plan(self, new_plan: Plan) -> None:
        """Follow ``new_plan`` from now on (logging a goal switch)."""
        self._empty_replans = 0
        old = self._plan
        kind = str(new_plan.kind)
        if (
            old is None
            or math.hypot(
                old.goal_xy_m[0] - new_plan.goal_xy_m[0], old.goal_xy_m[1] - new_plan.goal_xy_m[1]
            )
            > self.params.commitment_radius_m
        ):
            if old is not None:
                self.counts.switches += 1
                self.goal_memory.abandon(old.goal_xy_m, self._time_s)
            self.goal_memory.adopt(new_plan.goal_xy_m, self._known_cells)
            self.follower.start_goal(new_plan, self._time_s)
            self._log("goal", f"{kind} {tuple(round(v, 2) for v in new_plan.goal_xy_m)}")
        if old is None or old.kind != new_plan.kind:
            self._log(
                kind, f"goal={new_plan.goal_xy_m}, {len(self.candidates)} semantic frontier(s)"
            )
        self._plan = new_plan
        self.follower.track(new_plan)
        self.mode = ExpertMode(kind)
        if new_plan.kind == PlanKind.SEMANTIC:
            self.counts.semantic_plans += 1
        else:
            self.counts.fallback_plans += 1

    def _log(self, event: str, detail: str = "") -> None:
        self.events.append((round(self._time_s, 2), event, detail))

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
        if self.follower.last_command is not None and self._plan is not None:
            out["points_m"] = [self.follower.last_command.goal_xy_m]
        text = f"{self.name}: {self.mode}"
        if self.done:
            text += f" ({self.stop_reason})"
        out["text"] = text
        return out

