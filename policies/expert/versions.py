"""Named versions of the semantic expert: ``semantic-v2``, ``semantic-v3``, ``semantic-v4``;
``semantic`` is the newest.

As with Gymnasium's env ids (``CartPole-v0``, ``CartPole-v1``), a version name never changes
meaning: a table measured with ``semantic-v2`` is measured again with ``semantic-v2`` in any
later release, while ``semantic`` moves on to the newest version. A version is a recipe
(:class:`~semexplore_gym.policies.expert.recipes.ExpertRecipe`: the plan sources it asks, the
rules of its goal memory, its parameter values; :data:`EXPERT_VERSIONS`); ``make_policy``
builds it with the caller's overrides on top, so ``semantic-v2[cost.w_v=2]`` is the 0.2.0
expert with another weight. Every run record (the mission JSON of ``semexplore explore``, ``runs.csv``'s
``policy_version`` column and ``summary.md``) states the version a spec resolved to
(:func:`expert_version`).

A release that changes the expert's behaviour adds a version here with a new recipe, and each
older version keeps its recipe, so its missions stay as they were: an old behaviour lives in the
parts an old recipe lists, not in a switch of today's expert. ``tests/policies/test_expert_versions.py`` holds ``semantic-v2`` to
the 0.2.0 release's own mission on a small office, ``semantic`` to ``semantic-v4``, and
``semantic-v4`` to ``semantic-v3`` on the perfect map, mission for mission.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from types import MappingProxyType

from semexplore_gym.policies.expert.recipes import (
    SEMANTIC_V2,
    SEMANTIC_V3,
    SEMANTIC_V4,
    ExpertRecipe,
)
from semexplore_gym.policies.specs import parse_spec


@dataclass(frozen=True)
class ExpertVersion:
    """One released behaviour of the semantic expert.

    Attributes:
        name: The policy spec that runs it (``semantic-v2``); never reused for another behaviour.
        release: The package release it shipped in.
        recipe: What it is made of (its plan sources, goal rules and parameter values).
        changes: What changed against the version before, in a few words.
    """

    name: str
    release: str
    recipe: ExpertRecipe
    changes: str = ""


#: Every named version, oldest first.
EXPERT_VERSIONS: Mapping[str, ExpertVersion] = MappingProxyType(
    {
        v.name: v
        for v in (
            ExpertVersion(
                "semantic-v2", "0.2.0", SEMANTIC_V2, "the robust expert of the 0.2.0 release"
            ),
            ExpertVersion(
                "semantic-v3",
                "0.3.0",
                SEMANTIC_V3,
                "shuttle guard, views into frontiers reached but unseen, the grid's nearest "
                "frontier as a candidate, goals mapped when their frontier is, room beyond "
                "gaps, a point of its own per dropped goal, Algorithm 1's goal over the grid's "
                "route",
            ),
            ExpertVersion(
                "semantic-v4",
                "0.4.0",
                SEMANTIC_V4,
                "on a SLAM map, the wall slivers (UNKNOWN strips narrower than "
                "sliver_max_width_m along walls) read as wall; on the perfect map semantic-v3",
            ),
        )
    }
)
#: The version the plain ``semantic`` spec runs.
LATEST_EXPERT = "semantic-v4"
#: The name that always means the newest version.
NEWEST_ALIAS = "semantic"


def expert_version(spec: str) -> str:
    """The expert version a policy spec runs: ``"semantic-v4"`` for ``semantic``,
    ``semantic[cost.w_v=2]`` or ``semantic-v4``, ``"semantic-v2"`` for ``semantic-v2[...]``, and
    ``""`` for every other policy (a baseline, a learned agent, the paper-pure preset).

    Raises:
        ValueError: a malformed spec (the message names it).
    """
    base = parse_spec(spec)[0].partition(":")[0]
    if base == NEWEST_ALIAS:
        return LATEST_EXPERT
    return base if base in EXPERT_VERSIONS else ""


def version_recipe(name: str) -> ExpertRecipe:
    """The recipe of version ``name`` (``semantic`` for the newest)."""
    return EXPERT_VERSIONS[LATEST_EXPERT if name == NEWEST_ALIAS else name].recipe
