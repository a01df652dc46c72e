"""Frontier teams: one navigator per robot, frontiers divided (or not) by a coordinator.

Every robot runs :class:`~semexplore_gym.policies.frontier.NearestFrontierPolicy`'s machinery
(WFD frontiers on the map it observes, geodesic distances, Navfn + DWA, blacklist); only the
choice of its next target differs:

* ``"independent"``: each robot takes its own nearest frontier (no coordination; robots near
  each other chase the same one).
* ``"greedy"``: greedy nearest-frontier assignment (Yamauchi 1998's shared map, with targets
  claimed): a robot takes the nearest frontier that is not within ``claim_radius_m`` of a
  teammate's target, the nearest at all if every one is claimed.
* ``"coordinated"``: Burgard et al. (2005): a frontier's utility starts at 1 and is reduced
  around the targets teammates already hold (by ``1 - d / discount_radius_m`` each), and the
  targets of every robot that needs one *now* are chosen together by
  :func:`scipy.optimize.linear_sum_assignment` over ``path length - utility_weight_m *
  utility``. With ``spread_branches`` it also spreads robots over different branches of the
  map: a target on the far side of a teammate (its path would pass within
  ``branch_radius_m`` of a teammate's position) costs ``branch_penalty_m`` more.

A robot replans when its target stops being a frontier (it has been mapped: the map changed
materially there), when it reaches or gives up its goal, and every ``replan_period_s`` while
any teammate waits for a target. The team is done when no robot has a reachable frontier: a
robot without one waits (re-checking every ``idle_recheck_s``) while teammates still work.

Yielding: robots have priorities (agent order). A robot that finds a higher-priority teammate
within ``yield_distance_m`` ahead of it (within ``yield_cone_rad`` of its heading) backs off
along its heading's opposite for that step (or stands if backing would hit something in its
scan), so in a passage two robots wide the lower-priority robot gives way and the other passes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Literal

import numpy as np
from scipy.optimize import linear_sum_assignment
from semexplore_gym.policies.base import StepStats
from semexplore_gym.policies.frontier_baselines import NearestFrontierParams, NearestFrontierPolicy
from semexplore_gym.policies.team.base import TeamPolicy

from semexplore_gym.core.grid import FREE
from semexplore_gym.core.planning.grid_search import (
    INSCRIBED_COST,
    NO_INFORMATION,
    geodesic_distance_m,
    inflate_costmap,
)

Coordination = Literal["independent", "greedy", "coordinated"]


@dataclass(frozen=True)
class FrontierTeamParams:
    """Parameters of the frontier teams.

    Attributes:
        coordination: ``"independent"``, ``"greedy"`` or ``"coordinated"`` (module docstring).
        claim_radius_m: ``"greedy"``: a frontier this near a teammate's target is claimed.
        discount_radius_m: ``"coordinated"``: utility is reduced within this distance of a
            teammate's target (about the LiDAR range: what that robot will see from there).
        utility_weight_m: ``"coordinated"``: metres of path one unit of utility is worth.
        spread_branches: ``"coordinated"``: penalise targets whose straight line from the
            robot passes a teammate (send robots down different branches).
        branch_radius_m: How near a teammate the line must pass to count.
        branch_penalty_m: The penalty, metres of path.
        replan_period_s: While a teammate waits for a target, replan every this often.
        idle_recheck_s: A robot without a reachable frontier looks again this often.
        yield_distance_m: A teammate of higher priority this near and ahead makes a robot yield.
        yield_cone_rad: Half-angle of "ahead".
        member: Each robot's nearest-frontier parameters (navigation, blacklist, retries).
    """

    coordination: Coordination = "coordinated"
    claim_radius_m: float = 2.0
    discount_radius_m: float = 3.5
    utility_weight_m: float = 6.0
    spread_branches: bool = True
    branch_radius_m: float = 0.6
    branch_penalty_m: float = 3.0
    replan_period_s: float = 2.0
    idle_recheck_s: float = 5.0
    yield_distance_m: float = 0.7
    yield_cone_rad: float = 1.2
    member: NearestFrontierParams = field(default_factory=NearestFrontierParams)

    def __post_init__(self) -> None:
        if self.coordination not in ("independent", "greedy", "coordinated"):
            raise ValueError(
                "coordination must be 'independent', 'greedy' or 'coordinated', "
                f"got {self.coordination!r}"
            )
        for name in (
            "claim_radius_m",
            "discount_radius_m",
            "utility_weight_m",
            "branch_radius_m",
            "branch_penalty_m",
            "replan_period_s",
            "idle_recheck_s",
            "yield_distance_m",
            "yield_cone_rad",
        ):
            v = getattr(self, name)
            if not (math.isfinite(v) and v >= 0):
                raise ValueError(f"{name} must be a finite number >= 0, got {v!r}")


@dataclass
class FrontierTarget:
    """A frontier one team member can reach: its nearest cell, that cell in metres, and the
    path length to it (what the team's assignment weighs)."""

    cell: tuple[int, int]
    xy_m: tuple[float, float]
    path_m: float


class _Member(NearestFrontierPolicy):
    """One robot of a frontier team: the nearest-frontier robot whose target choice is the
    team's (``select_target`` asks the team)."""

    name = "team_member"

    def __init__(self, team: FrontierTeam, index: int, params: NearestFrontierParams) -> None:
        super().__init__(params)
        self.team = team
        self.index = index
        self.goal_cell: tuple[int, int] | None = None

    def candidates(
        self, grid: np.ndarray, pose: np.ndarray, stats: StepStats
    ) -> list[FrontierTarget]:
        """Every frontier's nearest cell by path, with its path length (blacklist excluded)."""
        assert self.nav is not None
        self.frontiers = self.detect(grid, pose)
        self.blacklist_hits = 0
        if not self.frontiers:
            return []
        costmap = inflate_costmap(grid, self.geometry.resolution_m, self.nav.costmap_params)
        traversable = (costmap < INSCRIBED_COST) & (grid == FREE)
        fmask = np.zeros(grid.shape, dtype=bool)
        for f in self.frontiers:
            fmask[f.cells[:, 0], f.cells[:, 1]] = True
        traversable |= fmask & ((costmap < INSCRIBED_COST) | (costmap == NO_INFORMATION))
        dist = geodesic_distance_m(traversable, self.geometry, pose[:2])
        out: list[FrontierTarget] = []
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
            out.append(FrontierTarget(cell, (float(x), float(y)), float(d[i])))
        return out

    def select_target(
        self, grid: np.ndarray, pose: np.ndarray, stats: StepStats
    ) -> tuple[float, float] | None:
        self.counters["selections"] += 1
        choice = self.team.assign(self.index, grid, pose, stats)
        self.target_cell = choice.cell if choice is not None else None
        self.goal_cell = self.target_cell
        if choice is None:
            return None
        self.path_length_m = choice.path_m
        return choice.xy_m


class FrontierTeam(TeamPolicy):
    """A team of nearest-frontier robots with one of three coordinations (module docstring).

    Args:
        params: Parameters; ``None`` = defaults. Keyword overrides are applied on top.
    """

    name = "frontier_team"
    _poses: list[np.ndarray]  # each agent's last pose (TeamPolicy.reset_members)

    def __init__(self, params: FrontierTeamParams | None = None, **overrides: Any) -> None:
        super().__init__()
        p = params if params is not None else FrontierTeamParams()
        if overrides:
            import dataclasses

            p = dataclasses.replace(p, **overrides)
        self.params = p
        self.name = f"team_{p.coordination}" + (
            "" if p.coordination != "coordinated" or p.spread_branches else "_nobranch"
        )
        self.members: list[_Member] = []

    def reset(
        self,
        observations: dict[str, dict[str, np.ndarray]],
        infos: dict[str, dict[str, Any]],
        seed: int | None = None,
    ) -> None:
        super().reset(observations, infos, seed)
        self.members = [_Member(self, i, self.params.member) for i in range(len(self.agents))]
        self.reset_members(self.members, observations, infos, seed)
        self._idle_since = [math.inf] * len(self.agents)

    # ------------------------------------------------------------ the step
    def act(
        self, observations: dict[str, dict[str, np.ndarray]], infos: dict[str, dict[str, Any]]
    ) -> dict[str, np.ndarray]:
        n = len(self.agents)
        self._poses = [
            np.asarray(observations[a]["pose"], dtype=np.float64)
            if a in observations
            else self._poses[i]
            for i, a in enumerate(self.agents)
        ]
        actions: dict[str, np.ndarray] = {}
        for i, (m, a) in enumerate(zip(self.members, self.agents, strict=True)):
            if a not in observations:
                continue
            if m.done and m.now_s - self._idle_since[i] >= self.params.idle_recheck_s:
                # Teammates may have opened new frontiers since: look again.
                m.resume()
            if m.done and not math.isfinite(self._idle_since[i]):
                self._idle_since[i] = m.now_s
            action = m.act(observations[a], infos[a])
            if m.done:
                m.now_s += m.dt_s  # a waiting robot's clock runs on
                self._idle_since[i] = min(self._idle_since[i], m.now_s)
            else:
                self._idle_since[i] = math.inf
                active = [not t.done for t in self.members]
                action, yielded = yield_action(
                    i,
                    self._poses,
                    active,
                    observations[a],
                    action,
                    self.params.yield_distance_m,
                    self.params.yield_cone_rad,
                )
                if yielded:
                    self.counters["yields"] = self.counters.get("yields", 0) + 1
            actions[a] = action
        if n and all(m.done for m in self.members):
            self.done = True
            reasons = {m.stop_reason for m in self.members}
            self.stop_reason = "no robot has a reachable frontier: " + "; ".join(sorted(reasons))
        return actions

    # -------------------------------------------------------- coordination
    def assign(
        self, i: int, grid: np.ndarray, pose: np.ndarray, stats: StepStats
    ) -> FrontierTarget | None:
        """Robot ``i``'s next target under the team's coordination (None: no reachable one)."""
        member = self.members[i]
        cands = member.candidates(grid, pose, stats)
        if not cands:
            return None
        p = self.params
        others = [
            self.members[j].goal_cell
            for j in range(len(self.members))
            if j != i and not self.members[j].done and self.members[j].goal_cell is not None
        ]
        g = member.geometry
        other_goals = [tuple(float(v) for v in g.grid_to_world(*c)) for c in others if c]
        if p.coordination == "independent" or not other_goals:
            best = min(cands, key=lambda c: c.path_m)
        elif p.coordination == "greedy":
            free = [c for c in cands if _min_distance(c.xy_m, other_goals) > p.claim_radius_m]
            best = min(free or cands, key=lambda c: c.path_m)
        else:
            best = self._coordinated(i, cands, other_goals)
        self.counters["assignments"] = self.counters.get("assignments", 0) + 1
        return best

    def _coordinated(
        self, i: int, cands: list[FrontierTarget], other_goals: list[tuple[float, ...]]
    ) -> FrontierTarget:
        p = self.params
        xy = np.array([c.xy_m for c in cands])
        utility = np.ones(len(cands))
        for gx, gy in other_goals:
            d = np.hypot(xy[:, 0] - gx, xy[:, 1] - gy)
            utility -= np.clip(1.0 - d / max(p.discount_radius_m, 1e-9), 0.0, 1.0)
        utility = np.clip(utility, 0.0, 1.0)
        cost = np.array([c.path_m for c in cands]) - p.utility_weight_m * utility
        if p.spread_branches:
            me = self._poses[i][:2]
            for j, q in enumerate(self._poses):
                if j != i and not self.members[j].done:
                    cost += p.branch_penalty_m * _passes_near(me, xy, q[:2], p.branch_radius_m)
        # Robots that need a target now (this one, and idle teammates) are assigned together.
        rows = [i] + [
            j
            for j, m in enumerate(self.members)
            if j != i and not m.done and m.goal_cell is None and m.nav is not None
        ]
        if len(rows) == 1:
            return cands[int(np.argmin(cost))]
        matrix = np.empty((len(rows), len(cands)))
        matrix[0] = cost
        for k, j in enumerate(rows[1:], start=1):
            qx, qy = self._poses[j][:2]
            # A teammate's path lengths are not computed here: its straight-line distance
            # ranks the targets it would take.
            matrix[k] = np.hypot(xy[:, 0] - qx, xy[:, 1] - qy) - p.utility_weight_m * utility
        r, c = linear_sum_assignment(matrix)
        pick = dict(zip(r.tolist(), c.tolist(), strict=True))
        return cands[pick[0]] if 0 in pick else cands[int(np.argmin(cost))]

    def overlays(self) -> dict[str, dict[str, Any]]:
        return {a: m.overlay() for a, m in zip(self.agents, self.members, strict=True)}

    def mission_metrics(self) -> dict[str, Any]:
        return {
            "assignments": self.counters.get("assignments", 0),
            "yields": self.counters.get("yields", 0),
        }


def yield_action(
    i: int,
    poses: list[np.ndarray],
    active: list[bool],
    obs: dict[str, np.ndarray],
    action: np.ndarray,
    distance_m: float,
    cone_rad: float,
) -> tuple[np.ndarray, bool]:
    """Robot ``i``'s action after giving way: ``(action, yielded)``.

    A robot yields to an active teammate of higher priority (lower index) within
    ``distance_m`` and within ``cone_rad`` of its heading: it backs off at half speed, or
    stands when its scan shows something within 0.3 m behind it.
    """
    x, y, yaw = (float(v) for v in poses[i][:3])
    for j in range(i):
        if not active[j]:
            continue
        dx, dy = float(poses[j][0]) - x, float(poses[j][1]) - y
        bearing = abs((math.atan2(dy, dx) - yaw + math.pi) % (2 * math.pi) - math.pi)
        if math.hypot(dx, dy) < distance_m and bearing < cone_rad:
            scan = np.asarray(obs["scan"])
            n_b = scan.shape[0]
            back = scan[(np.arange(-(n_b // 8), n_b // 8 + 1) + n_b // 2) % n_b]
            clear = bool(np.all((back == 0) | (back > 0.3)))
            return np.array([-0.5 if clear else 0.0, 0.0], dtype=np.float32), True
    return action, False


def _min_distance(xy: tuple[float, float], points: list[tuple[float, ...]]) -> float:
    return min(math.hypot(xy[0] - px, xy[1] - py) for px, py in points)


def _passes_near(
    start: np.ndarray, ends: np.ndarray, point: np.ndarray, radius: float
) -> np.ndarray:
    """1.0 where the segment from ``start`` to each of ``ends`` passes within ``radius`` of
    ``point`` (the point not at the start itself), else 0.0."""
    ab = ends - start
    ap = point - start
    denom = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-12)
    t = np.clip((ab @ ap) / denom, 0.0, 1.0)
    closest = start + ab * t[:, None]
    near = np.hypot(*(closest - point).T) < radius
    return (near & (t > 0.05)).astype(np.float64)
