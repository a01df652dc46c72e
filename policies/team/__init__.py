"""Team policies for ``SemanticExploreMulti-v0``: one action per robot from all robots' observations.

``make_team_policy(spec)``: ``"independent"`` (each robot its nearest frontier),
``"greedy"`` (nearest unclaimed frontier, Yamauchi 1998 with claims), ``"coordinated"``
(Burgard-style utility discount and an assignment by ``linear_sum_assignment``, robots spread
over branches), ``"coordinated_nobranch"`` (the same without the branch spreading),
``"semantic"`` (the coordinated semantic expert: the paper's expert per robot, goals divided
through its ``choose_goal`` plug-in point) and ``"semantic_nosem"`` (its no-semantics ablation).
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


#: The coordinated semantic expert and its no-semantics ablation.
SEMANTIC_TEAM_POLICIES: dict[str, dict[str, Any]] = {
    "semantic": {"semantic": True},
    "semantic_nosem": {"semantic": False},
}


def team_policy_names() -> list[str]:
    """Every name :func:`make_team_policy` knows."""
    return sorted([*TEAM_POLICIES, *SEMANTIC_TEAM_POLICIES])


def make_team_policy(spec: str, **overrides: Any) -> TeamPolicy:
    """A team policy by name (see :func:`team_policy_names`), keyword overrides on top."""
    if spec in SEMANTIC_TEAM_POLICIES:
        from semexplore_gym.policies.team.semantic_team import SemanticTeam, SemanticTeamParams

        return SemanticTeam(SemanticTeamParams(**{**SEMANTIC_TEAM_POLICIES[spec], **overrides}))
    if spec not in TEAM_POLICIES:
        raise ValueError(f"unknown team policy {spec!r}; known: {team_policy_names()}")
    return FrontierTeam(FrontierTeamParams(**{**TEAM_POLICIES[spec], **overrides}))


__all__ = [
    "SEMANTIC_TEAM_POLICIES",
    "TEAM_POLICIES",
    "team_policy_names",
    "FrontierTeam",
    "FrontierTeamParams",
    "TeamPolicy",
    "make_team_policy",
]
