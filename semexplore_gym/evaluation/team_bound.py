"""The team benchmark's lower bound on a team's T99 (see
:func:`~semexplore_gym.core.coverage_tour.team_tour.team_lower_bound_m`).

Robot 0's start is the same for every team size of one (world, seed), so the two one-robot
bounds it needs are computed once per process and (world, seed), kept while the world lasts; the path through the
teammates' starts is the team's own.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Any

#: The coverage level the bound is for (the benchmark's T99).
BOUND_COVERAGE = 0.99

_ONE_ROBOT: dict[tuple[str, int], tuple[float, float]] = {}


def team_lower_bound_s(env: Any, key: tuple[str, int]) -> float | None:
    """A lower bound on the T99 of the team in ``env`` (a ``SemanticExploreMulti-v0`` just
    reset), at top speed; None when no bound can be computed for this world (the reason is
    the core's ValueError, which the mission's row does not need)."""
    from semexplore_gym.core.coverage_tour.lower_bound import (
        LowerBoundParams,
        allowed_cells,
        lower_bound,
    )
    from semexplore_gym.core.coverage_tour.team_tour import starts_gap_m, team_lower_bound_m

    truth = replace(env.ground_truth(0), coverage_goal=BOUND_COVERAGE)
    params = LowerBoundParams(coverage_share=BOUND_COVERAGE)
    try:
        if key not in _ONE_ROBOT:
            if any(k[0] != key[0] for k in _ONE_ROBOT):
                _ONE_ROBOT.clear()  # one world at a time: tasks come world-major
            one = lower_bound(truth, params).distance_m
            # one forced region only (the branch bound is a whole walk, not one robot's share)
            far_params = replace(params, max_groups=1, branch_block_m=0.0)
            far = lower_bound(truth, far_params).distance_m
            _ONE_ROBOT[key] = (one, far)
        one, far = _ONE_ROBOT[key]
        allowed, _ = allowed_cells(truth, params.penetration_tolerance_m)
    except ValueError:
        return None
    n = len(env.possible_agents)
    starts = [tuple(env.ground_truth(i).start_pose[:2]) for i in range(n)]
    gap, spread = starts_gap_m(allowed, truth.geometry, starts)
    bound_m = team_lower_bound_m(one, far, n, gap, spread)
    return bound_m / truth.max_linear_speed_mps
