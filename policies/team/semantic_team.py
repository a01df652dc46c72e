"""The coordinated semantic expert: the paper's expert on every robot, frontiers divided.

Each robot runs :class:`~semexplore_gym.policies.expert.expert.SemanticExpertPolicy` (its
semantic topometric map, Algorithm 1's cost ``C`` per frontier, the potential field). Only the
goal choice is the team's, through the expert's ``choose_goal`` plug-in point: a candidate's
cost becomes

    C + discount_weight * U_taken + branch_weight * B

* ``U_taken`` (Burgard et al. 2005): how much of the candidate's area a teammate's goal will
  already reveal, ``max_j (1 - d(goal, goal_j) / discount_radius_m)`` clipped to [0, 1];
* ``B`` (the semantic map spreads the team): 1 when the candidate lies behind the same
  intersection as a teammate's goal (``intersection_id`` of the frontier pathway's nearest
  intersection on this robot's map, matched through the intersection's position), or when the
  candidate's path runs within ``branch_radius_m`` of a teammate: robots take different
  branches.

When several robots need a goal at once (this robot and teammates without one), the goals are
chosen together by :func:`scipy.optimize.linear_sum_assignment` (teammates ranked by straight
distance, as their own costs are not computed here). ``semantic=False`` is the ablation: the
paper's semantic terms off (``w_p = w_I = 0``: cost = ``d / L_path + w_v v``) and no
intersection matching (the distance discount and path spreading stay).

A goal one robot drops because of what the map shows (it looked and the gap stayed closed, it
reached it again and again, no grid path leads there) is dropped by its teammates too; a goal
whose approaches failed is not (a teammate may have been in the way). The team stops when
every robot's expert has stopped (no frontier left on its map); a robot that stopped while
teammates work looks again every ``idle_recheck_s``. Robots yield to
higher-priority teammates in passages as in :mod:`~semexplore_gym.policies.team.frontier_teams`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.optimize import linear_sum_assignment
from semexplore_gym.policies.expert.expert import SemanticExpertPolicy
from semexplore_gym.policies.expert.params import SemanticExpertParams
from semexplore_gym.policies.expert.recipes import OUTSIDE_CHOICE
from semexplore_gym.policies.team.base import TeamPolicy
from semexplore_gym.policies.team.frontier_teams import yield_action

from semexplore_gym.core.planning.graph_search import FrontierCandidate

#: Drops a robot keeps to itself (see ``_share_drops``): its approaches failed.
UNSHARED_DROP_REASONS = ("attempts",)


@dataclass(frozen=True)
class SemanticTeamParams:
    """Parameters of the coordinated semantic expert (module docstring).

    Attributes:
        semantic: Use the semantic terms (False: the no-semantics ablation).
        discount_radius_m: Utility discount radius around teammates' goals.
        discount_weight: Cost units of ``C`` a fully taken candidate costs more.
        branch_weight: Cost units of ``C`` for a candidate in a teammate's branch.
        branch_radius_m: A path this near a teammate counts as its branch.
        intersection_match_m: Intersections of two robots' maps within this are the same.
        idle_recheck_s: A stopped robot looks again this often while teammates work.
        yield_distance_m: See :class:`~semexplore_gym.policies.team.FrontierTeamParams`.
        yield_cone_rad: See :class:`~semexplore_gym.policies.team.FrontierTeamParams`.
        expert: Each robot's expert parameters; each robot's expert is made from the
            outside-choice recipe (:data:`~semexplore_gym.policies.expert.recipes.
            OUTSIDE_CHOICE`: the team's coordinated choice, not each robot's nearest frontier,
            decides, and the teams were measured driving the map's paths).
    """

    semantic: bool = True
    discount_radius_m: float = 3.5
    discount_weight: float = 2.0
    branch_weight: float = 1.0
    branch_radius_m: float = 0.6
    intersection_match_m: float = 1.0
    idle_recheck_s: float = 5.0
    yield_distance_m: float = 0.7
    yield_cone_rad: float = 1.2
    expert: SemanticExpertParams = dataclasses.field(default_factory=SemanticExpertParams)


class _ExpertMember(SemanticExpertPolicy):
    """One robot's expert; its goal choice is the team's."""

    recipe = OUTSIDE_CHOICE

    def __init__(self, team: SemanticTeam, index: int, params: SemanticExpertParams) -> None:
        super().__init__(params)
        self.team = team
        self.index = index
        self.goal_intersection_xy: tuple[float, float] | None = None

    def choose_goal(self, candidates: list[FrontierCandidate]) -> FrontierCandidate:
        choice = self.team.choose(self.index, candidates, super().choose_goal)
        self.goal_intersection_xy = self.intersection_xy(choice)
        return choice

    def intersection_xy(self, c: FrontierCandidate) -> tuple[float, float] | None:
        """Where the intersection leading to ``c``'s frontier is on this robot's map."""
        iid = c.frontier.intersection_id
        if iid is None or self.tmap is None:
            return None
        area = self.tmap.areas.get(iid)
        if area is None:
            return None
        cx, cy = area.centre_m
        return (float(cx), float(cy))

    def look_again(self) -> None:
        """Un-stop: the map may have new frontiers that teammates opened."""
        self.resume()


class SemanticTeam(TeamPolicy):
    """The coordinated semantic expert (module docstring)."""

    _poses: list[np.ndarray]  # each agent's last pose (TeamPolicy.reset_members)

    def __init__(self, params: SemanticTeamParams | None = None, **overrides: Any) -> None:
        super().__init__()
        p = params if params is not None else SemanticTeamParams()
        if overrides:
            p = dataclasses.replace(p, **overrides)
        if not p.semantic:
            p = dataclasses.replace(
                p, expert=dataclasses.replace(p.expert, cost=_metric_only(p.expert))
            )
        self.params = p
        self.name = "team_semantic" if p.semantic else "team_semantic_nosem"
        self.members: list[_ExpertMember] = []

    def reset(
        self,
        observations: dict[str, dict[str, np.ndarray]],
        infos: dict[str, dict[str, Any]],
        seed: int | None = None,
    ) -> None:
        super().reset(observations, infos, seed)
        self.members = [_ExpertMember(self, i, self.params.expert) for i in range(len(self.agents))]
        self.reset_members(self.members, observations, infos, seed)
        self._clock_s = 0.0
        self._stopped_at = [math.inf] * len(self.agents)
        self._shared: set[tuple[float, float]] = set()

    def act(
        self, observations: dict[str, dict[str, np.ndarray]], infos: dict[str, dict[str, Any]]
    ) -> dict[str, np.ndarray]:
        p = self.params
        self._poses = [
            np.asarray(observations[a]["pose"], dtype=np.float64) if a in observations else q
            for a, q in zip(self.agents, self._poses, strict=True)
        ]
        actions: dict[str, np.ndarray] = {}
        for i, (m, a) in enumerate(zip(self.members, self.agents, strict=True)):
            if a not in observations:
                continue
            if m.done and self._clock_s - self._stopped_at[i] >= p.idle_recheck_s:
                m.look_again()
                self._stopped_at[i] = math.inf
            action = m.act(observations[a], infos[a])
            if m.done:
                self._stopped_at[i] = min(self._stopped_at[i], self._clock_s)
            else:
                active = [not t.done for t in self.members]
                action, yielded = yield_action(
                    i,
                    self._poses,
                    active,
                    observations[a],
                    action,
                    p.yield_distance_m,
                    p.yield_cone_rad,
                )
                if yielded:
                    self.counters["yields"] = self.counters.get("yields", 0) + 1
            actions[a] = action
        self._share_drops(observations)
        self._clock_s += self.members[0].dt_s if self.members else 0.0
        if self.members and all(m.done for m in self.members):
            self.done = True
            reasons = sorted({m.stop_reason for m in self.members})
            self.stop_reason = "no robot has a reachable frontier: " + "; ".join(reasons)
        return actions

    def _share_drops(self, observations: dict[str, dict[str, np.ndarray]]) -> None:
        """A goal one robot dropped for what the map shows (looked at from close by or from
        elsewhere and still closed, reached again and again, no grid path) is dropped by its
        teammates too, once: they would otherwise cross the building to find the same gap
        closed. Failed approaches stay the robot's own (:data:`UNSHARED_DROP_REASONS`: a
        teammate in the way fails an approach; shared, such drops once stopped a whole team
        at a third of a maze). Each robot revives a drop by its own rule."""
        for j, src in enumerate(self.members):
            for xy in src.goal_memory.dropped_points(exclude=UNSHARED_DROP_REASONS):
                key = (round(xy[0], 3), round(xy[1], 3))
                if key in self._shared:
                    continue
                self._shared.add(key)
                for i, dst in enumerate(self.members):
                    a = self.agents[i]
                    mem = dst.goal_memory
                    if i == j or a not in observations or mem.geometry is None:
                        continue
                    if not mem.is_blacklisted(xy):
                        mem.drop(np.asarray(observations[a]["map"]), xy, "teammate")

    # -------------------------------------------------------- coordination
    def choose(
        self,
        i: int,
        candidates: list[FrontierCandidate],
        default: Any,
    ) -> FrontierCandidate:
        """Robot ``i``'s goal among its scored ``candidates`` (module docstring)."""
        p = self.params
        mates = [
            m
            for j, m in enumerate(self.members)
            if j != i and not m.done and m.goal_xy_m is not None
        ]
        if not mates:
            return default(candidates)
        self.counters["assignments"] = self.counters.get("assignments", 0) + 1
        me = self.members[i]
        xy = np.array([c.goal_xy_m for c in candidates], dtype=np.float64)
        taken = np.zeros(len(candidates))
        for m in mates:
            gx, gy = m.goal_xy_m  # type: ignore[misc]
            d = np.hypot(xy[:, 0] - gx, xy[:, 1] - gy)
            taken = np.maximum(taken, np.clip(1.0 - d / max(p.discount_radius_m, 1e-9), 0, 1))
        branch = np.zeros(len(candidates))
        for k, c in enumerate(candidates):
            if p.semantic:
                ixy = me.intersection_xy(c)
                if ixy is not None and any(
                    m.goal_intersection_xy is not None
                    and math.dist(ixy, m.goal_intersection_xy) < p.intersection_match_m
                    for m in mates
                ):
                    branch[k] = 1.0
                    continue
            path = np.asarray(c.path_m, dtype=np.float64)
            for j, q in enumerate(self._poses):
                if j != i and not self.members[j].done and len(path):
                    d = (
                        np.hypot(path[1:, 0] - q[0], path[1:, 1] - q[1])
                        if len(path) > 1
                        else np.array([math.inf])
                    )
                    if float(np.min(d)) < p.branch_radius_m:
                        branch[k] = 1.0
                        break
        cost = (
            np.array([c.cost for c in candidates])
            + p.discount_weight * taken
            + p.branch_weight * branch
        )
        waiting = [
            j
            for j, m in enumerate(self.members)
            if j != i and not m.done and m.goal_xy_m is None and m.tmap is not None
        ]
        if not waiting:
            return candidates[int(np.argmin(cost))]
        matrix = [cost]
        for j in waiting:
            qx, qy = self._poses[j][:2]
            matrix.append(np.hypot(xy[:, 0] - qx, xy[:, 1] - qy) / 10.0 + p.discount_weight * taken)
        rows, cols = linear_sum_assignment(np.array(matrix))
        pick = dict(zip(rows.tolist(), cols.tolist(), strict=True))
        return candidates[pick[0]] if 0 in pick else candidates[int(np.argmin(cost))]

    def overlays(self) -> dict[str, dict[str, Any]]:
        out = {}
        for a, m in zip(self.agents, self.members, strict=True):
            ov = m.overlay()
            out[a] = {"goal_m": ov.get("goal_m"), "paths_m": ov.get("paths_m", [])}
        return out

    def mission_metrics(self) -> dict[str, Any]:
        return {
            "assignments": self.counters.get("assignments", 0),
            "yields": self.counters.get("yields", 0),
        }


def _metric_only(expert: SemanticExpertParams) -> Any:
    """The expert's cost weights with the semantic terms (``w_p``, ``w_I``) at 0."""
    cost = expert.cost
    names = {f.name for f in dataclasses.fields(cost)}
    zero = {k: 0.0 for k in ("w_p", "w_i", "w_I") if k in names}
    return dataclasses.replace(cost, **zero)
