"""The semantic expert's goal memory: drops, reaches, retries, revivals, the trail, the commanded
goal and the stop reason (the rule: never give up on a reachable frontier).

:class:`GoalMemory` is a part the expert owns. It decides what happens when the approach to a
goal fails (retry it another way, or drop it), when a goal is reached without clearing its
frontier, when the map round a dropped goal changes, and why the mission stopped. Its
parameters are :class:`~semexplore_gym.policies.expert.params.GoalMemoryParams` (the
fields of the same names in :class:`SemanticExpertParams`, documented in
:mod:`semexplore_gym.policies.expert.params`); which of its rules it follows is the
:class:`GoalRules` of the expert's recipe (:mod:`semexplore_gym.policies.expert.recipes`).
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, TypeVar

import numpy as np
from semexplore_gym.policies.base import off_map_msg
from semexplore_gym.policies.expert.counters import ExpertCounters
from semexplore_gym.policies.expert.params import GoalMemoryParams
from semexplore_gym.policies.expert.plan import Plan, PlanKind
from semexplore_gym.policies.navigation.blacklist import GoalBlacklist
from semexplore_gym.policies.navigation.frontier_memory import FrontierMemory

from semexplore_gym.core.grid import GridGeometry

if TYPE_CHECKING:
    from semexplore_gym.core.planning.graph_search import FrontierCandidate

__all__ = ["TRAIL_CELL_M", "GoalMemory", "GoalRules", "Reach", "Retry", "ViewRequest"]

_Scored = TypeVar("_Scored", bound="FrontierCandidate")

#: Lattice of the robot's trail (metres per cell).
TRAIL_CELL_M = 0.25


@dataclass(frozen=True)
class GoalRules:
    """The rules a goal memory follows: a part of an expert's recipe, not a parameter.

    The defaults are today's expert (``semantic-v3``); an older version's recipe lists the
    rules of its time (:mod:`semexplore_gym.policies.expert.recipes`).

    Attributes:
        vanish_on_frontier: A goal is mapped once no frontier cell (UNKNOWN next to FREE) is
            left near it; off (``semantic-v2``, the paper): once no UNKNOWN cell is, which
            unknown space behind a mapped wall keeps from happening.
        drop_each_point: A goal dropped beside an earlier drop keeps a point of its own, so the
            frontier round it is ignored too (off: the grid fallback may find it again at once).
        reach_blacklist: Drop a goal reached ``max_goal_reaches`` times without clearing.
        oscillation_guard: Do not switch back to a goal abandoned ``oscillation_window_s`` ago.
        shuttle_guard: Commit to a goal adopted again without the map growing.
        view_unseen_frontiers: Look into a frontier reached without clearing from elsewhere
            before dropping it (the recipe lists the ``view`` source).
        grid_check: The stop rule is the grid check (the recipe lists the grid fallback); off:
            the mission stops when Algorithm 1 has no frontier left (the paper).
    """

    vanish_on_frontier: bool = True
    drop_each_point: bool = True
    reach_blacklist: bool = True
    oscillation_guard: bool = True
    shuttle_guard: bool = True
    view_unseen_frontiers: bool = True
    grid_check: bool = True


@dataclass(frozen=True)
class Retry:
    """A goal whose approach failed, to be approached another way at the next replan.

    Attributes:
        goal_xy_m: The goal (the frontier's goal point, not a point beside it).
        failures: Failed approaches so far (1: the next is a grid route; more: another side).
        failed_at_xy_m: Where the robot stood when the first approach failed.
    """

    goal_xy_m: tuple[float, float]
    failures: int
    failed_at_xy_m: tuple[float, float]


@dataclass(frozen=True)
class ViewRequest:
    """A frontier reached (or looked at) without clearing: look into it from elsewhere first.

    Attributes:
        frontier_xy_m: The frontier's point.
        reason: The drop reason if no place sees into it (``"reached"`` or ``"looked"``).
        looked_from_xy_m: Where the robot stood when it gave up on the frontier as it was.
    """

    frontier_xy_m: tuple[float, float]
    reason: str
    looked_from_xy_m: tuple[float, float]


@dataclass
class Reach:
    """A place the robot reached as its goal, and how often, without the frontier clearing."""

    xy_m: tuple[float, float]
    count: int


class GoalMemory:
    """Failed approaches are retried, dropped goals come back, and the stop reason is told.

    Args:
        params: The goal memory's parameters.
        rules: The rules it follows (default: today's expert's).
        counts: The expert's counters (``blacklisted``, ``retries``, ``revived``, ``looks``).
        log: Records an event ``(name, detail)`` in the expert's event log.

    Attributes:
        frontiers: Failures, dropped goals (with revival) and abandoned goals.
        blacklist: The dropped goals still active (what Algorithm 1's candidates skip).
        retry: The goal to approach another way at the next replan (None: none).
        reaches: Goals reached without their frontier clearing.
        trail: Cells of a :data:`TRAIL_CELL_M` lattice the robot has been in.
        commanded_xy_m: The goal commanded from outside (None: the expert chooses).
        view: The frontier to look into from elsewhere at the next replan (None: none).
        viewed: Frontiers that had their look from elsewhere (dropped at once next time).
        recent_goals: The last adopted goals with the map's known cells then (shuttle guard).
        shuttle_xy_m: The goal the shuttle guard committed to (None: none).
    """

    def __init__(
        self,
        params: GoalMemoryParams,
        counts: ExpertCounters,
        log: Callable[[str, str], None],
        rules: GoalRules | None = None,
    ) -> None:
        self.params = params
        self.rules = rules if rules is not None else GoalRules()
        self.counts = counts
        self.log = log
        self.geometry: GridGeometry | None = None
        self.reset(None)

    def reset(self, geometry: GridGeometry | None, params: GoalMemoryParams | None = None) -> None:
        """Forget everything: a new mission on a map of ``geometry`` (with ``params``, if
        given, from now on)."""
        if params is not None:
            self.params = params
        prm = self.params
        self.geometry = geometry
        self.here_xy_m: tuple[float, float] | None = None  # the last place visited
        self.frontiers = FrontierMemory(
            prm.blacklist_radius_m,
            prm.revive_window_m,
            prm.revive_min_changed_cells,
            prm.max_revivals,
            prm.max_goal_attempts,
            drop_each_point=self.rules.drop_each_point,
        )
        self.blacklist = GoalBlacklist(prm.blacklist_radius_m)
        self.retry: Retry | None = None
        self.reaches: list[Reach] = []
        # Where the robot has been, on a coarse lattice: a narrow frontier it already passed
        # close to has had its closer look.
        self.trail: set[tuple[int, int]] = set()
        self.commanded_xy_m: tuple[float, float] | None = None
        self.view: ViewRequest | None = None
        self.viewed: list[tuple[float, float]] = []
        self.recent_goals: deque[tuple[tuple[float, float], int]] = deque(
            maxlen=max(1, int(prm.shuttle_switches))
        )
        self.shuttle_xy_m: tuple[float, float] | None = None
        # The narrow tier's goals, each with the map's room to move (cells the robot's centre
        # may take at the narrow clearance) when it was first adopted.
        self.narrow_goals: list[tuple[tuple[float, float], int]] = []
        # When the map last gained room to move, as the narrow tier saw it: (time, room).
        self.narrow_room_since: tuple[float, int] | None = None

    # ------------------------------------------------------------------ queries
    def dropped_points(self, exclude: Sequence[str] = ()) -> list[tuple[float, float]]:
        """The dropped goals that have not come back (but those dropped for a reason in
        ``exclude``)."""
        return self.frontiers.active_points(exclude)

    def is_blacklisted(self, xy_m: tuple[float, float]) -> bool:
        """Whether ``xy_m`` lies near a dropped goal."""
        return xy_m in self.blacklist

    def recently_abandoned(self, xy_m: tuple[float, float], now_s: float) -> bool:
        """With the oscillation guard on: whether the robot switched away from a goal near
        ``xy_m`` within ``oscillation_window_s``."""
        return self.rules.oscillation_guard and self.frontiers.recently_abandoned(
            xy_m, now_s, self.params.oscillation_window_s
        )

    def been_near(self, xy_m: tuple[float, float], radius_m: float) -> bool:
        """Whether the robot's trail passed within ``radius_m`` of ``xy_m``."""
        c = TRAIL_CELL_M
        k = int(math.ceil(radius_m / c))
        ix, iy = int(xy_m[0] // c), int(xy_m[1] // c)
        for i in range(ix - k, ix + k + 1):
            for j in range(iy - k, iy + k + 1):
                if (i, j) in self.trail and math.dist(((i + 0.5) * c, (j + 0.5) * c), xy_m) <= (
                    radius_m
                ):
                    return True
        return False

    def trail_near(self, xy_m: tuple[float, float], radius_m: float) -> list[tuple[float, float]]:
        """Centres of the trail's cells within ``radius_m`` of ``xy_m``: where the robot was."""
        c = TRAIL_CELL_M
        pts = (((i + 0.5) * c, (j + 0.5) * c) for i, j in self.trail)
        return [p for p in pts if math.dist(p, xy_m) <= radius_m]

    # ------------------------------------------------------------------ events
    def narrow_goal(
        self,
        goal_xy_m: tuple[float, float],
        room_cells: int,
        same_goal_m: float,
        goals: int,
        min_new_cells: float,
        now_s: float = 0.0,
        give_up_s: float = 0.0,
    ) -> bool:
        """The narrow tier proposes ``goal_xy_m``, the map holding ``room_cells`` cells the
        robot's centre may take: True to give up instead (a new goal, while the last ``goals``
        narrow goals, and all that ran since the first of them, added fewer than
        ``min_new_cells`` of them; ``goals`` 0: never). A goal within ``same_goal_m`` of the
        last one continues it and is never given up (the robot may be crawling through the
        passage). With ``give_up_s`` > 0, a new goal is also given up once the room grew by
        less than ``min_new_cells`` in the ``give_up_s`` seconds up to ``now_s`` (the clock
        starts at the first narrow goal and restarts whenever the room grows that much)."""
        past = self.narrow_goals
        if past and math.dist(goal_xy_m, past[-1][0]) <= same_goal_m:
            past[-1] = (goal_xy_m, past[-1][1])
            return False
        if goals > 0 and len(past) >= goals and room_cells - past[-goals][1] < min_new_cells:
            return True
        if give_up_s > 0.0:
            since = self.narrow_room_since
            if since is None or room_cells - since[1] >= min_new_cells:
                self.narrow_room_since = (now_s, room_cells)
            elif now_s - since[0] > give_up_s:
                return True
        past.append((goal_xy_m, room_cells))
        return False

    def visit(self, xy_m: tuple[float, float]) -> None:
        """The robot is at ``xy_m`` (its trail)."""
        self.here_xy_m = xy_m
        self.trail.add((int(xy_m[0] // TRAIL_CELL_M), int(xy_m[1] // TRAIL_CELL_M)))

    def adopt(self, goal_xy_m: tuple[float, float], known_cells: int) -> bool:
        """A new goal was adopted with ``known_cells`` known; with the shuttle guard on, True
        (and :attr:`shuttle_xy_m` set) when it is a goal adopted within the last
        ``shuttle_switches`` goals and the map gained less than ``shuttle_min_new_m2`` since."""
        if not self.rules.shuttle_guard:
            return False
        again = self.would_shuttle(goal_xy_m, known_cells)
        self.recent_goals.append((goal_xy_m, known_cells))
        if not again:
            if self.shuttle_xy_m is not None and not self.is_shuttle_goal(goal_xy_m):
                self.shuttle_xy_m = None
            return False
        self.shuttle_xy_m = goal_xy_m
        self.counts.shuttles += 1
        self.log("shuttle", f"goal adopted again without progress, kept: {goal_xy_m}")
        return True

    def would_shuttle(self, goal_xy_m: tuple[float, float], known_cells: int) -> bool:
        """With the shuttle guard on: whether adopting ``goal_xy_m`` now, with ``known_cells``
        known, would be adopting again a goal of the last ``shuttle_switches`` without the map
        gaining ``shuttle_min_new_m2`` since (what :meth:`adopt` reports)."""
        if not self.rules.shuttle_guard:
            return False
        assert self.geometry is not None
        prm = self.params
        min_new = prm.shuttle_min_new_m2 / self.geometry.resolution_m**2
        return any(
            math.dist(goal_xy_m, xy) <= prm.shuttle_radius_m and known_cells - k < min_new
            for xy, k in self.recent_goals
        )

    def is_shuttle_goal(self, xy_m: tuple[float, float]) -> bool:
        """Whether the shuttle guard committed to a goal near ``xy_m``."""
        s = self.shuttle_xy_m
        return s is not None and math.dist(s, xy_m) <= self.params.shuttle_radius_m

    def shuttle_candidate(self, ranked: Sequence[_Scored]) -> _Scored | None:
        """The cheapest of ``ranked`` (frontier candidates) at the goal the shuttle guard
        committed to (None: no commitment, or that goal is no candidate now)."""
        held = [c for c in ranked if self.is_shuttle_goal(c.goal_xy_m)]
        return min(held, key=lambda c: c.cost) if held else None

    def abandon(self, goal_xy_m: tuple[float, float], now_s: float) -> None:
        """The robot switched away from ``goal_xy_m``."""
        self.frontiers.abandon(goal_xy_m, now_s)

    def command(self, xy_m: tuple[float, float] | None) -> None:
        """Drive to ``xy_m`` from the next replan on (None: the expert chooses again)."""
        self.commanded_xy_m = xy_m

    def end_command(self, why: str) -> None:
        """The commanded goal is done (reached, failed or unreachable): forget it."""
        if self.commanded_xy_m is not None:
            self.log(why, f"goal={self.commanded_xy_m}")
        self.commanded_xy_m = None

    def drop(self, grid: np.ndarray, xy_m: tuple[float, float], reason: str) -> None:
        """Give up on the goal at ``xy_m`` until the map round it changes."""
        assert self.geometry is not None
        self.frontiers.drop(xy_m, reason, grid, self.geometry)
        self.blacklist.points_m[:] = self.frontiers.active_points()
        self.counts.blacklisted += 1
        self.log("blacklist", f"{reason}: {xy_m}")

    def goal_failed(self, grid: np.ndarray, plan: Plan, robot_xy_m: tuple[float, float]) -> None:
        """The approach to ``plan``'s goal failed (a stuck recovery ended): retry it another
        way, or drop it. A commanded goal is given up at once."""
        if plan.kind == PlanKind.COMMANDED:
            self.end_command("command_failed")
            return
        # A retry's target may be a point beside the goal: the goal itself is what failed.
        goal = (
            plan.frontier_xy_m
            if plan.kind in (PlanKind.RETRY, PlanKind.VIEW) and plan.frontier_xy_m
            else plan.goal_xy_m
        )
        if self.is_shuttle_goal(goal):
            self.shuttle_xy_m = None
        n, failed_at = self.frontiers.record_failure(goal, robot_xy_m)
        if n >= self.params.max_goal_attempts or plan.kind in (PlanKind.LOOK, PlanKind.VIEW):
            self.retry = None
            self.drop(grid, goal, "attempts")
            return
        self.retry = Retry(goal, n, failed_at)
        self.counts.retries += 1
        self.log("retry", f"attempt {n + 1} at {goal}")

    def goal_reached(
        self, grid: np.ndarray, plan: Plan, robot_xy_m: tuple[float, float] | None = None
    ) -> None:
        """The robot (at ``robot_xy_m``; default: the goal) reached ``plan``'s goal (the replan
        that follows decides what next)."""
        if plan.kind == PlanKind.COMMANDED:
            self.end_command("command_reached")
            return
        if self.is_shuttle_goal(plan.goal_xy_m):
            self.shuttle_xy_m = None
        if plan.kind == PlanKind.RETRY:
            self.retry = None
        at = robot_xy_m if robot_xy_m is not None else plan.goal_xy_m
        if plan.kind == PlanKind.VIEW and plan.frontier_xy_m is not None:
            # Looked from a place that sees into it, and it stayed unknown.
            self.drop(grid, plan.frontier_xy_m, "viewed")
        elif plan.kind == PlanKind.LOOK and plan.frontier_xy_m is not None:
            # Looked from close by and the frontier is still there: the gap stays closed,
            # unless another place sees into it.
            self.counts.looks += 1
            self._give_up(grid, plan.frontier_xy_m, "looked", at)
        elif self.rules.reach_blacklist:
            self._register_reach(grid, plan.goal_xy_m, at)

    def _register_reach(
        self, grid: np.ndarray, goal: tuple[float, float], at: tuple[float, float]
    ) -> None:
        r = self.params.blacklist_radius_m
        for reach in self.reaches:
            if math.hypot(goal[0] - reach.xy_m[0], goal[1] - reach.xy_m[1]) <= r:
                reach.count += 1
                if reach.count >= self.params.max_goal_reaches:
                    reach.count = 0
                    self._give_up(grid, reach.xy_m, "reached", at)
                return
        self.reaches.append(Reach((goal[0], goal[1]), 1))
        if self.params.max_goal_reaches <= 1:
            self._give_up(grid, goal, "reached", at)

    def _give_up(
        self, grid: np.ndarray, xy_m: tuple[float, float], reason: str, at: tuple[float, float]
    ) -> None:
        """Drop the frontier at ``xy_m`` as it is, or first look into it from elsewhere (once
        per place, with ``view_unseen_frontiers``)."""
        r = self.params.blacklist_radius_m
        if not self.rules.view_unseen_frontiers or any(
            math.dist(xy_m, v) <= r for v in self.viewed
        ):
            self.drop(grid, xy_m, reason)
            return
        self.viewed.append(xy_m)
        self.view = ViewRequest(xy_m, reason, at)

    def revive(self, grid: np.ndarray) -> None:
        """Bring back the dropped goals round which the map changed enough."""
        if not self.frontiers.dropped:
            return
        assert self.geometry is not None
        back = self.frontiers.revive(grid, self.geometry)
        if back:
            self.blacklist.points_m[:] = self.frontiers.active_points()
            self.counts.revived += len(back)
            for xy in back:
                self.log("revive", f"map changed round {xy}")

    def stop_reason(self) -> str:
        """Which rule ended the mission, and what was left behind."""
        if not self.rules.grid_check:
            n = self.frontiers.count()
            return "no semantic frontier left" + (f" ({n} frontier(s) dropped)" if n else "")
        parts = []
        for reason, text in (
            ("attempts", f"failed {self.params.max_goal_attempts} approaches"),
            ("grid", "no grid path"),
            ("reached", f"reached {self.params.max_goal_reaches} times, not cleared"),
            ("looked", "looked at, gap closed"),
            ("viewed", "seen from another place, still unknown"),
            ("unseeable", "no reachable place sees into them"),
            ("sliver", "a sliver of unknown behind, not worth a view"),
        ):
            n = self.frontiers.count(reason)
            if n:
                parts.append(f"{n} {text}")
        tail = f"; dropped: {', '.join(parts)}" if parts else ""
        reason = f"no frontier left (grid check: none reachable{tail})"
        if self.geometry is None or self.here_xy_m is None:
            return reason
        # From a pose estimate off the map (a diverged SLAM) nothing is reachable: say so first.
        return off_map_msg(self.geometry, self.here_xy_m, reason)
