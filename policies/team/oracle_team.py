"""The team oracle: k robots drive a min-makespan split of the oracle's coverage tour.

**Privileged**, as the one-robot oracle (:mod:`semexplore_gym.policies.oracle`): it reads the
true world from ``info["privileged_world"]`` of a ``SemanticExploreMulti-v0`` made with
``privileged=True`` (the team benchmark does that for it) and refuses any other env. It is a
yardstick for team policies, never a learner's teacher.

At ``reset`` it plans the one-robot coverage tour from robot 0's start
(:func:`~semexplore_gym.core.coverage_tour.plan_coverage_tour`, the one-robot oracle's settings)
and splits its viewpoints into one route per robot with the least makespan
(:func:`~semexplore_gym.core.coverage_tour.team_tour.plan_team_tour`: OR-Tools vehicle routing,
each route from its robot's own start: teammates start near robot 0, but sometimes on the far
side of a wall). Each robot then drives its route exactly as the one-robot oracle drives
its tour (:class:`~semexplore_gym.policies.oracle.OraclePolicy`, given the route instead of
planning one: the same path following, stuck recovery, pruning against the live map, repairs,
shortcuts and the fallback goals once the route is done: a robot whose route is done looks for
what the team has not seen yet). With the env's team map (the default) every robot prunes
against what the whole team has seen. The team stops when team
coverage reaches ``coverage_goal`` or every robot has nothing left to do.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from semexplore_gym.policies.oracle import (
    OracleParams,
    OraclePolicy,
    PrivilegedPolicyError,
)
from semexplore_gym.policies.team.base import TeamPolicy

from semexplore_gym.core.coverage_tour import (
    PRIVILEGED_INFO_KEY,
    CoverageTour,
    PrivilegedWorld,
    TourParams,
    plan_coverage_tour,
)
from semexplore_gym.core.coverage_tour.team_tour import (
    TeamTour,
    TeamTourParams,
    plan_team_tour,
    require_routing_solver,
)

_NOT_PRIVILEGED = (
    "the team oracle is a privileged policy: it needs the true world, which only "
    "SemanticExploreMulti-v0 made with privileged=True hands out (info['privileged_world'] at "
    "reset); semexplore benchmark --robots ... --oracle does that for it"
)


@dataclass(frozen=True)
class TeamOracleParams:
    """Parameters of :class:`TeamOracle`.

    Attributes:
        member: Each robot's driving (the one-robot oracle's parameters; its ``tour`` is the
            tour the team splits). A member drives the least-cost path from where it is
            (``drive_planned_legs`` does not apply): its route is re-solved on distances
            alone, so no leg was counted for it to follow.
        routing: The split's solver settings.
        coverage_goal: The team stops at this team coverage (the benchmark's T99 level; the
            env's own goal is ignored, as the team benchmark sets it to 1).
    """

    member: OracleParams = field(default_factory=OracleParams)
    routing: TeamTourParams = field(default_factory=TeamTourParams)
    coverage_goal: float = 0.99

    def __post_init__(self) -> None:
        if not 0.0 < self.coverage_goal <= 1.0:
            raise ValueError(f"coverage_goal must be in (0, 1], got {self.coverage_goal!r}")


def route_tour(tour: CoverageTour, route: tuple[int, ...], start_m: float) -> CoverageTour:
    """``tour`` cut down to the viewpoints of ``route`` (in its order), ``start_m`` the
    distance from the start to its first viewpoint."""
    idx = np.asarray(route, dtype=np.int64)
    dist = tour.distances_m[np.ix_(idx, idx)]
    legs = np.r_[start_m, dist[np.arange(idx.size - 1), np.arange(1, idx.size)]] if idx.size else []
    legs_m = np.asarray(legs, dtype=np.float64)
    return replace(
        tour,
        viewpoints_rc=tour.viewpoints_rc[idx].reshape(-1, 2),
        viewpoints_xy_m=tour.viewpoints_xy_m[idx].reshape(-1, 2),
        leg_lengths_m=legs_m,
        length_m=float(legs_m.sum()),
        visible=tour.visible[idx],
        distances_m=dist,
    )


class _RouteOracle(OraclePolicy):
    """One robot of the team oracle: the one-robot oracle on a given route."""

    def __init__(self, params: OracleParams, route: CoverageTour) -> None:
        super().__init__(params)
        self._route = route

    def plan_tour(self, facts: PrivilegedWorld, tour_params: TourParams) -> CoverageTour:
        return self._route

    def _planned_leg(
        self, leg_from: tuple[int, int], rc: tuple[int, int], pose: tuple[float, float, float]
    ) -> np.ndarray | None:
        return None  # no leg of a route was counted: the least-cost path from the robot

    def _best_route(
        self, here: tuple[int, int], dist: np.ndarray, routes: list[list[int]], unseen: np.ndarray
    ) -> list[int]:
        # A route sees only its share of what the team needs: no prediction of the whole
        # goal to judge it by; the survivors are re-solved from where the robot is.
        return routes[1]


class TeamOracle(TeamPolicy):
    """PRIVILEGED team explorer (module docstring): the oracle's tour split among the robots."""

    name = "team_oracle"
    #: Reads ground truth: the team benchmark makes its env with ``privileged=True``.
    privileged = True

    def __init__(self, params: TeamOracleParams | None = None) -> None:
        super().__init__()
        self.params = params if params is not None else TeamOracleParams()
        self.members: list[_RouteOracle] = []
        self.team_tour: TeamTour | None = None
        self.tour: CoverageTour | None = None

    def reset(
        self,
        observations: dict[str, dict[str, np.ndarray]],
        infos: dict[str, dict[str, Any]],
        seed: int | None = None,
    ) -> None:
        super().reset(observations, infos, seed=seed)
        truths: list[PrivilegedWorld] = []
        for a in self.agents:
            truth = infos[a].get(PRIVILEGED_INFO_KEY)
            if not isinstance(truth, PrivilegedWorld):
                raise PrivilegedPolicyError(_NOT_PRIVILEGED)
            truths.append(truth)
        require_routing_solver()
        prm = self.params
        first = truths[0]
        tour_params = replace(
            prm.member.tour,
            leg_prefer_clearance_m=prm.member.path_prefer_clearance_m,
            leg_wall_cost=prm.member.path_wall_cost,
        )
        self.tour = tour = plan_coverage_tour(first, tour_params)
        k = len(self.agents)
        if tour.n_viewpoints < k:
            raise ValueError(
                f"the team oracle needs a viewpoint per robot: {k} robots, but the coverage "
                f"tour of this world has {tour.n_viewpoints}"
            )
        starts = [(t.start_pose[0], t.start_pose[1]) for t in truths]
        self.team_tour = split = plan_team_tour(tour, first.geometry, starts, k, prm.routing)
        self.members = []
        for i, agent in enumerate(self.agents):
            route = split.routes[i]
            first_m = split.lengths_m[i] - float(
                sum(tour.distances_m[a, b] for a, b in zip(route[:-1], route[1:], strict=True))
            )
            member = _RouteOracle(prm.member, route_tour(tour, route, first_m))
            info = dict(infos[agent])
            info[PRIVILEGED_INFO_KEY] = replace(truths[i], coverage_goal=prm.coverage_goal)
            member.reset(observations[agent], info, seed=None if seed is None else seed + i)
            self.members.append(member)
        self.counters = {"viewpoints": tour.n_viewpoints}

    def act(
        self, observations: dict[str, dict[str, np.ndarray]], infos: dict[str, dict[str, Any]]
    ) -> dict[str, np.ndarray]:
        still = np.zeros(2, dtype=np.float32)
        coverage = float(infos[self.agents[0]].get("coverage", 0.0))
        if coverage >= self.params.coverage_goal:
            self.done, self.stop_reason = True, "coverage_goal"
        actions: dict[str, np.ndarray] = {}
        for member, agent in zip(self.members, self.agents, strict=True):
            if self.done or member.done:
                actions[agent] = still
            else:
                actions[agent] = member.act(observations[agent], infos[agent])
        if not self.done and all(m.done for m in self.members):
            self.done, self.stop_reason = True, "nothing_left_to_see"
        return actions

    def overlays(self) -> dict[str, dict[str, Any]]:
        return {a: m.overlay() for m, a in zip(self.members, self.agents, strict=True)}

    def mission_metrics(self) -> dict[str, Any]:
        split = self.team_tour
        if split is None or self.tour is None:
            return {}
        return {
            "oracle_tour_m": round(self.tour.length_m, 3),
            "oracle_makespan_m": round(split.makespan_m, 3),
            "oracle_routes_m": ";".join(f"{v:.3f}" for v in split.lengths_m),
        }


__all__ = ["TeamOracle", "TeamOracleParams", "route_tour"]
