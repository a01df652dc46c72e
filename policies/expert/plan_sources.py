"""The sources that propose the semantic expert's plans.

A :class:`~semexplore_gym.policies.expert.plan.Plan` is where the robot drives and along which
path. At each replan the expert asks its :class:`PlanSource` objects in order
(``SemanticExpertPolicy.plan_sources``); the first plan proposed is adopted, and when every
source passes the expert waits a step and, after ``stop_confirmations`` such replans, stops.
The default order (:data:`DEFAULT_PLAN_SOURCES`; :func:`insert_plan_source` adds one):

======================  ======================================================================
source                  proposes
======================  ======================================================================
``commanded``           the goal commanded from outside (``drive_to``), over a grid route
``retry``               another approach to a goal whose approach failed (a grid route, then
                        another side of its frontier), or drops it
``view``                a place that sees into a frontier reached (or looked at) without its
                        unknown side becoming known, or drops it when no reachable place does
``semantic``            Algorithm 1's chosen frontier along the topometric map (the paper)
``committed_fallback``  the grid fallback's goal of the last plan, while it lasts
``nearest_fallback``    the nearest frontier a clearance-aware grid search reaches
``pocket_escape``       out of a pocket of the usable map, then to a frontier outside it
``room_beyond_gap``     through a gap narrower than the clearance into room the map shows
                        beyond it, with a frontier (in
                        :mod:`~semexplore_gym.policies.expert.narrow_sources`)
``narrow_fallback``     the nearest frontier a grid search reaches with a thinner clearance
                        (``narrow_passages``), through passages followed slowly and exactly
``look``                close to a frontier too narrow to reach, to look again
======================  ======================================================================

Every source reads what it needs from a :class:`PlanContext` and keeps no state of its own (the
goal memory and the counters are the expert's), so one instance serves every expert. Which
sources an expert asks, and which variant of each, is its recipe's
(:mod:`~semexplore_gym.policies.expert.recipes`): the paper's method lists ``commanded``,
``retry`` and ``semantic`` (the map's path) only; ``narrow_fallback`` passes unless the user
switches ``narrow_passages`` on.
"""

from __future__ import annotations

import math

import numpy as np
from semexplore_gym.policies.expert.goal_memory import TRAIL_CELL_M
from semexplore_gym.policies.expert.narrow_sources import (
    NARROW_REACHED_M,
    NarrowFallback,
    RoomBeyondGap,
)
from semexplore_gym.policies.expert.plan import Plan, PlanKind
from semexplore_gym.policies.expert.plan_context import (
    PlanContext,
    PlanSource,
    goal_open,
    path_clearance_along,
    standable_prefix,
    unknown_near,
)
from semexplore_gym.policies.navigation.side_approach import side_approach

from semexplore_gym.core.frontiers.reachable import (
    nearest_reachable_frontier,
    pocket_exit_path,
)
from semexplore_gym.core.frontiers.viewpoint import (
    ViewSearch,
    find_view_pose,
    unknown_extent_cells,
    unknown_rim,
)
from semexplore_gym.core.planning.graph_search import FrontierCandidate, metric_cost
from semexplore_gym.core.planning.line_of_sight import segment_is_clear
from semexplore_gym.core.planning.polyline import heading_angle

__all__ = [
    "DEFAULT_PLAN_SOURCES",
    "CommandedGoal",
    "CommittedFallback",
    "LookAtNarrowFrontier",
    "NearestFallback",
    "PlanContext",
    "PlanSource",
    "PocketEscape",
    "RetryFailedGoal",
    "SemanticFrontier",
    "ViewFrontier",
    "goal_open",
    "insert_plan_source",
    "path_clearance_along",
    "standable_prefix",
    "unknown_near",
]

#: A view place counts as reached this close (its line of sight holds from about there).
VIEW_REACHED_M = 0.15

#: Narrow frontiers checked against the trail before one is worth driving to.
MAX_LOOK_CANDIDATES = 8


