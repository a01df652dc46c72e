"""Coverage at the planner's own clearance: the ``coverage_at_planner_clearance`` column.

The env's ``coverage`` counts every cell the robot's body can sweep with its centre
``radius + episode.coverage_clearance_margin_m`` (0.01 m) from walls. The semantic expert plans
only through space ``radius + clearance_margin_m`` (0.05 m) from walls, so a passage between
0.23 m and 0.31 m wide counts for coverage but is closed to its planner. This column is the
share of the cells reachable at the planner's clearance that the final map has seen: near 1
with a low ``coverage`` means what was left lies behind passages the planner does not take
("unreachable for this planner"); low in both means the mission gave up on open space.
"""

from __future__ import annotations

from typing import Any

from semexplore_gym.envs.coverage_mask import coverage_mask, map_coverage
from semexplore_gym.policies.expert.params import SemanticExpertParams


def planner_clearance_margin_m(policy: Any) -> float:
    """The margin beyond the robot radius that ``policy`` plans with: the semantic expert's own
    ``clearance_margin_m`` (any policy whose ``params`` are :class:`SemanticExpertParams`), and
    the default expert's (0.05 m) for every other policy, so rows of different policies compare
    on the same cells."""
    params = getattr(policy, "params", None)
    if isinstance(params, SemanticExpertParams):
        return float(params.clearance_margin_m)
    return float(SemanticExpertParams().clearance_margin_m)


def coverage_at_planner_clearance(env: Any, policy: Any) -> float | None:
    """Share of the cells reachable from the episode's start at clearance ``radius +``
    :func:`planner_clearance_margin_m` that ``env``'s map has seen free, after a mission.

    One reachable-mask computation (the env's own :func:`coverage_mask`). None when the start
    itself has no cell with that clearance nearby (nothing is reachable at it), or when the env
    was never reset.
    """
    base = env.unwrapped
    if getattr(base, "start_pose", None) is None:
        return None
    try:
        mask = coverage_mask(
            base.world,
            base.map_geometry,
            base.start_pose[:2],
            base.config,
            planner_clearance_margin_m(policy),
        )
    except ValueError:
        return None
    return map_coverage(base.grid.encoded, mask)
