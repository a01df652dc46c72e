"""Team policies for ``SemanticExploreMulti-v0``: one action per robot from all robots' observations.

``make_team_policy(spec)``: ``"independent"`` (each robot its nearest frontier),
``"greedy"`` (nearest unclaimed frontier, Yamauchi 1998 with claims), ``"coordinated"``
(Burgard-style utility discount and an assignment by ``linear_sum_assignment``, robots spread
over branches) and ``"coordinated_nobranch"`` (the same without the branch spreading).
"""

from __future__ import annotations

from typing import Any

from semexplore_gym.policies.team.base import TeamPolicy
from semexplore_gym.policies.team.frontier_teams import FrontierTeam, FrontierTeamParams

TEAM_POLICIES: dict[str, dict[str, Any]] = {
    "independent": {"coordination": "independent"},
    "greedy": {"coordination": "greedy"},
    "coordinated": {"coordination": "coordinated"},
    "coordinated_nobranch": {"coordination": "coordinated", "spread_branches": False},
}


def make_team_policy(spec: str, **overrides: Any) -> TeamPolicy:
    """A team policy by name (see :data:`TEAM_POLICIES`), keyword overrides on top."""
    if spec not in TEAM_POLICIES:
        raise ValueError(f"unknown team policy {spec!r}; known: {sorted(TEAM_POLICIES)}")
    return FrontierTeam(FrontierTeamParams(**{**TEAM_POLICIES[spec], **overrides}))


__all__ = ["TEAM_POLICIES", "FrontierTeam", "FrontierTeamParams", "TeamPolicy", "make_team_policy"]