class CommandedGoal(PlanSource):
    """The goal commanded from outside (``drive_to``), over a grid route with the clearance.

    A commanded goal no grid route reaches is given up (``command_unreachable`` event) and the
    expert chooses again by itself.
    """

    name = "commanded"

    def propose(self, ctx: PlanContext) -> Plan | None:
        goal = ctx.memory.commanded_xy_m
        if goal is None:
            return None
        path = ctx.grid_route(goal)
        if path is None:
            ctx.memory.end_command("command_unreachable")
            return None
        return Plan(PlanKind.COMMANDED, goal, ctx.resampled(path))


class RetryFailedGoal(PlanSource):
    """The next approach to a failed goal: a grid route, then another side (or drop it)."""

    name = "retry"

    def propose(self, ctx: PlanContext) -> Plan | None:
        retry = ctx.memory.retry
        if retry is None:
            return None
        goal = retry.goal_xy_m
        if not unknown_near(ctx.grid, ctx.geometry, goal, ctx.params.goal_check_radius_m):
            ctx.memory.retry = None  # its frontier got mapped meanwhile
            return None
        target, path = goal, None
        if retry.failures == 1:
            path = ctx.grid_route(goal)
        else:
            found = side_approach(
                ctx.grid,
                ctx.geometry,
                ctx.xy_m,
                goal,
                retry.failed_at_xy_m,
                ctx.clearance_m,
                ctx.clearance_field(),
            )
            if found is not None:
                target, path = found
        if path is None and ctx.params.narrow_passages and retry.failures == 1:
            # Graded clearance: a way through passages narrower than the planners' clearance.
            path = ctx.narrow_route(goal)
            if path is not None:
                dense = ctx.resampled(path)
                return Plan(
                    PlanKind.RETRY,
                    goal,
                    dense,
                    frontier_xy_m=goal,
                    reached_within_m=NARROW_REACHED_M,
                    path_clearance_m=path_clearance_along(ctx, dense, ctx.known_clearance_field()),
                )
        if path is None:
            # The grid planner finds no way for the robot's disc: the goal is unreachable now.
            ctx.memory.retry = None
            ctx.memory.drop(ctx.grid, goal, "grid")
            return None
        return Plan(PlanKind.RETRY, target, ctx.resampled(path), frontier_xy_m=goal)


class ViewFrontier(PlanSource):
    """A place that sees into a frontier reached (or looked at) without clearing it.

    The goal memory asks for it (``memory.view``) instead of dropping such a frontier. The
    place is the nearest reachable cell with a line of sight over known free cells to the
    unknown cells next to the frontier, within the LiDAR's resolved range, away from every place
    the robot has been (its trail: its LiDAR had its chance there; :func:`~semexplore_gym.core.
    frontiers.viewpoint.find_view_pose`): with the planner's clearance first, then with the
    robot radius plus ``view_clearance_margin_m``.
    When there is none the frontier is dropped (``unseeable``); so is a frontier with less than
    ``view_min_unknown_m2`` of unknown behind it (``sliver``).
    """

    name = "view"

    def propose(self, ctx: PlanContext) -> Plan | None:
        cur = ctx.current
        if cur is not None and cur.kind == PlanKind.VIEW and cur.frontier_xy_m is not None:
            return self._keep(ctx, cur, cur.frontier_xy_m)
        req = ctx.memory.view
        if req is None:
            return None
        ctx.memory.view = None
        prm = ctx.params
        xy = req.frontier_xy_m
        if not unknown_near(ctx.grid, ctx.geometry, xy, prm.goal_check_radius_m):
            return None  # it cleared meanwhile
        if self._sliver(ctx, xy):
            ctx.memory.drop(ctx.grid, xy, "sliver")
            return None
        near_m = ctx.lidar_range_m[0] + prm.view_min_range_margin_m
        far_m = max(
            prm.view_range_fraction * ctx.lidar_range_m[1], near_m + ctx.geometry.resolution_m
        )
        thin_m = min(ctx.robot_radius_m + prm.view_clearance_margin_m, ctx.clearance_m)
        # Where the robot has been, its LiDAR had its chance: a rim cell in sight from there on
        # the grid is hidden in fact (a wall's face inside the cell). Look from elsewhere.
        trail = ctx.memory.trail_near(xy, far_m + prm.view_rim_radius_m + TRAIL_CELL_M)
        view = ViewSearch(
            (near_m, far_m),
            prm.view_rim_radius_m,
            [req.looked_from_xy_m, ctx.xy_m, *trail],
            TRAIL_CELL_M,
        )
        for clearance_m in dict.fromkeys((ctx.clearance_m, thin_m)):
            found = find_view_pose(
                ctx.grid, ctx.geometry, ctx.xy_m, xy, clearance_m, view, ctx.clearance_field()
            )
            if found is not None:
                ctx.counts.view_drives += 1
                ctx.log(
                    "view",
                    f"frontier {tuple(round(v, 2) for v in xy)} from "
                    f"{tuple(round(v, 2) for v in found.goal_xy_m)} "
                    f"({found.n_visible}/{found.n_rim} unknown cells in sight)",
                )
                path = ctx.resampled(found.path_m)
                return Plan(PlanKind.VIEW, found.goal_xy_m, path, None, xy, VIEW_REACHED_M)
        ctx.memory.drop(ctx.grid, xy, "unseeable")
        return None

    @staticmethod
    def _sliver(ctx: PlanContext, xy: tuple[float, float]) -> bool:
        """Whether less than ``view_min_unknown_m2`` of unknown hangs on the frontier's rim."""
        need = math.ceil(ctx.params.view_min_unknown_m2 / ctx.geometry.resolution_m**2)
        if need <= 0:
            return False
        rows, cols = unknown_rim(ctx.grid, ctx.geometry, xy, ctx.params.view_rim_radius_m)
        return unknown_extent_cells(ctx.grid, rows, cols, need) < need

    @staticmethod
    def _keep(ctx: PlanContext, cur: Plan, xy: tuple[float, float]) -> Plan | None:
        """The view under way, until its frontier is mapped or dropped, or its path is done
        (then the robot looked from about there: dropped as viewed)."""
        if ctx.memory.is_blacklisted(xy) or not unknown_near(
            ctx.grid, ctx.geometry, xy, ctx.params.goal_check_radius_m
        ):
            return None
        if cur.progress >= len(cur.path_m) - 1:
            ctx.memory.drop(ctx.grid, xy, "viewed")
            return None
        return cur


