"""The semantic expert's narrow tier: plan sources through passages narrower than the planners'
clearance (:class:`RoomBeyondGap`, listed by today's expert's recipe; :class:`NarrowFallback`,
the user's switch ``narrow_passages``). Their plans carry the map's clearance along their
paths, and the path follower tracks the tight stretches slowly and exactly. Both are in
:data:`~semexplore_gym.policies.expert.plan_sources.DEFAULT_PLAN_SOURCES`, after the pocket
escape and before the stop rule's look.
"""

from __future__ import annotations

import math

import numpy as np
from semexplore_gym.policies.expert.plan import Plan, PlanKind
from semexplore_gym.policies.expert.plan_context import (
    PlanContext,
    PlanSource,
    path_clearance_along,
    standable_prefix,
)

from semexplore_gym.core.frontiers.beyond_gap import room_beyond_gap_path
from semexplore_gym.core.frontiers.reachable import FrontierFilter, nearest_reachable_frontier

__all__ = ["NARROW_REACHED_M", "NarrowFallback", "RoomBeyondGap"]

#: A goal through a narrow passage counts as reached this close (metres): the expert's usual
#: radius would count it reached from outside the passage.
NARROW_REACHED_M = 0.1

#: A look into a narrow passage's mouth ends at least this far from the robot, somewhere its
#: trail has not been (metres).
NARROW_LOOK_MIN_M = 0.2
#: A narrow goal within this of the last one is the same goal (it drifts as its frontier is
#: mapped), for the narrow tier's give-up.
NARROW_SAME_GOAL_M = 1.0


class RoomBeyondGap(PlanSource):
    """Nothing is reachable at the planners' clearance, but the map shows room beyond a gap
    narrower than it (space with that clearance and a frontier, seen
    through the gap; see :mod:`semexplore_gym.core.frontiers.beyond_gap`): through the gap at
    the narrow tier's clearance, tracked slowly and exactly, then on to that frontier."""

    name = "room_beyond_gap"

    def propose(self, ctx: PlanContext) -> Plan | None:
        prm = ctx.params
        thin_m = ctx.narrow_clearance_m()
        if thin_m >= ctx.clearance_m:
            return None
        known = ctx.known_clearance_field()
        way = room_beyond_gap_path(
            ctx.grid,
            ctx.geometry,
            ctx.xy_m,
            ctx.clearance_m,
            thin_m,
            known,
            ctx.fallback_filter(),
            math.ceil(prm.narrow_min_room_m2 / ctx.geometry.resolution_m**2 - 1e-9),
        )
        if way is None:
            return None
        found = ctx.frontier_beyond(way)
        if found is None:
            return None
        ctx.counts.narrow_plans += 1
        if ctx.current is None or ctx.current.goal_xy_m != found.goal_xy_m:
            entry = tuple(round(float(v), 2) for v in way[-1])
            ctx.log("room", f"through a gap at {entry}, then to {found.goal_xy_m}")
        path = ctx.resampled(np.vstack([way, found.path_m[1:]]))
        return Plan(
            PlanKind.FALLBACK,
            found.goal_xy_m,
            path,
            path_clearance_m=path_clearance_along(ctx, path, known),
        )


class NarrowFallback(PlanSource):
    """Graded clearance (``narrow_passages``): nothing is reachable at the planners' clearance,
    so the nearest frontier a grid search with the robot radius plus
    ``narrow_clearance_margin_m`` reaches. The plan carries the map's clearance along its path:
    where that is below the planners' clearance the path follower tracks it slowly and exactly
    (see :class:`~semexplore_gym.policies.expert.path_following.PathFollower`).
    """

    name = "narrow_fallback"

    def propose(self, ctx: PlanContext) -> Plan | None:
        prm = ctx.params
        thin_m = ctx.narrow_clearance_m()
        if not prm.narrow_passages or thin_m >= ctx.clearance_m:
            return None
        clearance = ctx.known_clearance_field()
        # The fallback's own frontier filter: a frontier as narrow as the passage is a crack as
        # often as a way on (cave walls are full of them); a passage leading somewhere shows a
        # wider frontier beyond it once the robot looks along it (the look below).
        search = ctx.fallback_search_kwargs()
        found = nearest_reachable_frontier(
            ctx.grid,
            ctx.geometry,
            ctx.xy_m,
            thin_m,
            frontiers=FrontierFilter(**search),
            clearance_field=clearance,
        )
        if found is not None:
            path, goal = ctx.resampled(found.path_m), found.goal_xy_m
        else:
            # A passage seen only at a grazing angle is not mapped free across its width yet:
            # drive into its mouth as far as the thin clearance holds, and look along it.
            mouth = self._look_into(ctx, thin_m, clearance)
            if mouth is None:
                return None
            path, goal = mouth, (float(mouth[-1, 0]), float(mouth[-1, 1]))
        # The give-up: a new narrow goal only while the last ones mapped room to move in
        # (cells the robot's centre may take at the thin clearance; a crack narrower than the
        # robot maps free cells, but none of these).
        room = int(np.count_nonzero(clearance >= thin_m))
        min_new = prm.narrow_give_up_m2 / ctx.geometry.resolution_m**2
        if ctx.memory.narrow_goal(
            goal,
            room,
            NARROW_SAME_GOAL_M,
            prm.narrow_give_up_goals,
            min_new,
            now_s=ctx.time_s,
            give_up_s=prm.narrow_give_up_s,
        ):
            return None
        ctx.counts.narrow_plans += 1
        return Plan(
            PlanKind.FALLBACK,
            goal,
            path,
            reached_within_m=NARROW_REACHED_M,
            path_clearance_m=path_clearance_along(ctx, path, clearance),
        )

    @staticmethod
    def _look_into(ctx: PlanContext, thin_m: float, clearance: np.ndarray) -> np.ndarray | None:
        prm = ctx.params
        res_m = ctx.geometry.resolution_m
        found = nearest_reachable_frontier(
            ctx.grid,
            ctx.geometry,
            ctx.xy_m,
            ctx.clearance_m * prm.look_clearance_fraction,
            # At least as wide as a passage the robot fits through shows on the map.
            ctx.look_filter(max(1, math.floor(2.0 * thin_m / res_m + 1e-9))),
            clearance_field=clearance,
        )
        if found is None:
            return None
        path = standable_prefix(ctx, found.path_m, thin_m, clearance)
        if len(path) < 2:
            return None
        end = (float(path[-1, 0]), float(path[-1, 1]))
        if math.dist(end, ctx.xy_m) < NARROW_LOOK_MIN_M or ctx.memory.been_near(
            end, NARROW_LOOK_MIN_M
        ):
            return None  # looked from there already
        return path
