"""Team policies for ``SemanticExploreMulti-v0``: one action per robot from all robots' observations.

``make_team_policy(spec)``: ``"independent"`` (each robot its nearest frontier),
``"greedy"`` (nearest unclaimed frontier, Yamauchi 1998 with claims), ``"coordinated"``
(Burgard-style utility discount and an assignment by ``linear_sum_assignment``, robots spread
over branches), ``"coordinated_nobranch"`` (the same without the branch spreading),
``"semantic"`` (the coordinated semantic expert: the paper's expert per robot, goals divided
through its ``choose_goal`` plug-in point), ``"semantic_nosem"`` (its no-semantics ablation) and
``"oracle"`` (the privileged team oracle: the one-robot oracle's tour split into
min-makespan routes; its env must be made with ``privileged=True``).

A spec may end in a bracket of parameter overrides, as single-robot specs do:
``"semantic[discount_weight=6]"``, ``"semantic[expert.cost.w_v=0;branch_weight=0]"``,
``"greedy[claim_radius_m=3]"`` (dotted keys of :class:`SemanticTeamParams` or
:class:`FrontierTeamParams`); the team's name in tables then carries the bracket
(``team_semantic[discount_weight=6]``). A bracket without ``=`` is a label.
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


#: The privileged team oracle's name (:mod:`.oracle_team`).
TEAM_ORACLE = "oracle"


def team_policy_names() -> list[str]:
    """Every name :func:`make_team_policy` knows."""
    return sorted([*TEAM_POLICIES, *SEMANTIC_TEAM_POLICIES, TEAM_ORACLE])


def make_team_policy(spec: str, **overrides: Any) -> TeamPolicy:
    """A team policy by spec (a name of :func:`team_policy_names`, optionally with a bracket of
    parameter overrides or a label: module docstring), keyword overrides on top.

    Raises:
        ValueError: an unknown name, a malformed bracket or an unknown or bad parameter; the
            message names the spec.
    """
    from semexplore_gym.policies.specs import parse_spec, split_bracket

    from semexplore_gym.config.builder import ConfigError, build_params

    base, _, bracket = parse_spec(spec)
    team: TeamPolicy
    try:
        if base in SEMANTIC_TEAM_POLICIES:
            from semexplore_gym.policies.team.semantic_team import (
                SemanticTeam,
                SemanticTeamParams,
            )

            layer = SEMANTIC_TEAM_POLICIES[base]
            params = build_params(SemanticTeamParams, layer, bracket)
            team = SemanticTeam(params, **overrides)
        elif base == TEAM_ORACLE:
            from semexplore_gym.policies.team.oracle_team import TeamOracle, TeamOracleParams

            team = TeamOracle(build_params(TeamOracleParams, bracket), **overrides)
        elif base in TEAM_POLICIES:
            layer = TEAM_POLICIES[base]
            team = FrontierTeam(build_params(FrontierTeamParams, layer, bracket), **overrides)
        else:
            raise ValueError(f"unknown team policy {spec!r}; known: {team_policy_names()}")
    except (ConfigError, TypeError) as e:
        raise ValueError(f"team policy {spec!r}: {e}") from None
    inner = split_bracket(spec)[1]
    if inner:
        team.name = f"{team.name}[{inner}]"
    return team


__all__ = [
    "SEMANTIC_TEAM_POLICIES",
    "TEAM_ORACLE",
    "TEAM_POLICIES",
    "team_policy_names",
    "FrontierTeam",
    "FrontierTeamParams",
    "TeamPolicy",
    "make_team_policy",
]