class SemanticFrontier(PlanSource):
    """Algorithm 1's frontier (the expert's ``choose_goal``) along the topometric map's path.

    A recipe picks the variant (all three on: today's expert; all off: the paper's method):

    Args:
        grid_candidate: The grid's nearest frontier competes with Algorithm 1's choice, scored
            by the same ``C`` without semantic terms (``d / L_path + w_v * v``): frontiers the
            topometric map has no pathway for (or reaches the long way) are explored as the
            robot passes them. A goal the shuttle guard holds is seen through against it.
        grid_route: The robot drives to Algorithm 1's goal over the grid's clearance-aware
            route (the map's path runs through the skeleton, by the middle of every area and
            intersection on the way; the route cuts those corners at the planners' clearance);
            the map's path where the grid has none.
        entry_detour: When the straight first leg from the robot to the map's path crosses a
            wall, a grid route leads onto the path instead (none: pass).
    """

    name = "semantic"

    def __init__(
        self, *, grid_candidate: bool = True, grid_route: bool = True, entry_detour: bool = True
    ) -> None:
        self.grid_candidate = bool(grid_candidate)
        self.grid_route = bool(grid_route)
        self.entry_detour = bool(entry_detour)

    def __repr__(self) -> str:
        return (
            f"SemanticFrontier(grid_candidate={self.grid_candidate}, "
            f"grid_route={self.grid_route}, entry_detour={self.entry_detour})"
        )

    def propose(self, ctx: PlanContext) -> Plan | None:
        if not ctx.candidates:
            return None
        chosen = ctx.choose_goal(ctx.candidates)
        # A goal the shuttle guard holds is seen through: the grid's frontier must not take
        # turns with it (the two sources would shuttle between them as Algorithm 1's did).
        if self.grid_candidate and not ctx.memory.is_shuttle_goal(chosen.goal_xy_m):
            nearer = _cheaper_grid_frontier(ctx, chosen)
            if nearer is not None:
                return nearer
        path: np.ndarray | None = chosen.path_m
        route = ctx.grid_route(chosen.goal_xy_m) if self.grid_route else None
        if route is not None:
            path = route
            ctx.counts.semantic_grid_routes += 1
        elif (
            self.entry_detour
            and len(chosen.path_m) >= 2
            and not segment_is_clear(ctx.grid, ctx.geometry, ctx.xy_m, tuple(chosen.path_m[1]))
        ):
            detour = ctx.grid_route(tuple(chosen.path_m[1]))
            path = None if detour is None else np.vstack([detour, chosen.path_m[2:]])
            ctx.counts.entry_detours += int(detour is not None)
        if path is None:
            return None
        return Plan(PlanKind.SEMANTIC, chosen.goal_xy_m, ctx.resampled(path), chosen)


def _cheaper_grid_frontier(ctx: PlanContext, chosen: FrontierCandidate) -> Plan | None:
    """The grid's nearest frontier when it costs less than Algorithm 1's ``chosen``.

    It is scored by the same ``C`` with no semantic gain (``d / L_path + w_v * v``, the
    ``L_path`` of this replan), so a frontier the topometric map has no pathway for, or reaches
    only the long way round, is taken as the robot passes it rather than left for the end. A
    grid frontier within the commitment radius of ``chosen`` is the same goal: Algorithm 1's
    plan stands.
    """
    found = ctx.nearest_grid_frontier()
    if found is None or (
        math.dist(found.goal_xy_m, chosen.goal_xy_m) <= ctx.params.commitment_radius_m
    ):
        return None
    w = ctx.params.cost
    v_rad = heading_angle(found.path_m, ctx.xy_m, ctx.pose[2], w.heading_lookahead_m)
    cost = metric_cost(found.path_length_m, v_rad, chosen.l_path_m, w)
    if cost >= chosen.cost:
        return None
    ctx.counts.grid_frontier_plans += 1
    return Plan(PlanKind.FALLBACK, found.goal_xy_m, ctx.resampled(found.path_m))


class CommittedFallback(PlanSource):
    """Goal commitment for the grid fallback: the last fallback goal while it is there and
    reachable, rather than whichever frontier is nearest right now."""

    name = "committed_fallback"

    def propose(self, ctx: PlanContext) -> Plan | None:
        prm = ctx.params
        old = ctx.current
        if (
            old is None
            or old.kind != PlanKind.FALLBACK
            or ctx.memory.is_blacklisted(old.goal_xy_m)
            or math.hypot(ctx.pose[0] - old.goal_xy_m[0], ctx.pose[1] - old.goal_xy_m[1])
            <= prm.goal_reached_radius_m
            or not goal_open(
                ctx.grid,
                ctx.geometry,
                old.goal_xy_m,
                prm.goal_check_radius_m,
                on_frontier=ctx.memory.rules.vanish_on_frontier,
            )
        ):
            return None
        path = ctx.grid_route(old.goal_xy_m)
        if path is None:
            return None
        return Plan(PlanKind.FALLBACK, old.goal_xy_m, ctx.resampled(path))


class NearestFallback(PlanSource):
    """The nearest frontier a grid search with the robot's clearance reaches."""

    name = "nearest_fallback"

    def propose(self, ctx: PlanContext) -> Plan | None:
        found = ctx.nearest_grid_frontier()
        if found is None:
            return None
        return Plan(PlanKind.FALLBACK, found.goal_xy_m, ctx.resampled(found.path_m))


class PocketEscape(PlanSource):
    """The grid check found nothing: if the robot stands in a pocket, check from outside it.

    The potential field may leave the robot nearer a wall than the planner's clearance, in a
    spot that a gap narrower than the clearance cuts off from the rest of the usable map; the
    check, which starts where the robot stands, then sees only that pocket. The robot fits
    where it stands, so it leaves over cells with the clearance of its radius plus
    ``pocket_clearance_margin_m`` to the nearest region that is not a pocket, and the check
    runs again from there with the full clearance (see
    :mod:`semexplore_gym.policies.expert.params`). The plan is both legs; none when the
    check from outside finds nothing either.
    """

    name = "pocket_escape"

    def propose(self, ctx: PlanContext) -> Plan | None:
        prm = ctx.params
        thin_m = ctx.robot_radius_m + prm.pocket_clearance_margin_m
        clearance = ctx.clearance_field()
        exit_path = pocket_exit_path(
            ctx.grid,
            ctx.geometry,
            ctx.xy_m,
            ctx.clearance_m,
            min(thin_m, ctx.clearance_m),
            prm.pocket_max_share,
            clearance_field=clearance,
        )
        if exit_path is None:
            return None
        outside = (float(exit_path[-1, 0]), float(exit_path[-1, 1]))
        found = ctx.frontier_beyond(exit_path)
        if found is None:
            return None
        ctx.counts.pocket_escapes += 1
        ctx.log(
            "pocket",
            f"out at {tuple(round(v, 2) for v in outside)}, then to the frontier at "
            f"{tuple(round(v, 2) for v in found.frontier_xy_m)}",
        )
        path = np.vstack([exit_path, found.path_m[1:]])
        return Plan(PlanKind.FALLBACK, found.goal_xy_m, ctx.resampled(path))


class LookAtNarrowFrontier(PlanSource):
    """Before stopping: drive towards a frontier too narrow to reach, to look again.

    The grid fallback already found no frontier the robot's disc can reach. A frontier that a
    thinner robot (``look_clearance_fraction`` of the clearance) could reach is a gap narrower
    than the robot *at first sight* (a door seen at a grazing angle, a passage seen through a
    narrow slot); leaks through rasterised walls, one or two cells wide, are not. The robot
    follows the thin robot's path as far as its own clearance allows, and looks from there,
    once per place; if the robot already passed within ``look_seen_radius_m`` of the frontier
    it had its look, and the frontier is dropped.
    """

    name = "look"

    def propose(self, ctx: PlanContext) -> Plan | None:
        prm = ctx.params
        res_m = ctx.geometry.resolution_m
        if ctx.counts.look_drives >= prm.max_look_drives:
            return None
        clearance = ctx.clearance_field()
        for _ in range(MAX_LOOK_CANDIDATES):
            found = nearest_reachable_frontier(
                ctx.grid,
                ctx.geometry,
                ctx.xy_m,
                ctx.clearance_m * prm.look_clearance_fraction,
                ctx.look_filter(max(1, math.ceil(prm.look_min_frontier_m / res_m - 1e-9))),
                clearance_field=clearance,
            )
            if found is None:
                return None
            path = standable_prefix(ctx, found.path_m)
            near = math.dist(tuple(path[-1]), found.frontier_xy_m) <= prm.look_reach_m
            if (
                len(path) >= 2
                and near
                and not ctx.memory.been_near(found.frontier_xy_m, prm.look_seen_radius_m)
            ):
                ctx.counts.look_drives += 1
                goal = (float(path[-1, 0]), float(path[-1, 1]))
                return Plan(PlanKind.LOOK, goal, path, frontier_xy_m=found.frontier_xy_m)
            ctx.counts.looks += 1
            ctx.memory.drop(ctx.grid, found.frontier_xy_m, "looked")
        return None


#: Today's expert's plan sources (``semantic-v3``), in the order they are asked (see the module
#: docstring; the other recipes: :mod:`~semexplore_gym.policies.expert.recipes`).
DEFAULT_PLAN_SOURCES: tuple[PlanSource, ...] = (
    CommandedGoal(),
    RetryFailedGoal(),
    ViewFrontier(),
    SemanticFrontier(),
    CommittedFallback(),
    NearestFallback(),
    PocketEscape(),
    RoomBeyondGap(),
    NarrowFallback(),
    LookAtNarrowFrontier(),
)


def insert_plan_source(
    sources: tuple[PlanSource, ...],
    source: PlanSource,
    *,
    before: str | None = None,
    after: str | None = None,
) -> tuple[PlanSource, ...]:
    """``sources`` with ``source`` inserted before or after the source named so (else last).

    Raises:
        ValueError: no source has that name, or both ``before`` and ``after`` are given.
    """
    if before is not None and after is not None:
        raise ValueError("give before or after, not both")
    anchor = before if before is not None else after
    if anchor is None:
        return (*sources, source)
    names = [s.name for s in sources]
    if anchor not in names:
        raise ValueError(f"no plan source named {anchor!r}; have {names}")
    i = names.index(anchor) + (0 if before is not None else 1)
    return (*sources[:i], source, *sources[i:])
